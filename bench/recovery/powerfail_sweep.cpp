// SPDX-License-Identifier: GPL-3.0-or-later
// powerfail_sweep: the mains cut at N random instants (fixed seed) through the constant-pitch demo
// job on the simulated broach; for each, the coupled stop's helix error against each axis stopping
// alone, the breakpoint record's latency (signal to durable), and the job resumed from the record on
// a machine powered up where the axes rest — its groove against the uninterrupted run's.
//
//   powerfail_sweep [--cuts N] [--seed S] [--program FILE] [--journal-root DIR] [--json]
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/power_fail_recorder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/recovery/breakpoint_journal.hpp"
#include "opencnc/recovery/recovery_wait.hpp"

namespace {

using namespace opencnc;
using control::Request;

/// The feedback of every coupled period of the main program, by the interpreter's segment id.
class Grooves final : public control::ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const control::TraceContext& c) override {
    if (c.job != control::JobKind::Program || c.program == nullptr || !s.coupled ||
        s.segment >= c.program->size())
      return;
    if (c.program->move(s.segment).kind != canon::MoveKind::Feed) return;
    by_segment[c.program->segment_of(s.segment)].push_back({s.actual[Axis::Z], s.actual[Axis::C]});
  }
  std::map<canon::SegmentId, std::vector<std::pair<double, double>>> by_segment;
};

struct Rig {
  Rig(const std::string& profile_path, const std::filesystem::path& journal_dir,
      std::vector<std::string> sets = {}) {
    profile = *config::load_profile(profile_path, sets).profile;
    Diagnostics d;
    auto source = control::GcodeProgramSource::create(profile, d);
    rig = std::make_unique<control::SimRig>(profile, source);
    std::string error;
    journal = recovery::BreakpointJournal::open(journal_dir.string(), source, &error);
    rig->controller().add_feature(journal, control::ObserverOptions{profile.servo_period_s, true});
    grooves = std::make_shared<Grooves>();
    rig->controller().attach(grooves, control::ObserverOptions{0, true});
    rig->step();
    rig->request(Request::simple(control::CommandKind::MachineOn));
    rig->request(Request::set_mode(control::Mode::Auto));
  }
  config::MachineProfile profile;
  std::unique_ptr<control::SimRig> rig;
  std::shared_ptr<recovery::BreakpointJournal> journal;
  std::shared_ptr<Grooves> grooves;
};

/// Largest distance on the bore (µm) of the resumed groove from the reference's, segment by
/// segment (C interpolated at the same Z), from the breakpoint on along the cutting direction.
/// `skip_mm`: leave out the first millimetres of every segment (where both runs break away from rest).
double deviation_um(const Grooves& resumed, const Grooves& ref, const recovery::BreakpointRecord& r,
                    double radius_mm, double skip_mm = 0) {
  double worst = 0;
  for (const auto& [segment, rows] : resumed.by_segment) {
    auto it = ref.by_segment.find(segment);
    if (it == ref.by_segment.end()) continue;
    std::vector<std::pair<double, double>> line = it->second;
    std::sort(line.begin(), line.end());
    const double dir = r.move_end[Axis::Z] >= r.move_start[Axis::Z] ? 1.0 : -1.0;
    const double first_z = it->second.front().first;  // where the reference began the segment
    for (const auto& [z, c] : rows) {
      if (segment == r.segment && (z - r.actual[Axis::Z]) * dir < 0) continue;  // the run-in
      if (std::fabs(z - first_z) < skip_mm) continue;
      auto hi = std::lower_bound(line.begin(), line.end(), std::pair{z, -1e300});
      if (hi == line.begin() || hi == line.end()) continue;
      const auto lo = hi - 1;
      const double cref = lo->second + (hi->second - lo->second) * (z - lo->first) / (hi->first - lo->first);
      worst = std::max(worst, std::fabs(std::remainder(c - cref, 360.0)));
    }
  }
  return worst * std::numbers::pi / 180 * radius_mm * 1000;
}

