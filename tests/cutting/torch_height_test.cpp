// SPDX-License-Identifier: GPL-3.0-or-later
// TorchHeight on its own: the sequence of a cut against a plate and a voltage the test makes, the
// height control's locks, its speed and acceleration limits, failed starts.
#include <gtest/gtest.h>

#include <cmath>

#include "opencnc/control/torch_height.hpp"

namespace opencnc::control {
namespace {

constexpr double kPeriod = 1e-3;

machine::PlasmaConfig config() {
  machine::PlasmaConfig c;
  c.enabled = 1;
  return c;
}

/// A flat plate at `plate_z` under a torch programmed at `programmed_z`: the float switch trips
/// switch_offset below it; the voltage is 100 V + 7.5 V/mm of height + `extra_v`.
struct World {
  double plate_z = -3.2, programmed_z = 15, extra_v = 0;
  bool arc = true;
  double velocity = 40, feed = 40;
  TorchInputs inputs(const TorchHeight& t) const {
    TorchInputs in;
    in.programmed_z = programmed_z;
    in.measured_z = programmed_z + t.offset_mm();
    in.sensor = in.measured_z <= plate_z - t.config().switch_offset_mm;
    in.arc_ok = arc && t.torch_on();
    const double height = in.measured_z - plate_z;
    in.arc_voltage_v = in.arc_ok ? 100 + 7.5 * height + extra_v : 0.0;
    in.path_velocity = velocity;
    in.feed = feed;
    return in;
  }
};

/// Steps until `done` or `periods` have passed; the last z of the torch in `z`.
template <typename F>
bool run(TorchHeight& t, World& w, int periods, F done) {
  for (int i = 0; i < periods; ++i) {
    t.step(w.inputs(t));
    if (done()) return true;
  }
  return false;
}

TEST(TorchHeight, FindsThePlatePiercesAndGoesToTheCutHeight) {
  TorchHeight t;
  t.configure(config(), kPeriod);
  World w;
  EXPECT_FALSE(t.apply_code(180, 1));  // not the torch's
  ASSERT_TRUE(t.apply_code(machine::kTorchOnCode, 0));
  EXPECT_EQ(t.status().phase, TorchPhase::Probing);
  ASSERT_TRUE(run(t, w, 5000, [&] { return t.status().phase == TorchPhase::Igniting; }));
  EXPECT_TRUE(t.head_waits());
  // The plate as found: the trip point plus the float's travel, within one period of probing.
  EXPECT_NEAR(t.status().plate_z_mm, w.plate_z, t.config().probe_speed_mm_s * kPeriod + 1e-9);
  EXPECT_NEAR(w.programmed_z + t.offset_mm(), t.status().plate_z_mm + t.config().pierce_height_mm, 1e-9);
  ASSERT_TRUE(run(t, w, 10, [&] { return t.status().phase == TorchPhase::Piercing; }));
  EXPECT_TRUE(t.torch_on());
  EXPECT_EQ(t.status().pierces, 1u);
  // The pierce delay, then down to the cut height; the path waits until it is there.
  int pierce_periods = 0;
  ASSERT_TRUE(run(t, w, 2000, [&] {
    ++pierce_periods;
    return t.status().phase != TorchPhase::Piercing;
  }));
  EXPECT_NEAR(pierce_periods * kPeriod, t.config().pierce_delay_s, 2 * kPeriod);
  ASSERT_TRUE(run(t, w, 2000, [&] { return t.status().phase == TorchPhase::Cutting; }));
  EXPECT_FALSE(t.head_waits());
  EXPECT_NEAR(w.programmed_z + t.offset_mm(), t.status().plate_z_mm + t.config().cut_height_mm, 1e-9);
  // Torch off: back up to the programmed height, the path waiting meanwhile.
  ASSERT_TRUE(t.apply_code(machine::kTorchOffCode, 0));
  EXPECT_FALSE(t.torch_on());
  ASSERT_TRUE(run(t, w, 5000, [&] { return t.status().phase == TorchPhase::Off; }));
  EXPECT_EQ(t.offset_mm(), 0.0);
}

// Cutting with the voltage sampled; then the plate's height changes under the torch (a voltage
// the test adds): the control brings the voltage back, within its speed and acceleration.
TorchHeight cutting(World& w, machine::PlasmaConfig c = config()) {
  TorchHeight t;
  t.configure(c, kPeriod);
  t.apply_code(machine::kTorchOnCode, 0);
  run(t, w, 20000, [&] { return t.status().thc == ThcState::Active; });
  return t;
}

TEST(TorchHeight, CorrectsTheHeightWithinItsSpeedAndAcceleration) {
  World w;
  TorchHeight t = cutting(w);
  ASSERT_EQ(t.status().thc, ThcState::Active);
  // The voltage at the cut height above the plate as found (within one period of probing).
  EXPECT_NEAR(t.status().target_voltage_v, 100 + 7.5 * 1.5, 7.5 * t.config().probe_speed_mm_s * kPeriod);
  w.plate_z += 2;  // the plate rises 2 mm at once: the voltage falls by 15 V (held: a void) …
  run(t, w, 200, [] { return false; });
  EXPECT_NEAR(t.status().correction_mm, 0, 0.01) << "a jump of 15 V is a void: held";
  w.plate_z -= 2 - 0.4;  // … a slope of 0.4 mm is corrected
  double z0 = t.offset_mm(), v0 = 0, vmax = 0, amax = 0;
  for (int i = 0; i < 1000; ++i) {
    t.step(w.inputs(t));
    const double v = (t.offset_mm() - z0) / kPeriod;
    vmax = std::max(vmax, std::fabs(v));
    amax = std::max(amax, std::fabs(v - v0) / kPeriod);
    z0 = t.offset_mm();
    v0 = v;
  }
  EXPECT_NEAR(t.status().correction_mm, 0.4, 0.05);
  EXPECT_LE(vmax, t.config().max_velocity_mm_s + 1e-9);
  EXPECT_LE(amax, t.config().max_accel_mm_s2 * (1 + 1e-9));
}

TEST(TorchHeight, HoldsAtCornersWhileBrakingAndWhenTheProgramSaysSo) {
  World w;
  TorchHeight t = cutting(w);
  w.extra_v = 3;              // the torch would go down by 0.4 mm if it were let
  w.velocity = w.feed - 0.5;  // still at speed but braking at 500 mm/s²
  t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::AntiDive);
  w.velocity = 0.5 * w.feed;  // a corner
  t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::CornerLock);
  w.velocity = w.feed;
  t.apply_code(machine::kThcHoldCode, 0);
  for (int i = 0; i < 100; ++i) t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::ProgramLock);
  EXPECT_NEAR(t.status().correction_mm, 0, 1e-6);
  t.apply_code(machine::kThcReleaseCode, 0);
  for (int i = 0; i < 1000; ++i) t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::Active);
  EXPECT_NEAR(t.status().correction_mm, -3 / 7.5, 0.05);
}

