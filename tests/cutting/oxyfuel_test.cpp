// SPDX-License-Identifier: GPL-3.0-or-later
// The oxy-fuel torch: the stage on its own (the capacitive sensor's reading to a height, the
// preheat by time and by the operator's start, the cutting oxygen, the height control on the
// sensor with its jump lock), the simulated sensor over a plate with a kerf, [process.oxyfuel]'s
// errors, and examples/oxyfuel-bracket.ngc through the controller on configs/oxyfuel-table.toml
// (a plate warped ±5 mm) with the preheat by time and by the operator's start.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/control/servo_setup.hpp"
#include "opencnc/control/torch_height.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/cutting/cutting_recorder.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/machine/cut_chart_codes.hpp"
#include "opencnc/machine/sim_plasma_process.hpp"

namespace opencnc::control {
namespace {

constexpr double kPeriod = 1e-3;

machine::PlasmaConfig oxy(machine::PreheatMode mode = machine::PreheatMode::Time) {
  machine::PlasmaConfig c;
  c.enabled = 1;
  c.process = machine::TorchProcess::OxyFuel;
  c.preheat = mode;
  c.preheat_s = 2;
  c.ignite_s = 0.5;
  c.preheat_height_mm = 6;
  c.pierce_height_mm = 12;
  c.pierce_delay_s = 1;
  c.cut_height_mm = 7;
  c.sensor_volts_per_mm = 0.4;
  c.sensor_zero_v = 0.5;
  c.sensor_range_mm = 25;
  c.height_jump_mm = 1;
  c.deadband_mm = 0.02;
  c.time_constant_s = 0.05;
  c.max_velocity_mm_s = 20;
  c.max_accel_mm_s2 = 500;
  c.void_hold_s = 0.1;
  c.filter_s = 0.005;
  c.thc_delay_s = 0.1;
  c.cut_oxygen_output = 2;
  return c;
}

/// A plate at `plate_z` under a torch programmed at `programmed_z`; the sensor reads the height
/// plus `extra_mm` (a kerf under it), saturated at its range, as volts. No arc, ever.
struct World {
  double plate_z = -3.2, programmed_z = 30, extra_mm = 0;
  double velocity = 10, feed = 10;
  TorchInputs inputs(const TorchHeight& t) const {
    TorchInputs in;
    in.programmed_z = programmed_z;
    in.measured_z = programmed_z + t.offset_mm();
    const machine::PlasmaConfig& c = t.config();
    const double h = std::min(in.measured_z - plate_z + extra_mm, c.sensor_range_mm);
    in.height_v = c.sensor_zero_v + c.sensor_volts_per_mm * h;
    in.path_velocity = velocity;
    in.feed = feed;
    return in;
  }
  double height(const TorchHeight& t) const { return programmed_z + t.offset_mm() - plate_z; }
};

template <typename F>
bool run(TorchHeight& t, World& w, int periods, F done, std::vector<TorchEvent>* told = nullptr) {
  for (int i = 0; i < periods; ++i) {
    t.step(w.inputs(t));
    if (told && t.event_pending()) told->push_back(t.event());
    if (done()) return true;
  }
  return false;
}

TEST(OxyFuelTorch, SensesThePlatePreheatsByTimeOpensTheOxygenAndCutsAtTheCutHeight) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  EXPECT_TRUE(t.status().oxy_fuel);
  World w;
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  // Out of the sensor's range at Z30 (33.2 mm up): down until it reads the plate, no contact.
  ASSERT_TRUE(run(t, w, 5000, [&] { return t.status().phase == TorchPhase::ToPierce; }));
  EXPECT_LT(w.height(t), 25.0 + 1e-9);
  EXPECT_NEAR(t.status().plate_z_mm, w.plate_z, 0.02);  // the filter's lag while moving down
  ASSERT_TRUE(run(t, w, 5000, [&] { return t.status().phase == TorchPhase::Igniting; }));
  EXPECT_NEAR(w.height(t), 6, 0.02);  // the preheat height
  EXPECT_TRUE(t.torch_on());
  EXPECT_FALSE(t.status().cut_oxygen);
  std::vector<TorchEvent> told;
  int periods = 0;
  ASSERT_TRUE(run(
      t, w, 2000, [&] { return ++periods, t.status().phase == TorchPhase::Preheating; }, &told));
  EXPECT_NEAR(periods * kPeriod, 0.5, 2 * kPeriod);  // ignite_s
  EXPECT_EQ(t.status().preheats, 1u);
  EXPECT_FALSE(t.status().waiting_start);
  EXPECT_TRUE(t.head_waits());
  periods = 0;
  ASSERT_TRUE(run(
      t, w, 5000, [&] { return ++periods, t.status().phase == TorchPhase::Piercing; }, &told));
  EXPECT_NEAR(periods * kPeriod, 2.0, 2 * kPeriod);  // preheat_s
  EXPECT_NEAR(t.status().preheat_s, 2.0, 2 * kPeriod);
  EXPECT_NEAR(t.status().preheat_total_s, 2.0, 2 * kPeriod);
  EXPECT_EQ(t.status().pierces, 1u);
  EXPECT_EQ(t.status().operator_starts, 0u);
  EXPECT_TRUE(t.status().cut_oxygen);
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0], TorchEvent::CutStarted);
  // The pierce rises to the pierce height with the oxygen on, then down to the cut height.
  double highest = 0;
  ASSERT_TRUE(run(t, w, 5000, [&] {
    highest = std::max(highest, w.height(t));
    return t.status().phase == TorchPhase::Cutting;
  }));
  EXPECT_NEAR(highest, 12, 0.03);
  EXPECT_NEAR(w.height(t), 7, 0.03);
  EXPECT_FALSE(t.head_waits());
  EXPECT_FALSE(t.hold_requested());
  // Torch off: oxygen and flame off, back up to the programmed height.
  ASSERT_TRUE(t.apply_code(machine::kTorchOffCode, 0));
  ASSERT_TRUE(run(t, w, 5000, [&] { return t.status().phase == TorchPhase::Off; }));
  EXPECT_FALSE(t.torch_on());
  EXPECT_FALSE(t.status().cut_oxygen);
  EXPECT_EQ(t.offset_mm(), 0.0);
}

