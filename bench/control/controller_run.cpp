// SPDX-License-Identifier: GPL-3.0-or-later
// controller_run — programs through the whole controller on the simulated machine in virtual
// time: the figures of docs/controller.md (time, following and contour error, limits) and the
// speed of virtual time (machine seconds per CPU second of this thread).
//
//   controller_run [--profile FILE] [--set key=value]... [--no-report] [--service-every N] [files...]
//
// --service-every N: the controller's work between every N servo periods (default 1).
//
// Without files it runs the reference programs built from canonical calls (square G61/G64,
// dense spiral with and without G64 Q, 2000 small arcs of 90° and of 112.885°, the issue's).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "opencnc/analysis/reference_programs.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/run_recorder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

using namespace opencnc;
using namespace opencnc::control;
using namespace opencnc::controller;

namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Job {
  std::string name;
  std::shared_ptr<const canon::Program> program;  // or a file
  std::string file;
};

bool ask(SimRig& rig, Request r, std::string& why) {
  const Outcome o = rig.request(std::move(r), 200000);
  why = o.message;
  for (const auto& d : o.diagnostics.items()) {
    if (d.severity == Severity::Error) why += "\n  " + d.format();
  }
  return o.accepted;
}

void run(const config::MachineProfile& profile, const Job& job, bool report, int service_every) {
  Diagnostics diags;
  SimRig rig(profile, *features::machine_setup(profile, diags), service_every);
  std::string why;
  if (!ask(rig, Request::simple(CommandKind::MachineOn), why) ||
      !ask(rig, Request::set_mode(Mode::Auto), why)) {
    fmt::print("{:<28} refused: {}\n", job.name, why);
    return;
  }
  // From the open on: interpreting, checking, planning and running all count.
  const double c0 = cpu_seconds();
  const std::uint64_t t0 = rig.ticks();
  if (!ask(rig, job.program ? Request::open(job.program, job.name) : Request::open(job.file), why)) {
    fmt::print("{:<28} refused: {}\n", job.name, why);
    return;
  }
  std::shared_ptr<RunRecorder> rec;
  if (report) {
    rec = std::make_shared<RunRecorder>(machine_limits(profile), profile.servo_period_s);
    rig.controller().attach(rec, ObserverOptions{0, true});
  }
  if (!ask(rig, Request::simple(CommandKind::CycleStart), why)) {
    fmt::print("{:<28} refused: {}\n", job.name, why);
    return;
  }
  for (std::uint64_t n = 0; n < 100'000'000; ++n) {
    rig.step();
    if ((n & 255) == 0) {  // no operator: continue program stops and manual tool changes
      const ServoStatus& v = rig.status().servo;
      if (v.state == State::Stopped) rig.controller().submit(Request::simple(CommandKind::CycleStart));
      if (v.wait == Wait::ManualToolChange)
        rig.controller().submit(Request::simple(CommandKind::ToolChanged));
    }
    if ((n & 63) == 0 && !rig.status().run_active) break;
  }
  const double cpu = cpu_seconds() - c0;
  const double machine_s = static_cast<double>(rig.ticks() - t0) * profile.servo_period_s;
  const ControllerStatus st = rig.status();
  if (!rec) {
    fmt::print("{:<28} {:9.3f} s machine  {:8.4f} s CPU  {:6.0f}x  {}\n", job.name, machine_s, cpu,
               machine_s / cpu, st.runs_finished > 0 ? "finished" : st.fault_text);
    return;
  }
  const RunReport r = rec->report();
  double vmax = 0, amax = 0;
  for (const auto& a : r.axes)
    vmax = std::max(vmax, a.max_velocity), amax = std::max(amax, a.max_acceleration);
  fmt::print("{:<28} {:9.3f} {:9.3f} {:8.4f} {:8.4f} {:8.4f} {:6} {:7.1f} {:7.1f}  {}\n", job.name,
             r.machining_time_s, r.motion_time_s, r.max_following_error_mm, r.max_contour_error_mm,
             r.max_command_contour_error_mm, r.limit_violations, vmax, amax,
             st.runs_finished > 0 ? "finished" : st.fault_text);
}

std::vector<Job> reference_jobs() {
  using analysis::PathMode;
  const auto p = [](canon::Program prog) { return std::make_shared<const canon::Program>(std::move(prog)); };
  // G64 P0.01 merges as LinuxCNC does with Q = P; Q0 merges nothing.
  const PathMode g64{canon::MotionControl::Continuous, 0.01, 0.01},
      g64q0{canon::MotionControl::Continuous, 0.01, 0};
  const PathMode g61{canon::MotionControl::ExactPath, 0, 0}, arcs{canon::MotionControl::Continuous, 0.1, 0.1};
  return {
      {"square G64 P0.01", p(analysis::square_program(100, 6000, g64)), ""},
      {"square G61", p(analysis::square_program(100, 6000, g61)), ""},
      {"spiral 20000 G64 P0.01", p(analysis::spiral_program(20000, 6000, g64)), ""},
      {"spiral 20000 G64 P0.01 Q0", p(analysis::spiral_program(20000, 6000, g64q0)), ""},
      {"2000 quarter arcs R0.3", p(analysis::small_arcs_program(2000, 0.3, 90, 3000, arcs)), ""},
      // The small arcs: chord 0.5 mm (gen_small_arcs.py 2000 112.885; LinuxCNC 73.715 s).
      {"2000 arcs R0.3 112.885deg", p(analysis::small_arcs_program(2000, 0.3, 112.885, 3000, arcs)), ""},
  };
}

}  // namespace

int main(int argc, char** argv) {
  std::string profile_file = OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml";
  std::vector<std::string> sets;
  std::vector<Job> jobs;
  bool report = true;
  int service_every = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      fmt::print(
          "usage: controller_run [--profile FILE] [--set key=value]... [--no-report] [--service-every N] "
          "[files...]\n  without files: the reference programs built from canonical calls\n");
      return 0;
    }
    if (a == "--profile" && i + 1 < argc) {
      profile_file = argv[++i];
    } else if (a == "--set" && i + 1 < argc) {
      sets.emplace_back(argv[++i]);
    } else if (a == "--service-every" && i + 1 < argc) {
      service_every = std::atoi(argv[++i]);
      if (service_every < 1) {
        fmt::print(stderr, "controller_run: --service-every takes a whole number of periods, 1 or more\n");
        return 2;
      }
    } else if (a == "--no-report") {
      report = false;
    } else if (a.starts_with('-')) {
      fmt::print(stderr, "controller_run: unknown option {} (see --help)\n", a);
      return 2;
    } else {
      jobs.push_back({a.substr(a.find_last_of('/') + 1), nullptr, a});
    }
  }
  const config::ProfileLoad load = config::load_profile(profile_file, sets);
  for (const auto& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
  if (!load.ok()) return 2;
  if (jobs.empty()) jobs = reference_jobs();
  if (report) {
    fmt::print("{:<28} {:>9} {:>9} {:>8} {:>8} {:>8} {:>6} {:>7} {:>7}\n", "program", "time [s]", "motion",
               "FE [mm]", "contour", "cmd ctr", "viol.", "v max", "a max");
  }
  for (const Job& j : jobs) run(*load.profile, j, report, service_every);
  return 0;
}