TEST(TorchHeight, AVoltageJumpHoldsTheHeightAndTheCorrectionStaysWithinItsLimit) {
  World w;
  machine::PlasmaConfig c = config();
  c.max_correction_mm = 0.3;
  TorchHeight t = cutting(w, c);
  w.extra_v = 25;  // a kerf crossing
  for (int i = 0; i < 30; ++i) t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::VoidLock);
  EXPECT_LT(std::fabs(t.status().correction_mm), 0.01);
  w.extra_v = 0;
  for (int i = 0; i < 60; ++i) t.step(w.inputs(t));
  EXPECT_EQ(t.status().thc, ThcState::VoidLock) << "held for void_hold_s after the voltage is back";
  w.extra_v = -4;  // a real 0.53 mm rise of the plate: corrected only to the limit
  for (int i = 0; i < 2000; ++i) t.step(w.inputs(t));
  EXPECT_NEAR(t.status().correction_mm, 0.3, 1e-12);
}

TEST(TorchHeight, AnArcLossPutsTheTorchOutHoldsAndAResumePiercesAgain) {
  World w;
  TorchHeight t = cutting(w);
  w.arc = false;
  bool held = false;
  for (int i = 0; i < 20 && !held; ++i) {
    t.step(w.inputs(t));
    held = t.hold_requested();
    if (held) {
      EXPECT_EQ(t.event(), TorchEvent::ArcLost);
    }
  }
  ASSERT_TRUE(held);
  EXPECT_FALSE(t.torch_on());
  EXPECT_EQ(t.status().arc_losses, 1u);
  EXPECT_EQ(t.status().phase, TorchPhase::Paused);
  TorchInputs in = w.inputs(t);
  in.hold = true;  // the tick holds the run
  t.step(in);
  w.arc = true;
  ASSERT_TRUE(run(t, w, 20000, [&] { return t.status().phase == TorchPhase::Cutting; }));
  EXPECT_EQ(t.status().pierces, 2u);
}