TEST(OxyFuelTorch, AnOperatorPreheatWaitsForTheStartAndStartCutEndsIt) {
  TorchHeight t;
  t.configure(oxy(machine::PreheatMode::Operator), kPeriod);
  World w;
  EXPECT_FALSE(t.start_cut());  // nothing to start
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  std::vector<TorchEvent> told;
  ASSERT_TRUE(run(
      t, w, 10000, [&] { return t.status().phase == TorchPhase::Preheating; }, &told));
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0], TorchEvent::PreheatWaits);
  EXPECT_FALSE(t.hold_requested());  // it waits, it does not hold the run
  // Far past any preheat time: still preheating, the path waiting.
  EXPECT_FALSE(run(t, w, 10000, [&] { return t.status().phase != TorchPhase::Preheating; }));
  EXPECT_TRUE(t.status().waiting_start);
  EXPECT_TRUE(t.head_waits());
  EXPECT_FALSE(t.status().cut_oxygen);
  EXPECT_NEAR(t.status().preheat_s, 10.0, 2 * kPeriod);
  EXPECT_TRUE(t.start_cut());
  t.step(w.inputs(t));
  EXPECT_EQ(t.status().phase, TorchPhase::Piercing);
  EXPECT_TRUE(t.status().cut_oxygen);
  EXPECT_FALSE(t.status().waiting_start);
  EXPECT_EQ(t.status().operator_starts, 1u);
  EXPECT_EQ(t.status().pierces, 1u);
  EXPECT_FALSE(t.start_cut());  // the cut runs: nothing to start
}

TEST(OxyFuelTorch, StartCutEndsATimedPreheatEarly) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  World w;
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  ASSERT_TRUE(run(t, w, 10000, [&] { return t.status().phase == TorchPhase::Preheating; }));
  ASSERT_TRUE(run(t, w, 600, [] { return false; }) == false);
  ASSERT_TRUE(t.start_cut());
  t.step(w.inputs(t));
  EXPECT_EQ(t.status().phase, TorchPhase::Piercing);
  EXPECT_NEAR(t.status().preheat_s, 0.601, 2 * kPeriod);
  EXPECT_EQ(t.status().operator_starts, 1u);
}