int usage(int rc) {
  fmt::print(rc == 0 ? stdout : stderr,
             "usage: powerfail_sweep [--cuts N] [--seed S] [--program FILE] [--journal-root DIR] [--json]\n"
             "  the mains cut at N random instants of the broach's demo job: coupled and independent stop\n"
             "  errors, record latency, and the resumed groove against the uninterrupted run's\n");
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  int cuts = 20;
  unsigned seed = 20261126;
  bool json = false;
  std::string program = OPENCNC_SOURCE_DIR "/examples/broach-constant.ngc";
  std::filesystem::path root = std::filesystem::current_path() / "powerfail-sweep";
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    if (a == "--help" || a == "-h") return usage(0);
    if (a == "--json") {
      json = true;
    } else if (a == "--cuts" || a == "--seed" || a == "--program" || a == "--journal-root") {
      const char* v = value();
      if (v == nullptr) return usage(2);
      if (a == "--cuts") cuts = std::max(1, std::atoi(v));
      if (a == "--seed") seed = static_cast<unsigned>(std::strtoul(v, nullptr, 10));
      if (a == "--program") program = v;
      if (a == "--journal-root") root = v;
    } else {
      fmt::print(stderr, "powerfail_sweep: unknown option '{}'\n", a);
      return usage(2);
    }
  }
  const std::string profile_path = OPENCNC_SOURCE_DIR "/configs/broach-zc.toml";
  // The root is the sweep's own: a fresh folder, or an earlier sweep's (only "reference" and
  // "cut-N" in it). Anything else is somebody's, and stays.
  std::error_code ec;
  if (std::filesystem::exists(root, ec)) {
    for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
      const std::string name = entry.path().filename().string();
      if (name != "reference" && name.rfind("cut-", 0) != 0) {
        fmt::print(stderr, "powerfail_sweep: --journal-root {} holds {}, not an earlier sweep's journals\n",
                   root.string(), name);
        return 2;
      }
    }
    if (ec || !std::filesystem::is_directory(root, ec)) {
      fmt::print(stderr, "powerfail_sweep: --journal-root {} is not a folder the sweep can use\n", root.string());
      return 2;
    }
  }
  // The uninterrupted run, once.
  std::filesystem::remove_all(root);
  Rig ref(profile_path, root / "reference");
  ref.rig->request(Request::open(program), 1000000);
  ref.rig->request(Request::simple(control::CommandKind::CycleStart));
  ref.rig->run_until([&] { return !ref.rig->status().run_active && ref.rig->status().servo.time_s > 1; },
                     100'000'000);
  const double length_s = ref.rig->status().servo.time_s;

  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(0.5, length_s - 0.5);
  double coupled_max = 0, independent_max = 0, resume_max = 0, moving_max = 0;
  std::vector<double> latencies;
  int resumed = 0, failed = 0;
  for (int k = 0; k < cuts; ++k) {
    const double cut_s = at(rng);
    const auto dir = root / fmt::format("cut-{}", k);
    recovery::BreakpointRecord r;
    control::PowerFailReport pf;
    std::vector<float> bore;  // the workpiece as the cut left it
    {
      Rig cut(profile_path, dir);
      auto recorder = std::make_shared<control::PowerFailRecorder>(
          control::coupling_config(cut.profile.coupling), control::machine_limits(cut.profile),
          cut.profile.servo_period_s, cut.profile.coupling.radius_mm);
      cut.rig->controller().attach(recorder, control::ObserverOptions{cut.profile.servo_period_s, true});
      cut.rig->request(Request::open(program), 1000000);
      cut.rig->request(Request::simple(control::CommandKind::CycleStart));
      cut.rig->run_until([&] { return cut.rig->status().servo.time_s >= cut_s; }, 100'000'000);
      cut.rig->machine().set_mains_ok(false);
      cut.rig->run_until([&] { return cut.rig->status().servo.state == control::State::Faulted; }, 100000);
      cut.rig->run(3);
      cut.journal->flush();
      pf = recorder->report();
      for (double l : cut.journal->latencies_ms()) latencies.push_back(l);
      r = cut.journal->last_written().value_or(recovery::BreakpointRecord{});
      const std::span<const float> b = cut.rig->machine().broach_bore();
      bore.assign(b.begin(), b.end());
    }
    if (pf.coupled) {
      coupled_max = std::max(coupled_max, pf.coupled_error_um);
      independent_max = std::max(independent_max, pf.independent_error_um);
    }
    double dev = 0;
    if (r.valid) {
      std::vector<std::string> sets;
      for (const auto& [name, axis] : {std::pair{"x", Axis::X}, {"z", Axis::Z}, {"c", Axis::C}}) {
        sets.push_back(fmt::format("axis.{}.sim.start_position={:.17g}", name, r.actual[axis]));
        sets.push_back(fmt::format("axis.{}.homing.position={:.17g}", name, r.actual[axis]));
      }
      Rig after(profile_path, dir, sets);
      after.rig->machine().restore_broach_bore(bore);  // the groove cut before the power failed
      const control::Outcome o = after.rig->request(Request::feature("journal", "resume"), 1000000);
      // Bounded: the rest of the job cannot take longer than the whole of it.
      const std::string why =
          o.accepted ? recovery::run_recovery(*after.rig, *after.journal, {length_s + 10, 2.0}) : o.message;
      if (why.empty()) {
        ++resumed;
        dev = deviation_um(*after.grooves, *ref.grooves, r, after.profile.coupling.radius_mm);
        resume_max = std::max(resume_max, dev);
        moving_max = std::max(
            moving_max, deviation_um(*after.grooves, *ref.grooves, r, after.profile.coupling.radius_mm, 1.0));
      } else {
        ++failed;
        fmt::print(stderr, "cut {} at {:.3f} s: resume failed: {}: {}\n", k, cut_s, o.message, why);
      }
    }
    if (!json) {
      fmt::print(
          "cut {:3} at {:8.3f} s  coupled {:.3f} um  independent {:9.1f} um  resumed groove {:.3f} um\n", k,
          cut_s, pf.coupled ? pf.coupled_error_um : 0.0, pf.coupled ? pf.independent_error_um : 0.0, dev);
    }
  }
  std::sort(latencies.begin(), latencies.end());
  const double p99 =
      latencies.empty()
          ? 0
          : latencies[std::min(latencies.size() - 1,
                               static_cast<std::size_t>(0.99 * static_cast<double>(latencies.size())))];
  const double pmax = latencies.empty() ? 0 : latencies.back();
  std::filesystem::remove_all(root);
  if (json) {
    fmt::print(
        "{{\"cuts\": {}, \"resumed\": {}, \"resume_failed\": {}, \"coupled_error_um_max\": {:.6f}, "
        "\"independent_error_um_max\": {:.6f}, \"resume_deviation_um_max\": {:.6f}, "
        "\"resume_deviation_um_max_past_1mm\": {:.6f}, \"record_p99_ms\": {:.6f}, \"record_max_ms\": {:.6f}, "
        "\"program_s\": {:.3f}}}\n",
        cuts, resumed, failed, coupled_max, independent_max, resume_max, moving_max, p99, pmax, length_s);
  } else {
    fmt::print(
        "coupled {:.3f} um max, independent {:.1f} um max, resumed groove {:.3f} um max ({:.3f} past the "
        "first mm "
        "of each move; {} of {} resumed), record p99 {:.3f} ms (max {:.3f})\n",
        coupled_max, independent_max, resume_max, moving_max, resumed, cuts, p99, pmax);
  }
  return failed == 0 ? 0 : 1;
}
