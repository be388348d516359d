// SPDX-License-Identifier: GPL-3.0-or-later
// powerfail_sweep: the mains cut at N random instants (fixed seed) through the constant-pitch demo
// job on the simulated broach; for each, the coupled stop's helix error against each axis stopping
// alone, the breakpoint record's latency (signal to durable), and the job resumed from the record on
// a machine powered up where the axes rest — its groove against the uninterrupted run's. With
// --json the output lists every cut too (its instant and errors), so that an outlier can be found
// and replayed; --stop-only skips the resumes (the stops alone, about ten times faster).
//
//   powerfail_sweep [--cuts N] [--seed S] [--program FILE] [--journal-root DIR] [--set KEY=VALUE]...
//                   [--stop-only] [--json]
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/broaching/power_fail_recorder.hpp"
#include "opencnc/broaching/recovery_wait.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

namespace {

using namespace opencnc;
using controller::Request;

/// The feedback of every coupled period of the main program, by the interpreter's segment id.
class Grooves final : public controller::ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override {
    if (c.job != controller::JobKind::Program || c.program == nullptr || !s.coupled ||
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
    auto machine = features::machine_setup(
        profile, d, controller::MachineSetup::Options::with("journal", journal_dir.string()));
    rig = std::make_unique<controller::SimRig>(profile, *machine);
    journal = std::dynamic_pointer_cast<recovery::BreakpointJournal>(machine->feature("journal"));
    grooves = std::make_shared<Grooves>();
    rig->controller().attach(grooves, controller::ObserverOptions{0, true});
    rig->step();
    rig->request(Request::simple(control::CommandKind::MachineOn));
    rig->request(Request::set_mode(control::Mode::Auto));
  }
  config::MachineProfile profile;
  std::unique_ptr<controller::SimRig> rig;
  std::shared_ptr<recovery::BreakpointJournal> journal;
  std::shared_ptr<Grooves> grooves;
};

/// A point of a groove on the bore's surface: Z (mm) and the arc of C (mm at the bore's radius),
/// C unwrapped along the track.
using TrackPoint = std::array<double, 2>;

double to_segment_mm(const TrackPoint& q, const TrackPoint& a, const TrackPoint& b) {
  const double dz = b[0] - a[0], ds = b[1] - a[1];
  const double len2 = dz * dz + ds * ds;
  const double t = len2 > 0 ? std::clamp(((q[0] - a[0]) * dz + (q[1] - a[1]) * ds) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(q[0] - a[0] - t * dz, q[1] - a[1] - t * ds);
}

/// Largest distance on the bore (µm) from the resumed groove to the uninterrupted run's: every
/// period of every segment from the breakpoint on (the run-in left out) against the nearest point
/// of the reference's track of the same segment, in the (Z, arc of C) plane — how far the cutter
/// ran from the groove the uninterrupted run cut, whatever the timing along it. Both tracks advance
/// with time, so each period searches a window of the reference around the last match.
/// Only the periods with Z in [z_min, z_max] count (the bore: the groove is in the workpiece; at
/// the strokes' ends the cutter is in the air). `skip_mm`: leave out the first millimetres of every
/// segment (where both break away from rest).
struct Span {
  double z_min = -1e300, z_max = 1e300, skip_mm = 0;
};
double deviation_um(const Grooves& resumed, const Grooves& ref, const recovery::BreakpointRecord& r,
                    double radius_mm, Span span) {
  constexpr std::ptrdiff_t kWindow = 64;  // periods either side of the last match
  const double mm_per_deg = std::numbers::pi / 180 * radius_mm;
  const double dir = r.move_end[Axis::Z] >= r.move_start[Axis::Z] ? 1.0 : -1.0;
  double worst_mm = 0;
  for (const auto& [segment, rows] : resumed.by_segment) {
    const auto it = ref.by_segment.find(segment);
    if (it == ref.by_segment.end() || it->second.size() < 2) continue;
    std::vector<TrackPoint> track;  // the reference, C unwrapped
    double c_unwrapped = it->second.front().second;
    for (std::size_t i = 0; i < it->second.size(); ++i) {
      if (i > 0) c_unwrapped += std::remainder(it->second[i].second - it->second[i - 1].second, 360.0);
      track.push_back({it->second[i].first, c_unwrapped * mm_per_deg});
    }
    const auto n = static_cast<std::ptrdiff_t>(track.size());
    const double first_z = it->second.front().first;
    std::ptrdiff_t j = -1;  // the reference's vertex matched last
    for (const auto& [z, c] : rows) {
      if (segment == r.segment && (z - r.actual[Axis::Z]) * dir < 0) continue;  // the run-in
      if (std::fabs(z - first_z) < span.skip_mm || z < span.z_min || z > span.z_max) continue;
      if (j < 0) {  // the first period: the nearest vertex in Z
        j = 0;
        for (std::ptrdiff_t k = 1; k < n; ++k)
          if (std::fabs(track[k][0] - z) < std::fabs(track[j][0] - z)) j = k;
      }
      double best = 1e300;
      std::ptrdiff_t best_k = j;
      for (std::ptrdiff_t k = std::max<std::ptrdiff_t>(0, j - kWindow); k + 1 < n && k <= j + kWindow; ++k) {
        const double c_deg = track[k][1] / mm_per_deg;  // C in the track's turns
        const TrackPoint q{z, (c_deg + std::remainder(c - c_deg, 360.0)) * mm_per_deg};
        const double d = to_segment_mm(q, track[k], track[k + 1]);
        if (d <= best) {  // ties: the later (a stationary stretch is passed, not stuck on)
          best = d;
          best_k = k;
        }
      }
      j = best_k;
      worst_mm = std::max(worst_mm, best);
    }
  }
  return worst_mm * 1000;
}

/// The earlier measure, kept for comparison: the largest difference on the bore (µm) of the
/// resumed groove's C from the reference's at the same Z (C interpolated in Z), segment by segment,
/// from the breakpoint on. Ill-posed where Z turns (a stroke's end: the overshoot and the settling
/// give two C for one Z), which is where its maxima were.
/// `skip_mm`: leave out the first millimetres of every segment (where both runs break away from rest).
double same_z_deviation_um(const Grooves& resumed, const Grooves& ref, const recovery::BreakpointRecord& r,
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
             "usage: powerfail_sweep [--cuts N] [--seed S] [--program FILE] [--journal-root DIR]\n"
             "                       [--set KEY=VALUE]... [--stop-only] [--json]\n"
             "  the mains cut at N random instants of the broach's demo job: coupled and independent stop\n"
             "  errors, record latency, and the resumed groove against the uninterrupted run's\n"
             "  --set        override a key of configs/broach-zc.toml in every run (as opencnc run --set):\n"
             "               e.g. power.sim.ups_runtime_s=0 power.dc_link_capacitance_f=0.00004 (a nearly\n"
             "               empty DC link: the stops shortened by its energy)\n"
             "  --stop-only  measure the stops, do not resume\n"
             "  --json       one JSON object: the maxima, and \"per_cut\": each cut's instant and errors\n");
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  int cuts = 20;
  unsigned seed = 20261126;
  bool json = false, stop_only = false;
  std::string program = OPENCNC_SOURCE_DIR "/examples/broach-constant.ngc";
  std::filesystem::path root = std::filesystem::current_path() / "powerfail-sweep";
  std::vector<std::string> profile_sets;  // --set, for every run
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    if (a == "--help" || a == "-h") return usage(0);
    if (a == "--json") {
      json = true;
    } else if (a == "--stop-only") {
      stop_only = true;
    } else if (a == "--cuts" || a == "--seed" || a == "--program" || a == "--journal-root" || a == "--set") {
      const char* v = value();
      if (v == nullptr) return usage(2);
      if (a == "--set") profile_sets.emplace_back(v);
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
  {
    const config::ProfileLoad load = config::load_profile(profile_path, profile_sets);
    if (!load.ok()) {
      for (const auto& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
      return 2;
    }
  }
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
      fmt::print(stderr, "powerfail_sweep: --journal-root {} is not a folder the sweep can use\n",
                 root.string());
      return 2;
    }
  }
  // The uninterrupted run, once.
  std::filesystem::remove_all(root);
  Rig ref(profile_path, root / "reference", profile_sets);
  ref.rig->request(Request::open(program), 1000000);
  ref.rig->request(Request::simple(control::CommandKind::CycleStart));
  ref.rig->run_until([&] { return !ref.rig->status().run_active && ref.rig->status().servo.time_s > 1; },
                     100'000'000);
  const double length_s = ref.rig->status().servo.time_s;

  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(0.5, length_s - 0.5);
  double coupled_max = 0, independent_max = 0, resume_max = 0, moving_max = 0, same_z_max = 0, track_max = 0;
  double scale_max = 1, energy_at_rest_min = 1e300;  // the stops shortened by the DC link's energy
  std::vector<double> latencies;
  int resumed = 0, failed = 0;
  std::string per_cut;  // JSON objects, one per cut
  for (int k = 0; k < cuts; ++k) {
    const double cut_s = at(rng);
    const auto dir = root / fmt::format("cut-{}", k);
    recovery::BreakpointRecord r;
    broaching::PowerFailReport pf;
    std::vector<float> bore;  // the workpiece as the cut left it
    {
      Rig cut(profile_path, dir, profile_sets);
      auto recorder = std::make_shared<broaching::PowerFailRecorder>(
          control::coupling_config(cut.profile.coupling), controller::machine_limits(cut.profile),
          cut.profile.servo_period_s, cut.profile.coupling.radius_mm);
      cut.rig->controller().attach(recorder, controller::ObserverOptions{cut.profile.servo_period_s, true});
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
    if (pf.happened) {
      scale_max = std::max(scale_max, pf.decel_scale);
      energy_at_rest_min = std::min(energy_at_rest_min, pf.energy_at_rest_j);
    }
    double dev = 0;
    if (r.valid && !stop_only) {
      std::vector<std::string> sets = profile_sets;
      for (const auto& [name, axis] : {std::pair{"x", Axis::X}, {"z", Axis::Z}, {"c", Axis::C}}) {
        sets.push_back(fmt::format("axis.{}.sim.start_position={:.17g}", name, r.actual[axis]));
        sets.push_back(fmt::format("axis.{}.homing.position={:.17g}", name, r.actual[axis]));
      }
      Rig after(profile_path, dir, sets);
      after.rig->machine().restore_broach_bore(bore);  // the groove cut before the power failed
      const controller::Outcome o = after.rig->request(Request::feature("journal", "resume"), 1000000);
      // Bounded: the rest of the job cannot take longer than the whole of it.
      const std::string why =
          o.accepted ? recovery::run_recovery(*after.rig, *after.journal, {length_s + 10, 2.0}) : o.message;
      if (why.empty()) {
        ++resumed;
        const double radius = after.profile.coupling.radius_mm;
        const machine::SimBroachConfig& b = after.profile.broaching.sim;
        const Span in_bore{b.bore_start, b.bore_end, 0};
        dev = deviation_um(*after.grooves, *ref.grooves, r, radius, in_bore);
        resume_max = std::max(resume_max, dev);
        moving_max = std::max(moving_max, deviation_um(*after.grooves, *ref.grooves, r, radius,
                                                       {b.bore_start, b.bore_end, 1.0}));
        track_max = std::max(track_max, deviation_um(*after.grooves, *ref.grooves, r, radius, {}));
        same_z_max = std::max(same_z_max, same_z_deviation_um(*after.grooves, *ref.grooves, r, radius));
      } else {
        ++failed;
        fmt::print(stderr, "cut {} at {:.3f} s: resume failed: {}: {}\n", k, cut_s, o.message, why);
      }
    }
    per_cut += fmt::format(
        "{}{{\"cut\": {}, \"at_s\": {:.6f}, \"coupled\": {}, \"coupled_error_um\": {:.6f}, "
        "\"independent_error_um\": {:.6f}, \"resume_deviation_um\": {:.6f}, \"decel_scale\": {:.6f}, "
        "\"energy_at_rest_j\": {:.6f}}}",
        k == 0 ? "" : ", ", k, cut_s, pf.coupled, pf.coupled ? pf.coupled_error_um : 0.0,
        pf.coupled ? pf.independent_error_um : 0.0, dev, pf.decel_scale, pf.energy_at_rest_j);
    if (!json) {
      fmt::print(
          "cut {:3} at {:8.3f} s  coupled {:.3f} um  independent {:9.1f} um  resumed groove {:.3f} um\n", k,
          cut_s, pf.coupled ? pf.coupled_error_um : 0.0, pf.coupled ? pf.independent_error_um : 0.0, dev);
    }
  }
  std::sort(latencies.begin(), latencies.end());
  // Nearest rank: the ⌈0.99·n⌉-th smallest (with fewer than 100 records, the largest).
  const double p99 =
      latencies.empty()
          ? 0
          : latencies[static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(latencies.size()))) - 1];
  const double pmax = latencies.empty() ? 0 : latencies.back();
  std::filesystem::remove_all(root);
  if (json) {
    fmt::print(
        "{{\"cuts\": {}, \"resumed\": {}, \"resume_failed\": {}, \"coupled_error_um_max\": {:.6f}, "
        "\"independent_error_um_max\": {:.6f}, \"resume_deviation_um_max\": {:.6f}, "
        "\"resume_deviation_um_max_past_1mm\": {:.6f}, \"resume_deviation_whole_track_um_max\": {:.6f}, "
        "\"resume_deviation_same_z_um_max\": {:.6f}, "
        "\"decel_scale_max\": {:.6f}, \"energy_at_rest_j_min\": {:.6f}, "
        "\"record_p99_ms\": {:.6f}, \"record_max_ms\": {:.6f}, \"program_s\": {:.3f}, \"per_cut\": [{}]}}\n",
        cuts, resumed, failed, coupled_max, independent_max, resume_max, moving_max, track_max, same_z_max,
        scale_max, energy_at_rest_min < 1e300 ? energy_at_rest_min : 0.0, p99, pmax, length_s, per_cut);
  } else {
    fmt::print(
        "coupled {:.3f} um max, independent {:.1f} um max, resumed groove {:.3f} um max ({:.3f} past the "
        "first mm "
        "of each move; {:.3f} um on the whole track, outside the bore too; {:.3f} um by C at the same Z; {} "
        "of {} resumed), record p99 {:.3f} ms (max {:.3f})\n",
        coupled_max, independent_max, resume_max, moving_max, track_max, same_z_max, resumed, cuts, p99,
        pmax);
  }
  return failed == 0 ? 0 : 1;
}