TEST(OxyFuelTorch, ACutChartRowsPreheatReplacesTheProfilesForTheRun) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  World w;
  ASSERT_TRUE(t.apply_chart_code(machine::kChartPreheatCode, 3.5));
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  ASSERT_TRUE(run(t, w, 10000, [&] { return t.status().phase == TorchPhase::Preheating; }));
  ASSERT_TRUE(run(t, w, 10000, [&] { return t.status().phase == TorchPhase::Piercing; }));
  EXPECT_NEAR(t.status().preheat_s, 3.5, 2 * kPeriod);
  ASSERT_TRUE(t.apply_chart_code(machine::kChartPreheatCode, 0));  // 0: the profile's again
  EXPECT_EQ(t.config().preheat_s, 2.0);
  ASSERT_TRUE(t.apply_chart_code(machine::kChartPreheatCode, 5));
  t.begin_run();  // the next run starts from the profile's
  EXPECT_EQ(t.config().preheat_s, 2.0);
}

TEST(OxyFuelTorch, AFeedHoldDuringThePreheatPutsTheFlameOutAndAResumePreheatsAgain) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  World w;
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  ASSERT_TRUE(run(t, w, 10000, [&] { return t.status().phase == TorchPhase::Preheating; }));
  TorchInputs in = w.inputs(t);
  in.hold = true;
  t.step(in);
  EXPECT_EQ(t.status().phase, TorchPhase::Paused);
  EXPECT_FALSE(t.torch_on());
  t.step(in);  // the hold seen, then the resume
  ASSERT_TRUE(run(t, w, 10000, [&] { return t.status().phase == TorchPhase::Preheating; }));
  EXPECT_EQ(t.status().preheats, 2u);
  EXPECT_EQ(t.status().preheat_s, 0.0);  // a new preheat from the start
}

/// Into the cut, at speed.
void cutting(TorchHeight& t, World& w) {
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  ASSERT_TRUE(run(t, w, 20000, [&] { return t.status().phase == TorchPhase::Cutting; }));
  ASSERT_TRUE(run(t, w, 300, [&] { return t.status().thc == ThcState::Active; }));
}

TEST(OxyFuelTorch, TheHeightControlFollowsThePlateByTheSensorWithinItsLimits) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  World w;
  cutting(t, w);
  EXPECT_EQ(t.status().target_voltage_v, 0.0);  // no voltage: the sensor's height is held
  // The plate rises 3 mm at 0.5 mm/s: the torch follows within 0.1 mm, the correction no
  // faster than its speed limit.
  double worst = 0, last = t.offset_mm(), fastest = 0;
  for (int i = 0; i < 6000; ++i) {
    w.plate_z += 0.5 * kPeriod;
    t.step(w.inputs(t));
    if (i > 500) worst = std::max(worst, std::fabs(w.height(t) - 7));
    fastest = std::max(fastest, std::fabs(t.offset_mm() - last) / kPeriod);
    last = t.offset_mm();
  }
  EXPECT_LT(worst, 0.1);
  EXPECT_LE(fastest, t.config().max_velocity_mm_s + 1e-9);
  EXPECT_NEAR(t.status().correction_mm, 3.0, 0.1);
  EXPECT_NEAR(t.status().sensor_height_mm, 7.0, 0.1);
  // Below the share of the feed (a corner): held.
  w.velocity = 2;
  t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::CornerLock);
  w.velocity = 10;
  // M192 holds it too.
  ASSERT_TRUE(t.apply_code(machine::kThcHoldCode, 0));
  t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::ProgramLock);
  ASSERT_TRUE(t.apply_code(machine::kThcReleaseCode, 0));
}

