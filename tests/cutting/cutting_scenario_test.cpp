// SPDX-License-Identifier: GPL-3.0-or-later
// Whole programs through the controller on the simulated plasma table (configs/plasma-table.toml,
// a plate warped ±5 mm): the height held within ±0.1 mm, no dive at corners and kerf crossings,
// within the axes' limits; without height control it is not; an arc loss held, pierced again and
// the path completed; a bad [process.plasma] refused at its key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/control/servo_setup.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/cutting/cutting_recorder.hpp"
#include "opencnc/features/features.hpp"

namespace opencnc::controller::test {
namespace {

config::MachineProfile table(std::vector<std::string> sets = {}) {
  return control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/plasma-table.toml", sets));
}

/// The Z of every period, and the lowest and highest Z commanded.
class Samples final : public ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const TraceContext&) override {
    z.push_back(s.commanded[2]);
    torch.push_back(s.torch);
    velocity.push_back(s.path_velocity);
    segment = std::max(segment, s.segment);
  }
  std::vector<double> z;
  std::vector<control::TorchStatus> torch;
  std::vector<double> velocity;
  std::uint64_t segment = 0;
};

struct Cut {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<cutting::CuttingRecorder> recorder;
  std::shared_ptr<Samples> samples;
  cutting::CuttingReport report;
  bool finished = false;
  std::vector<std::string> notes;
};

