// SPDX-License-Identifier: GPL-3.0-or-later
// The handler of SIGINT and SIGTERM for `opencnc run`.
#include "stop_signals.hpp"

#include <unistd.h>

#include <csignal>

#include "opencnc/core/output_file.hpp"

namespace opencnc::cli {

namespace {

static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free flag");
std::atomic<int> g_requested{0};
std::atomic<int> g_count{0};
struct sigaction g_old_int {
}, g_old_term{}, g_old_hup{};

void say(const char* text, std::size_t size) noexcept {
  (void)!::write(STDERR_FILENO, text, size);
}

extern "C" void on_stop_signal(int signal) {
  const int n = g_count.fetch_add(1) + 1;
  if (n == 1) {
    g_requested.store(signal);
    static constexpr char kStopping[] =
        "\nopencnc: stopping on the path (feed hold, then abort); again to abort at once\n";
    say(kStopping, sizeof kStopping - 1);
    return;
  }
  if (n == 2) {
    static constexpr char kAborting[] =
        "\nopencnc: aborting at once; the report follows (again: quit without it)\n";
    say(kAborting, sizeof kAborting - 1);
    return;
  }
  remove_output_temporaries();
  static constexpr char kQuit[] = "\nopencnc: quit at once: no report\n";
  say(kQuit, sizeof kQuit - 1);
  ::_exit(128 + signal);
}

}  // namespace

StopSignals::StopSignals() {
  g_requested.store(0);
  g_count.store(0);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &sa, &g_old_int);
  ::sigaction(SIGTERM, &sa, &g_old_term);
  ::sigaction(SIGHUP, &sa, &g_old_hup);  // the terminal went away: stop the run, do not die in it
}

StopSignals::~StopSignals() {
  ::sigaction(SIGINT, &g_old_int, nullptr);
  ::sigaction(SIGTERM, &g_old_term, nullptr);
  ::sigaction(SIGHUP, &g_old_hup, nullptr);
}

const std::atomic<int>& StopSignals::requested() noexcept {
  return g_requested;
}

const std::atomic<int>& StopSignals::count() noexcept {
  return g_count;
}

const char* signal_name(int signal) noexcept {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

}  // namespace opencnc::cli