TEST(OxyFuelTorch, AKerfOrThePlatesEdgeUnderTheSensorHoldsTheHeight) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  World w;
  cutting(t, w);
  ASSERT_TRUE(run(t, w, 500, [] { return false; }) == false);
  const double before = t.offset_mm();
  // A kerf: the sensor reads 2 mm more for 0.2 s. The height is held, and for jump_hold_s after.
  w.extra_mm = 2;
  bool locked = false;
  for (int i = 0; i < 200; ++i) {
    t.step(w.inputs(t));
    locked = locked || t.status().thc == ThcState::VoidLock;
  }
  EXPECT_TRUE(locked);
  EXPECT_NEAR(t.offset_mm(), before, 0.05);  // no climb out of the kerf (the filter's first periods)
  w.extra_mm = 0;
  t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::VoidLock);
  ASSERT_TRUE(run(t, w, 300, [&] { return t.status().thc == ThcState::Active; }));
  EXPECT_NEAR(w.height(t), 7, 0.06);
  // Off the plate's edge the sensor reads its range: held, no dive into the void.
  w.extra_mm = 100;
  const double at_edge = t.offset_mm();
  ASSERT_TRUE(run(t, w, 1000, [] { return false; }) == false);
  EXPECT_EQ(t.status().thc, ThcState::VoidLock);
  EXPECT_FALSE(t.status().sensor);  // out of range
  EXPECT_NEAR(t.offset_mm(), at_edge, 0.05);
  EXPECT_EQ(t.status().arc_losses, 0u);  // no arc, no arc loss
  EXPECT_FALSE(t.hold_requested());
}

// Sensed over a kerf already cut (a retrace's C on its own path): the ring reads 2 mm more, so the
// plate is taken 2 mm low and the torch cuts the kerf 2 mm lower than it should; on solid plate
// the reading is 2 mm under the cut height, which is followed up (never a dive), not held.
TEST(OxyFuelTorch, APlateSensedOverAKerfIsFollowedUpOnceTheKerfEnds) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  World w;
  w.extra_mm = 2;
  cutting(t, w);
  EXPECT_NEAR(t.status().plate_z_mm, w.plate_z - 2, 0.05) << "taken low over the kerf";
  EXPECT_NEAR(w.height(t), 5, 0.06);
  w.extra_mm = 0;  // the kerf ends
  bool locked = false;
  run(t, w, 1000, [&] {
    locked = locked || t.status().thc == ThcState::VoidLock;
    return false;
  });
  EXPECT_FALSE(locked);
  EXPECT_EQ(t.status().thc, ThcState::Active);
  EXPECT_NEAR(w.height(t), 7, 0.06) << "up to the cut height";
}

TEST(OxyFuelTorch, WithoutThePlateInTheSensorsReachWithinTheTravelTheRunIsHeld) {
  TorchHeight t;
  t.configure(oxy(), kPeriod);
  World w;
  w.plate_z = -100;
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  std::vector<TorchEvent> told;
  ASSERT_TRUE(run(
      t, w, 20000, [&] { return t.status().phase == TorchPhase::Failed; }, &told));
  EXPECT_EQ(told.back(), TorchEvent::PlateNotFound);
  EXPECT_FALSE(t.torch_on());
}