/// An arc loss while cutting, held and resumed (the tick's hold, then none).
void lose_the_arc_and_resume(TorchHeight& t, World& w) {
  w.arc = false;
  for (int i = 0; i < 20 && t.status().phase != TorchPhase::Paused; ++i) t.step(w.inputs(t));
  ASSERT_EQ(t.status().phase, TorchPhase::Paused);
  TorchInputs in = w.inputs(t);
  in.hold = true;
  t.step(in);
  w.arc = true;
}

// The cut that goes on after an arc loss — pierced again where it held, or at a retrace's point
// back over the kerf it had cut (a voltage 25 V higher there) — keeps the voltage it had sampled
// on the plate: sampled over the kerf, the height would be held too high (a void lock) on solid
// plate for the rest of the cut. A cut ended by its M191, or a run that does not resume the
// program, samples its own.
TEST(TorchHeight, ACutGoingOnAfterAnInterruptionKeepsTheVoltageItHadSampled) {
  World w;
  TorchHeight t = cutting(w);
  const double sampled = t.status().target_voltage_v;
  ASSERT_GT(sampled, 0);
  lose_the_arc_and_resume(t, w);
  t.begin_run();  // the retrace: the program aborted, its auxiliary moves, the resume at C …
  t.begin_run();
  t.apply_code(machine::kTorchOnCode, 0);  // … replays the torch on
  w.extra_v = 25;                          // over the kerf already cut
  ASSERT_TRUE(run(t, w, 20000, [&] { return t.status().phase == TorchPhase::Cutting; }));
  EXPECT_EQ(t.status().target_voltage_v, sampled) << "not sampled again over the kerf";
  bool sampling = false;
  run(t, w, 500, [&] {
    sampling = sampling || t.status().thc == ThcState::Sampling;
    return false;
  });
  EXPECT_FALSE(sampling);
  EXPECT_EQ(t.status().thc, ThcState::VoidLock) << "the kerf: held";
  w.extra_v = 0;  // solid plate again: followed
  ASSERT_TRUE(run(t, w, 2000, [&] { return t.status().thc == ThcState::Active; }));
  EXPECT_NEAR(t.status().correction_mm, 0, 0.01);

  // Ended by its M191: the next cut samples its own.
  lose_the_arc_and_resume(t, w);
  t.apply_code(machine::kTorchOffCode, 0);
  run(t, w, 5000, [&] { return t.status().phase == TorchPhase::Off; });
  w.extra_v = 6;
  t.apply_code(machine::kTorchOnCode, 0);
  ASSERT_TRUE(run(t, w, 20000, [&] { return t.status().thc == ThcState::Active; }));
  EXPECT_NEAR(t.status().target_voltage_v, sampled + 6, 0.1);

  // Interrupted, then another run (not a resume): it samples its own.
  w.extra_v = 0;
  lose_the_arc_and_resume(t, w);
  t.begin_run();
  t.forget_interrupted_cut();
  w.extra_v = 3;
  t.apply_code(machine::kTorchOnCode, 0);
  ASSERT_TRUE(run(t, w, 20000, [&] { return t.status().thc == ThcState::Active; }));
  EXPECT_NEAR(t.status().target_voltage_v, sampled + 3, 0.1);
}