/// examples/plasma-nest.ngc (or `file`) run to its end on `profile`; `each` between periods.
Cut run(const config::MachineProfile& profile, const std::function<void(Cut&)>& each = {},
        const std::string& file = OPENCNC_SOURCE_DIR "/examples/plasma-nest.ngc") {
  Cut c;
  Diagnostics d;
  c.rig = std::make_unique<SimRig>(profile, *features::machine_setup(profile, d));
  c.recorder = std::make_shared<cutting::CuttingRecorder>(profile.plasma.config, profile.plasma.sim,
                                                          profile.servo_period_s);
  c.samples = std::make_shared<Samples>();
  c.rig->controller().attach(c.recorder, ObserverOptions{0, true});
  c.rig->controller().attach(c.samples, ObserverOptions{0, true});
  EventCursor events(c.rig->controller().events());
  c.rig->step();
  EXPECT_TRUE(c.rig->request(Request::simple(control::CommandKind::MachineOn)).accepted);
  EXPECT_TRUE(c.rig->request(Request::set_mode(control::Mode::Auto)).accepted);
  const Outcome opened = c.rig->request(Request::open(file), 100000);
  EXPECT_TRUE(opened.accepted) << opened.message;
  if (!opened.accepted) return c;
  EXPECT_TRUE(c.rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  c.finished = c.rig->run_until(
      [&] {
        if (each) each(c);
        for (const ControllerEvent& e : events.next())
          if (e.kind == ControllerEventKind::Note) c.notes.push_back(e.code);
        return !c.rig->status().run_active && c.rig->status().servo.state == control::State::Idle;
      },
      400000);
  c.report = c.recorder->report();
  return c;
}

/// Most Z acceleration of the commanded path, by second differences.
double max_z_acceleration(const std::vector<double>& z, double period_s) {
  double most = 0;
  for (std::size_t i = 2; i < z.size(); ++i)
    most = std::max(most, std::fabs(z[i] - 2 * z[i - 1] + z[i - 2]) / (period_s * period_s));
  return most;
}

TEST(CuttingScenario, TheNestHoldsTheCutHeightOnAWarpedPlateWithoutDiving) {
  const config::MachineProfile p = table();
  const Cut c = run(p);
  ASSERT_TRUE(c.finished);
  const cutting::CuttingReport& r = c.report;
  EXPECT_TRUE(r.height_measured);
  EXPECT_GT(r.cutting_s, 100);
  EXPECT_GE(r.height_in_band_fraction, 0.95);
  EXPECT_LE(r.max_dive_mm, 0.2);
  EXPECT_EQ(r.pierces, 12u);  // 7 holes, 3 outlines, 2 skeleton cuts
  EXPECT_EQ(r.arc_losses, 0u);
  EXPECT_EQ(r.failed_starts, 0u);
  EXPECT_GE(r.void_locks, 1u) << "the skeleton cut crosses the first one's kerf";
  // The plate under the cuts is warped by several mm: the offset did the work.
  double lo = 1e9, hi = -1e9;
  for (const control::TorchStatus& t : c.samples->torch) {
    if (t.phase != control::TorchPhase::Cutting) continue;
    lo = std::min(lo, t.plate_z_mm);
    hi = std::max(hi, t.plate_z_mm);
  }
  EXPECT_GT(hi - lo, 3.0);
  // Within the torch axis' soft limits and acceleration (0 limit violations).
  const config::AxisProfile* z = p.find(Axis::Z);
  ASSERT_NE(z, nullptr);
  for (double v : c.samples->z) {
    ASSERT_GE(v, z->min_limit);
    ASSERT_LE(v, z->max_limit);
  }
  EXPECT_LE(max_z_acceleration(c.samples->z, p.servo_period_s), z->max_acceleration * 1.001);
}

TEST(CuttingScenario, WithoutHeightControlOrItsLocksTheTorchLeavesTheBand) {
  // Without height control the torch keeps the height it pierced at while the warped plate rises
  // into it: the float switch trips while it burns and holds the run, torch out (no operator here).
  const Cut off = run(table({"process.plasma.thc.enabled=false"}));
  EXPECT_FALSE(off.finished) << "held where the torch touched the plate";
  EXPECT_EQ(off.report.float_trips, 1u);
  EXPECT_NE(std::find(off.notes.begin(), off.notes.end(), "control.torch.float-tripped"), off.notes.end());
  EXPECT_LT(off.report.height_in_band_fraction, 0.5);
  EXPECT_GT(off.report.max_dive_mm, 1.0);
  // Height control with no corner, void or anti-dive lock dives where the voltage jumps.
  const Cut unlocked = run(table({"process.plasma.thc.speed_share=0.05", "process.plasma.thc.void_jump_v=500",
                                  "process.plasma.thc.anti_dive_accel=100000"}));
  ASSERT_TRUE(unlocked.finished);
  EXPECT_GT(unlocked.report.max_dive_mm, 0.5);
}

TEST(CuttingScenario, AnArcLossHoldsThenTheResumePiercesAgainAndThePathIsCompleted) {
  const config::MachineProfile p = table();
  const Cut whole = run(p);
  bool lost = false, resumed = false;
  double held_z = 0;
  const Cut c = run(p, [&](Cut& k) {
    SimRig& rig = *k.rig;
    const control::ServoStatus& s = rig.status().servo;
    if (!lost && s.torch.phase == control::TorchPhase::Cutting && s.time_s > 40) {
      rig.machine().inject_arc_loss();
      lost = true;
    }
    if (lost && !resumed && s.state == control::State::Held && s.path_velocity == 0) {
      EXPECT_FALSE(s.torch.torch_on);
      EXPECT_EQ(s.torch.arc_losses, 1u);
      held_z = s.commanded[2];
      resumed = true;
      rig.controller().submit(Request::simple(control::CommandKind::Resume));
    }
  });
  ASSERT_TRUE(lost);
  ASSERT_TRUE(resumed);
  ASSERT_TRUE(c.finished);
  EXPECT_EQ(c.report.arc_losses, 1u);
  EXPECT_EQ(c.report.pierces, whole.report.pierces + 1) << "pierced again where it held";
  EXPECT_EQ(c.samples->segment, whole.samples->segment) << "the path complete to its last move";
  EXPECT_GE(c.report.height_in_band_fraction, 0.95);
  EXPECT_NE(std::find(c.notes.begin(), c.notes.end(), "control.torch.arc-lost"), c.notes.end());
  EXPECT_LT(held_z, 10.0) << "held at the cut height, not lifted to the program's";
}

TEST(CuttingScenario, HolesBelowTheDiameterAreCutAtTheReducedVelocityWithTheHeightHeld) {
  // [process.plasma.holes]: 32 mm, 60 % — the nest's six 24 and 14 mm holes (F1500: 15 mm/s),
  // not its 40 mm one nor the outlines (F2400: 40 mm/s).
  const config::MachineProfile p = table();
  const Cut c = run(p);
  ASSERT_TRUE(c.finished);
  EXPECT_EQ(c.report.holes_slowed, 6u);
  EXPECT_EQ(c.report.pierces, 12u);
  double hole_v = 0, other_v = 0;
  for (std::size_t i = 0; i < c.samples->torch.size(); ++i) {
    const control::TorchStatus& t = c.samples->torch[i];
    if (t.phase != control::TorchPhase::Cutting) continue;
    const double v = c.samples->velocity[i];
    (t.thc == control::ThcState::ProgramLock ? hole_v : other_v) =
        std::max(t.thc == control::ThcState::ProgramLock ? hole_v : other_v, v);
  }
  EXPECT_LE(hole_v, 0.6 * 1500 / 60.0 + 1e-6) << "holes at 60 % of F1500, shown in the trace";
  EXPECT_GT(hole_v, 0.6 * 1500 / 60.0 * 0.95);
  EXPECT_GT(other_v, 1500 / 60.0) << "the rest at its programmed feed";
  EXPECT_GE(c.report.height_in_band_fraction, 0.95);
  EXPECT_LE(c.report.max_dive_mm, 0.2);
  // Without the diameter, the holes are cut as programmed.
  const Cut plain = run(table({"process.plasma.holes.diameter=0"}));
  ASSERT_TRUE(plain.finished);
  EXPECT_EQ(plain.report.holes_slowed, 0u);
  EXPECT_LT(plain.report.cutting_s, c.report.cutting_s);
}

TEST(CuttingScenario, RunsAreRepeatableBitForBit) {
  const config::MachineProfile p = table();
  const Cut a = run(p), b = run(p);
  ASSERT_EQ(a.samples->z.size(), b.samples->z.size());
  EXPECT_TRUE(a.samples->z == b.samples->z);
}

TEST(CuttingConfig, BadKeysAreRefusedAtTheirPlace) {
  const auto refused = [](std::vector<std::string> sets, const std::string& words) {
    const config::ProfileLoad load =
        config::load_profile(OPENCNC_SOURCE_DIR "/configs/plasma-table.toml", sets);
    EXPECT_FALSE(load.ok());
    std::string all;
    for (const auto& d : load.diagnostics.items()) all += d.format() + "\n";
    EXPECT_NE(all.find(words), std::string::npos) << all;
  };
  refused({"process.plasma.cut_height=5"}, "process.plasma.cut_height (5) is above the pierce height");
  refused({"process.plasma.sensor_input=9"}, "process.plasma.sensor_input is digital input 9");
  refused({"process.plasma.thc.max_velocity=500"}, "process.plasma.thc.max_velocity (500) is more than");
  refused({"process.plasma.sensor=\"laser\""}, "process.plasma.sensor must be one of float, ohmic");
  refused({"process.torch=false"}, "[process] torch = true");
  refused({"process.plasma.thc.speed_share=1.5"}, "speed_share is a share of the feed");
}

TEST(CuttingConfig, AMachineWithoutPlasmaHasNoTorchStage) {
  const config::MachineProfile mill = control::test::mill();
  EXPECT_FALSE(mill.plasma.present);
  EXPECT_EQ(control::servo_config(mill, {}).plasma.enabled, 0);
  const config::MachineProfile p = table();
  EXPECT_EQ(control::servo_config(p, {}).plasma.enabled, 1);
  EXPECT_EQ(control::servo_config(p, {}).plasma.cut_height_mm, 1.5);
}

}  // namespace
}  // namespace opencnc::controller::test