TEST(SimOxyFuel, TheSensorReadsTheHeightHigherOverAKerfAndItsRangeOffThePlate) {
  machine::SimPlasmaConfig c;
  c.present = true;
  c.oxy_fuel = true;
  c.height_input = 1;
  c.cut_oxygen_output = 2;
  c.sensor_volts_per_mm = 0.4;
  c.sensor_zero_v = 0.5;
  c.sensor_range_mm = 25;
  c.height_noise_mm = 0.02;
  c.kerf_height_mm = 2;
  c.kerf_width_mm = 2;
  c.plate_min[0] = c.plate_min[1] = 0;
  c.plate_max[0] = c.plate_max[1] = 500;
  machine::SimPlasmaProcess sim;
  sim.configure(c, kPeriod);
  machine::MachineInputs in;
  const auto height = [&] {
    sim.sample(in);
    return (in.analog_in[1] - 0.5) / 0.4;
  };
  sim.step(100, 100, 7, true, false);
  EXPECT_NEAR(height(), 7, 0.02 + 1e-9);
  EXPECT_FALSE(in.process.arc_ok);  // a flame: no arc-OK
  EXPECT_EQ(in.analog_in[0], 0.0);  // no arc voltage
  // The flame alone cuts nothing; the cutting oxygen cuts a kerf along Y = 100.
  for (int i = 0; i <= 1000; ++i) sim.step(100 + 0.1 * i, 100, 7, true, false);
  EXPECT_FALSE(sim.kerf_at(150, 100));
  for (int i = 0; i <= 1000; ++i) sim.step(100 + 0.1 * i, 100, 7, true, true);
  sim.step(300, 300, 7, true, false);  // away: the trail behind the torch is marked
  sim.step(300, 300, 7, false, false);
  EXPECT_TRUE(sim.kerf_at(150, 100));
  // Across it, the oxygen off: the sensor reads 2 mm more over the kerf.
  sim.step(150, 97, 7, false, false);
  EXPECT_NEAR(height(), 7, 0.02 + 1e-9);
  sim.step(150, 100, 7, false, false);
  EXPECT_NEAR(height(), 9, 0.02 + 1e-9);
  EXPECT_NEAR(sim.sensed_height_mm(), 9, 1e-9);
  // Off the plate: its range.
  sim.step(600, 100, 7, false, false);
  EXPECT_NEAR(height(), 25, 1e-9);
  // Far above the plate: its range too.
  sim.step(200, 200, 40, false, false);
  EXPECT_NEAR(height(), 25, 1e-9);
}

}  // namespace
}  // namespace opencnc::control

namespace opencnc::controller::test {
namespace {

config::MachineProfile table(std::vector<std::string> sets = {}) {
  return control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/oxyfuel-table.toml", sets));
}

class Samples final : public ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const TraceContext&) override {
    z.push_back(s.commanded[2]);
    last = s.torch;
    if (s.torch.phase == control::TorchPhase::Cutting) {
      lo = std::min(lo, s.torch.plate_z_mm);
      hi = std::max(hi, s.torch.plate_z_mm);
    }
    if (s.torch.phase == control::TorchPhase::Preheating && s.path_velocity > 0) ++moved_while_preheating;
  }
  std::vector<double> z;
  control::TorchStatus last{};
  double lo = 1e9, hi = -1e9;
  int moved_while_preheating = 0;
};

struct Cut {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<Samples> samples;
  cutting::CuttingReport report;
  bool finished = false;
  std::vector<std::string> notes;
  std::vector<Outcome> starts;
  int oxygen_mismatch = 0;  ///< periods whose cutting oxygen output differs from the stage's
  int oxygen_on = 0;
};