TEST(TorchHeight, TheBreakawayOrTheFloatSwitchWhileBurningPutsTheTorchOutAndHolds) {
  for (const bool breakaway : {true, false}) {
    World w;
    TorchHeight t = cutting(w);
    TorchInputs in = w.inputs(t);
    (breakaway ? in.breakaway : in.sensor) = true;  // knocked, or the torch pressed down on the plate
    t.step(in);
    ASSERT_TRUE(t.event_pending());
    EXPECT_EQ(t.event(), breakaway ? TorchEvent::Breakaway : TorchEvent::FloatTripped);
    EXPECT_TRUE(t.hold_requested());
    EXPECT_FALSE(t.torch_on());
    EXPECT_EQ(t.status().phase, TorchPhase::Paused);
    EXPECT_EQ(t.status().breakaways, breakaway ? 1u : 0u);
    EXPECT_EQ(t.status().float_trips, breakaway ? 0u : 1u);
    in = w.inputs(t);
    in.hold = true;            // the tick holds the run
    in.breakaway = breakaway;  // still open while held: told once
    t.step(in);
    EXPECT_FALSE(t.event_pending()) << "told once";
    ASSERT_TRUE(run(t, w, 20000, [&] { return t.status().phase == TorchPhase::Cutting; }));
    EXPECT_EQ(t.status().pierces, 2u) << "a resume pierces again";
  }
}

// The float switch is the probe's own signal while the torch looks for the plate: no trip there.
TEST(TorchHeight, TheFloatSwitchWhileProbingIsThePlateNotATrip) {
  World w;
  TorchHeight t = cutting(w);
  EXPECT_EQ(t.status().float_trips, 0u);
  EXPECT_EQ(t.status().pierces, 1u);
}

TEST(TorchHeight, TooManyFailedStartsHoldTheRun) {
  World w;
  w.arc = false;
  TorchHeight t;
  t.configure(config(), kPeriod);
  t.apply_code(machine::kTorchOnCode, 0);
  int failed = 0;
  bool exhausted = false;
  for (int i = 0; i < 20000 && !exhausted; ++i) {
    t.step(w.inputs(t));
    if (t.event_pending() && t.event() == TorchEvent::StartFailed) ++failed;
    exhausted = t.event_pending() && t.event() == TorchEvent::StartsExhausted;
    if (exhausted) {
      EXPECT_TRUE(t.hold_requested());
    }
  }
  ASSERT_TRUE(exhausted);
  EXPECT_EQ(failed, t.config().max_starts - 1);
  EXPECT_EQ(t.status().failed_starts, static_cast<std::uint32_t>(t.config().max_starts));
  EXPECT_EQ(t.status().phase, TorchPhase::Failed);
}

TEST(TorchHeight, NoPlateWithinTheProbesTravelHoldsTheRun) {
  World w;
  w.plate_z = -100;
  TorchHeight t;
  t.configure(config(), kPeriod);
  t.apply_code(machine::kTorchOnCode, 0);
  ASSERT_TRUE(run(t, w, 20000, [&] { return t.event_pending(); }));
  EXPECT_EQ(t.event(), TorchEvent::PlateNotFound);
  EXPECT_TRUE(t.hold_requested());
  EXPECT_GE(t.offset_mm(), -t.config().probe_travel_mm);
}

}  // namespace
}  // namespace opencnc::control
