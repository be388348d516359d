// SPDX-License-Identifier: GPL-3.0-or-later
// journal_torture: a controller process (the simulated broach with the journal writer, the mains
// cut again and again) SIGKILLed at random moments (fixed seed), and every fifth time the newest
// slot torn or corrupted as a failing disk would; after each, the journal must still hold a
// breakpoint record that decodes (else `corrupt`) and is no older than the last one the process
// had reported durable (else `lost`).
//
//   journal_torture [--kills N] [--seed S] [--dir DIR] [--json]
#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <string_view>
#include <thread>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

namespace {

using namespace opencnc;

/// The child: power failures one after another, each record's sequence reported once durable.
[[noreturn]] void controller_process(const std::filesystem::path& dir, int report_fd, unsigned seed) {
  const config::MachineProfile profile =
      *config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml").profile;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(0.3, 4.0);
  for (;;) {
    Diagnostics d;
    auto machine =
        features::machine_setup(profile, d, controller::MachineSetup::Options::with("journal", dir.string()));
    if (!machine) ::_exit(2);
    auto journal = std::dynamic_pointer_cast<recovery::BreakpointJournal>(machine->feature("journal"));
    if (!journal) ::_exit(2);
    std::string error;
    controller::SimRig rig(profile, *machine);
    rig.step();
    rig.request(controller::Request::simple(control::CommandKind::MachineOn));
    rig.request(controller::Request::set_mode(control::Mode::Auto));
    rig.request(controller::Request::open(OPENCNC_SOURCE_DIR "/examples/broach-constant.ngc"), 1000000);
    rig.request(controller::Request::simple(control::CommandKind::CycleStart));
    const double cut = at(rng);
    rig.run_until([&] { return rig.status().servo.time_s >= cut; }, 10'000'000);
    rig.machine().set_mains_ok(false);
    rig.run_until([&] { return rig.status().servo.state == control::State::Faulted; }, 100000);
    rig.run(3);
    journal->flush();
    const auto reader = recovery::Journal::open(dir.string(), &error);
    const std::uint64_t seq = reader ? reader->sequence() : 0;
    if (::write(report_fd, &seq, sizeof seq) != sizeof seq) ::_exit(3);
  }
}

/// Tears (truncates into the record) or flips a byte of the slot holding sequence `seq`.
void damage(const std::filesystem::path& dir, std::uint64_t seq, bool tear) {
  const auto slot = dir / (seq % 2 == 1 ? "slot-a.jrn" : "slot-b.jrn");
  if (tear) {
    std::filesystem::resize_file(slot, 200);
    return;
  }
  std::fstream f(slot, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(300);
  const char c = static_cast<char>(f.get() ^ 0x40);
  f.seekp(300);
  f.put(c);
}

int usage(int rc) {
  fmt::print(
      rc == 0 ? stdout : stderr,
      "usage: journal_torture [--kills N] [--seed S] [--dir DIR] [--json]\n"
      "  SIGKILLs a controller process writing breakpoint records N times; none may be lost or corrupt\n");
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  int kills = 100;
  unsigned seed = 20261126;
  bool json = false;
  std::filesystem::path dir = std::filesystem::current_path() / "journal-torture";
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--help" || a == "-h") return usage(0);
    if (a == "--json") {
      json = true;
    } else if ((a == "--kills" || a == "--seed" || a == "--dir") && i + 1 < argc) {
      const char* v = argv[++i];
      if (a == "--kills") kills = std::max(1, std::atoi(v));
      if (a == "--seed") seed = static_cast<unsigned>(std::strtoul(v, nullptr, 10));
      if (a == "--dir") dir = v;
    } else {
      fmt::print(stderr, "journal_torture: unknown option '{}'\n", a);
      return usage(2);
    }
  }
  // The folder is the torture's own: a fresh one, or one holding nothing but an earlier run's two
  // slots. Anything else in it is somebody's, and stays.
  std::error_code ec;
  if (std::filesystem::exists(dir, ec)) {
    if (!std::filesystem::is_directory(dir, ec)) {
      fmt::print(stderr, "journal_torture: --dir {} is not a folder\n", dir.string());
      return 2;
    }
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (name != "slot-a.jrn" && name != "slot-b.jrn") {
        fmt::print(stderr, "journal_torture: --dir {} holds {}, not only a journal's slots: choose another folder\n",
                   dir.string(), name);
        return 2;
      }
    }
    std::filesystem::remove(dir / "slot-a.jrn", ec);
    std::filesystem::remove(dir / "slot-b.jrn", ec);
  }
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay_us(0, 60000);
  int runs = 0, lost = 0, corrupt = 0, damaged = 0, double_faults = 0;
  std::uint64_t reported = 0;  // the newest sequence any child reported durable
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < kills; ++k) {
    int fds[2];
    if (::pipe(fds) != 0) return 3;
    const pid_t child = ::fork();
    if (child < 0) return 3;
    if (child == 0) {
      ::close(fds[0]);
      controller_process(dir, fds[1], seed + static_cast<unsigned>(k));
    }
    ::close(fds[1]);
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    std::uint64_t s = 0;
    while (::read(fds[0], &s, sizeof s) == sizeof s) reported = std::max(reported, s);
    ::close(fds[0]);
    ++runs;
    std::string error;
    auto j = recovery::Journal::open(dir.string(), &error);
    if (!j) return 3;
    std::uint64_t expect = reported;
    if (k % 5 == 4 && j->sequence() >= 2) {  // the disk tears or corrupts the newest slot
      damage(dir, j->sequence(), k % 10 == 9);
      ++damaged;
      expect = std::min(expect, j->sequence() - 1);
      j = recovery::Journal::open(dir.string(), &error);
      reported = expect;  // the damaged record is gone for good: the fallback is the standard now
      if (!j->read()) {
        // The other slot held a write the kill had torn: two faults at once, which two slots
        // cannot survive (counted apart, not as a loss of the journal's promise).
        ++double_faults;
        reported = 0;
        continue;
      }
    }
    const auto raw = j->read();
    if (expect == 0 && !raw) continue;
    if (!raw || raw->sequence < expect) {
      fmt::print(stderr, "journal_torture: kill {}: the journal holds {} after record {} was durable\n", k,
                 raw ? fmt::format("record {}", raw->sequence) : std::string("no record"), expect);
      ++lost;
      continue;
    }
    if (!recovery::decode(raw->payload, &error)) ++corrupt;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::filesystem::remove_all(dir);
  if (json) {
    fmt::print(
        "{{\"runs\": {}, \"lost\": {}, \"corrupt\": {}, \"damaged\": {}, \"double_faults\": {}, "
        "\"wall_s\": {:.3f}}}\n",
        runs, lost, corrupt, damaged, double_faults, wall_s);
  } else {
    fmt::print(
        "{} kills ({} with the newest slot torn or corrupted, {} of them with the other slot torn by a "
        "kill): "
        "{} lost, {} corrupt, {:.1f} s\n",
        runs, damaged, double_faults, lost, corrupt, wall_s);
  }
  return lost == 0 && corrupt == 0 ? 0 : 1;
}