/// examples/oxyfuel-bracket.ngc run to its end on `profile`; with `start_after_s` the operator
/// starts each preheat that waits for them that long after it began.
Cut run(const config::MachineProfile& profile, double start_after_s = -1) {
  Cut c;
  Diagnostics d;
  c.rig = std::make_unique<SimRig>(profile, *features::machine_setup(profile, d));
  auto recorder = std::make_shared<cutting::CuttingRecorder>(profile.plasma.config, profile.plasma.sim,
                                                             profile.servo_period_s);
  c.samples = std::make_shared<Samples>();
  c.rig->controller().attach(recorder, ObserverOptions{0, true});
  c.rig->controller().attach(c.samples, ObserverOptions{0, true});
  EventCursor events(c.rig->controller().events());
  c.rig->step();
  EXPECT_TRUE(c.rig->request(Request::simple(control::CommandKind::MachineOn)).accepted);
  EXPECT_TRUE(c.rig->request(Request::set_mode(control::Mode::Auto)).accepted);
  const Outcome refused = c.rig->request(Request::simple(control::CommandKind::StartCut));
  EXPECT_FALSE(refused.accepted);  // no preheat under way
  EXPECT_NE(refused.message.find("no preheat is under way"), std::string::npos) << refused.message;
  const Outcome opened =
      c.rig->request(Request::open(OPENCNC_SOURCE_DIR "/examples/oxyfuel-bracket.ngc"), 100000);
  EXPECT_TRUE(opened.accepted) << opened.message;
  if (!opened.accepted) return c;
  EXPECT_TRUE(c.rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  std::uint64_t asked = 0;
  std::uint32_t started = 0;  // the preheat the operator last started (one press each)
  c.finished = c.rig->run_until(
      [&] {
        const ControllerStatus& st = c.rig->status();
        const control::TorchStatus& t = st.servo.torch;
        const bool oxygen = ((st.servo.digital_out >> 2) & 1u) != 0;
        c.oxygen_mismatch += oxygen != t.cut_oxygen ? 1 : 0;
        c.oxygen_on += oxygen ? 1 : 0;
        if (asked != 0 && c.rig->controller().outcome(asked)) {
          c.starts.push_back(*c.rig->controller().outcome(asked));
          asked = 0;
        }
        if (start_after_s >= 0 && asked == 0 && t.waiting_start && t.preheat_s >= start_after_s &&
            t.preheats != started) {
          asked = c.rig->controller().submit(Request::simple(control::CommandKind::StartCut));
          started = t.preheats;
        }
        for (const ControllerEvent& e : events.next())
          if (e.kind == ControllerEventKind::Note) c.notes.push_back(e.code);
        return !st.run_active && st.servo.state == control::State::Idle;
      },
      1000000);
  c.report = recorder->report();
  return c;
}

TEST(OxyFuelScenario, TheBracketPreheatsByTimeAndHoldsTheCutHeightOnAWarpedPlate) {
  const config::MachineProfile p = table();
  ASSERT_TRUE(p.plasma.present);
  ASSERT_TRUE(p.plasma.config.oxy_fuel());
  const Cut c = run(p);
  ASSERT_TRUE(c.finished);
  const cutting::CuttingReport& r = c.report;
  EXPECT_TRUE(r.oxy_fuel);
  EXPECT_TRUE(r.height_measured);
  EXPECT_EQ(r.pierces, 4u);  // the bore, the outline, two skeleton cuts
  EXPECT_EQ(r.preheats, 4u);
  EXPECT_EQ(r.operator_starts, 0u);
  EXPECT_NEAR(r.preheat_s, 4 * 4.0, 4 * 2e-3);
  EXPECT_GT(r.cutting_s, 120);
  EXPECT_GE(r.height_in_band_fraction, 0.95);
  EXPECT_LE(r.max_dive_mm, 0.2);
  EXPECT_EQ(r.arc_losses, 0u);
  EXPECT_GE(r.void_locks, 1u) << "the second skeleton cut crosses the first one's kerf";
  EXPECT_GT(c.samples->hi - c.samples->lo, 3.0) << "the plate under the cuts is warped";
  EXPECT_EQ(c.oxygen_mismatch, 0) << "the cutting oxygen output follows the stage";
  EXPECT_GT(c.oxygen_on, 0);
  EXPECT_EQ(c.samples->moved_while_preheating, 0) << "the path waits while the flame preheats";
  EXPECT_FALSE(c.samples->last.torch_on);
  EXPECT_FALSE(c.samples->last.cut_oxygen);
  const config::AxisProfile* z = p.find(Axis::Z);
  ASSERT_NE(z, nullptr);
  for (double v : c.samples->z) {
    ASSERT_GE(v, z->min_limit);
    ASSERT_LE(v, z->max_limit);
  }
  EXPECT_NE(std::find(c.notes.begin(), c.notes.end(), "control.torch.cut-started"), c.notes.end());
}

TEST(OxyFuelScenario, AnOperatorPreheatWaitsUntilStartCut) {
  const config::MachineProfile p = table({"process.oxyfuel.preheat=\"operator\""});
  ASSERT_EQ(p.plasma.config.preheat, machine::PreheatMode::Operator);
  const Cut c = run(p, 6.5);
  ASSERT_TRUE(c.finished);
  const cutting::CuttingReport& r = c.report;
  EXPECT_EQ(r.preheats, 4u);
  EXPECT_EQ(r.operator_starts, 4u);
  ASSERT_EQ(c.starts.size(), 4u);
  for (const Outcome& o : c.starts) EXPECT_TRUE(o.accepted) << o.message;
  EXPECT_NEAR(r.preheat_s, 4 * 6.5, 4 * 0.01);  // the operator's, not the profile's 4 s
  EXPECT_GE(r.height_in_band_fraction, 0.95);
  EXPECT_LE(r.max_dive_mm, 0.2);
  EXPECT_NE(std::find(c.notes.begin(), c.notes.end(), "control.torch.preheat-waits"), c.notes.end());
}

TEST(OxyFuelConfig, BadKeysAreRefusedAtTheirPlace) {
  const auto refused = [](std::vector<std::string> sets, const std::string& words) {
    const config::ProfileLoad load =
        config::load_profile(OPENCNC_SOURCE_DIR "/configs/oxyfuel-table.toml", sets);
    EXPECT_FALSE(load.ok());
    std::string all;
    for (const auto& d : load.diagnostics.items()) all += d.format() + "\n";
    EXPECT_NE(all.find(words), std::string::npos) << all;
  };
  refused({"process.oxyfuel.preheat_s=-1"}, "process.oxyfuel.preheat_s must not be negative (it is -1)");
  refused({"process.oxyfuel.preheat=\"forever\""}, "process.oxyfuel.preheat must be one of time, operator");
  refused({"process.oxyfuel.height_input=7"}, "process.oxyfuel.height_input is analog input 7");
  refused({"process.oxyfuel.cut_oxygen_output=9"}, "process.oxyfuel.cut_oxygen_output is digital output 9");
  refused({"process.oxyfuel.cut_height=13"}, "process.oxyfuel.cut_height (13) is above the pierce height");
  refused({"process.oxyfuel.sensor_range=10"}, "process.oxyfuel.sensor_range (10 mm) must reach above");
  refused({"process.oxyfuel.thc.jump=0.01"},
          "process.oxyfuel.thc.jump (0.01) must be more than the deadband");
  refused({"process.oxyfuel.thc.max_velocity=500"}, "process.oxyfuel.thc.max_velocity (500) is more than");
}

TEST(OxyFuelConfig, TheSensorsKeysAreNeededAndOneTorchAMachine) {
  std::string text;
  {
    const config::ProfileLoad load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/oxyfuel-table.toml");
    ASSERT_TRUE(load.ok());
  }
  std::FILE* f = std::fopen(OPENCNC_SOURCE_DIR "/configs/oxyfuel-table.toml", "rb");
  ASSERT_NE(f, nullptr);
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  std::fclose(f);
  const auto refused = [&](const std::string& from, const std::string& to, const std::string& words) {
    std::string t = text;
    const std::size_t at = t.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    const config::ProfileLoad load = config::parse_profile(t, "oxy.toml");
    EXPECT_FALSE(load.ok());
    std::string all;
    for (const auto& d : load.diagnostics.items()) all += d.format() + "\n";
    EXPECT_NE(all.find(words), std::string::npos) << all;
  };
  refused("height_input = 0", "",
          "[process.oxyfuel] needs height_input (its capacitive height sensor's analog input)");
  refused("sensor_volts_per_mm = 0.4", "", "[process.oxyfuel] needs sensor_volts_per_mm");
  refused("cut_oxygen_output = 2", "", "[process.oxyfuel] needs cut_oxygen_output");
  refused("[process.oxyfuel]\n",
          "[process.plasma]\narc_voltage_input = 0\nsensor_input = 0\n[process.oxyfuel]\n",
          "[process.plasma] and [process.oxyfuel] exclude each other");
  const config::MachineProfile p = table();
  const control::ServoConfig s = control::servo_config(p, {});
  EXPECT_EQ(s.plasma.enabled, 1);
  EXPECT_EQ(s.plasma.process, machine::TorchProcess::OxyFuel);
  EXPECT_EQ(s.plasma.cut_oxygen_output, 2);
  EXPECT_EQ(s.plasma.cut_height_mm, 7.0);
}

}  // namespace
}  // namespace opencnc::controller::test
