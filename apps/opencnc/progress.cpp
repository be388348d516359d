// SPDX-License-Identifier: GPL-3.0-or-later
// Progress lines of long interpreter runs on stderr.
#include "progress.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>

#include <fmt/format.h>

namespace opencnc::cli {

namespace {

std::string millions(std::uint64_t n) {
  return n >= 1'000'000 ? fmt::format("{:.1f} M", static_cast<double>(n) / 1e6) : fmt::format("{}", n);
}

}  // namespace

InterpreterProgress::InterpreterProgress(std::string what, bool forced)
    : what_(std::move(what)), terminal_(::isatty(STDERR_FILENO) != 0), enabled_(forced || terminal_) {}

gcode::RunStatus InterpreterProgress::run(gcode::Interpreter& interp, canon::Sink& sink) {
  if (!enabled_) return interp.run(sink);
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto period = terminal_ ? std::chrono::milliseconds(250) : std::chrono::milliseconds(1000);
  auto next = start + std::chrono::milliseconds(500);
  for (std::uint64_t n = 1;; ++n) {
    const gcode::RunStatus status = interp.step(sink);
    if (status != gcode::RunStatus::Ok) {
      clear();
      return status;
    }
    if ((n & 4095) != 0) continue;  // (the clock is read once per 4096 blocks)
    const auto now = Clock::now();
    if (now < next) continue;
    show(interp, std::chrono::duration<double>(now - start).count());
    next = now + period;
  }
}

void InterpreterProgress::show(const gcode::Interpreter& interp, double elapsed_s) {
  const gcode::InterpState st = interp.state();
  const std::string text = fmt::format("{}: line {}, {} blocks, {} moves, {:.0f} s", what_, st.next.line,
                                       millions(st.blocks_executed), millions(interp.segments()), elapsed_s);
  if (terminal_)
    fmt::print(stderr, "\r{}\033[K", text);
  else
    fmt::print(stderr, "{}\n", text);
  std::fflush(stderr);
  shown_ = true;
}

void InterpreterProgress::clear() {
  if (shown_ && terminal_) fmt::print(stderr, "\r\033[K");
  shown_ = false;
}

}  // namespace opencnc::cli
