// SPDX-License-Identifier: GPL-3.0-or-later
// stream_bench — a long program through the whole controller in virtual time: how long its
// preflight scan takes, how soon after it the machine moves (wall time from cycle start to the
// first servo period that moves), and the process's peak memory while it runs to the end.
//
//   stream_bench FILE [--profile PROFILE] [--set key=value]... [--first-motion-only]
//
// Make a long program with bench/control/gen_dense.py (docs/performance.md has the figures).
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

using namespace opencnc;
using namespace opencnc::control;
using namespace opencnc::controller;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // kB on Linux
}

bool ask(SimRig& rig, Request r) {
  const std::string name = r.name();
  const Outcome o = rig.request(std::move(r), 100000);
  if (!o.accepted) {
    fmt::print(stderr, "{} refused: {}\n", name, o.message);
    for (const auto& d : o.diagnostics.items()) fmt::print(stderr, "  {}\n", d.format());
  }
  return o.accepted;
}

}  // namespace

int main(int argc, char** argv) {
  std::string file, profile_file = OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml";
  std::vector<std::string> sets;
  bool first_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      fmt::print("usage: stream_bench FILE [--profile PROFILE] [--set key=value]... [--first-motion-only]\n");
      return 0;
    }
    if (a == "--profile" && i + 1 < argc) {
      profile_file = argv[++i];
    } else if (a == "--set" && i + 1 < argc) {
      sets.emplace_back(argv[++i]);
    } else if (a == "--first-motion-only") {
      first_only = true;
    } else if (!a.empty() && a[0] != '-' && file.empty()) {
      file = a;
    } else {
      fmt::print(stderr, "stream_bench: unknown option {} (see --help)\n", a);
      return 2;
    }
  }
  if (file.empty()) {
    fmt::print(stderr, "stream_bench: which program? (see --help)\n");
    return 2;
  }
  const config::ProfileLoad load = config::load_profile(profile_file, sets);
  if (!load.ok()) {
    for (const auto& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
    return 2;
  }
  Diagnostics diags;
  SimRig rig(*load.profile, *features::machine_setup(*load.profile, diags));
  if (!ask(rig, Request::simple(CommandKind::MachineOn)) || !ask(rig, Request::set_mode(Mode::Auto))) return 1;

  const auto t_open = Clock::now();
  const double c_open = cpu_seconds();
  if (!ask(rig, Request::open(file))) return 1;
  const double preflight_ms = ms_since(t_open);
  const double preflight_cpu = cpu_seconds() - c_open;
  const auto summary = rig.controller().open_program()->preflight.summary;
  const double rss_after_preflight = peak_rss_mb();

  const Pose start = rig.status().servo.commanded;
  const auto t_start = Clock::now();
  rig.controller().submit(Request::simple(CommandKind::CycleStart));
  std::uint64_t ticks = 0;
  while (rig.status().servo.commanded == start && ticks < 100000) {
    rig.step();
    ++ticks;
  }
  const double first_motion_ms = ms_since(t_start);
  fmt::print("program             {} ({} moves, {:.1f} mm)\n", file, summary.moves, summary.path_length_mm);
  fmt::print("preflight           {:.0f} ms wall, {:.3f} s CPU, peak RSS {:.1f} MB after it\n", preflight_ms,
             preflight_cpu, rss_after_preflight);
  fmt::print("first motion        {:.2f} ms wall after cycle start ({} servo periods)\n", first_motion_ms, ticks);
  if (first_only) return 0;

  const double c_run = cpu_seconds();
  const std::uint64_t t0 = rig.ticks();
  rig.run_until([&] { return !rig.status().run_active; }, ~std::uint64_t{0});
  const double machine_s = static_cast<double>(rig.ticks() - t0) * load.profile->servo_period_s;
  const double cpu = cpu_seconds() - c_run;
  const ControllerStatus st = rig.status();
  fmt::print("run                 {:.1f} s machine, {:.1f} s CPU ({:.0f}x), {}\n", machine_s, cpu, machine_s / cpu,
             st.runs_finished > 0 ? "finished" : "did not finish: " + st.fault_text);
  fmt::print("peak RSS            {:.1f} MB\n", peak_rss_mb());
  return st.runs_finished > 0 ? 0 : 1;
}
