// SPDX-License-Identifier: GPL-3.0-or-later
// SimJoint: step response, following error against gains, friction stick, quantisation,
// backlash, pitch error, index marks, stepper joints, rotary units.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

#include "opencnc/machine/sim_joint.hpp"

namespace opencnc::machine {
namespace {

constexpr double kPeriod = 0.001;
constexpr int kSubsteps = 10;

SimJointConfig servo_config() {
  SimJointConfig c;
  c.counts_per_unit = 10000;  // 0.1 µm
  c.model.inertia = 100;
  c.model.coulomb_friction = 0;
  c.model.static_friction = 0;
  c.model.viscous_friction = 0;
  c.switches.noise = 0;
  return c;
}

/// Drives a joint through whole periods with one command.
struct JointRig {
  SimJoint joint;
  SplitMix64 rng{7};
  JointInputs in{};

  int whole_periods = 0;  // periods begin_period() integrated at once

  explicit JointRig(const SimJointConfig& c, bool linear_periods = true)
      : joint(c, kPeriod, kSubsteps, linear_periods) {
    joint.sample(in, rng);
  }

  void period(double position, double velocity_ff = 0, bool enable = true, double external = 0) {
    JointOutputs out;
    out.position = position;
    out.velocity_ff = velocity_ff;
    out.enable = enable;
    joint.begin_period(out, true, external);
    whole_periods += joint.needs_substeps() ? 0 : 1;
    for (int i = 0; i < kSubsteps; ++i) joint.substep(i);
    joint.end_period();
    joint.sample(in, rng);
  }
  void steps(std::int64_t step_position, bool enable = true) {
    JointOutputs out;
    out.step_position = step_position;
    out.enable = enable;
    joint.begin_period(out, true, 0);
    for (int i = 0; i < kSubsteps; ++i) joint.substep(i);
    joint.end_period();
    joint.sample(in, rng);
  }
};

// With the velocity loop ~15× faster than the position loop, a step answers like a first-
// order lag with time constant 1/Kp: 63 % after 1/Kp, within 0.1 µm after ~16/Kp.
TEST(SimJoint, StepResponseIsFirstOrderWithPositionGain) {
  for (double kp : {30.0, 60.0}) {
    SimJointConfig c = servo_config();
    c.model.position_gain = kp;
    JointRig rig(c);
    const int tau_periods = static_cast<int>(std::lround(1.0 / kp / kPeriod));
    for (int k = 0; k < tau_periods; ++k) rig.period(1.0);
    EXPECT_NEAR(rig.joint.motor_position(), 1.0 - std::exp(-1.0), 0.05) << "Kp " << kp;
    double peak = 0;
    for (int k = 0; k < 15 * tau_periods; ++k) {
      rig.period(1.0);
      peak = std::max(peak, rig.joint.motor_position());
    }
    EXPECT_NEAR(rig.in.position, 1.0, 2e-4) << "Kp " << kp;
    EXPECT_LT(peak, 1.01) << "overshoot with Kp " << kp;
  }
}

// Following error as the servo tick measures it: the next command minus the feedback
// sampled at the end of this period.

// Ramp without feed-forward: the staircase reference lags the ramp by T/2 on average and the
// P position loop adds v/Kp, so the error is v·(1/Kp + T/2) (plus v·h/2 from the drive's own
// sampling). The model must produce this, and halve the 1/Kp part when the gain doubles.
TEST(SimJoint, FollowingErrorWithoutFeedForwardIsVelocityOverGain) {
  const double v = 50.0;  // mm/s
  for (double kp : {25.0, 50.0, 100.0}) {
    SimJointConfig c = servo_config();
    c.model.position_gain = kp;
    c.model.feed_forward = 0;
    JointRig rig(c);
    double cmd = 0;
    for (int k = 0; k < 1000; ++k) {
      rig.period(cmd);
      cmd += v * kPeriod;
    }
    const double expected = v * (1.0 / kp + kPeriod / 2);
    EXPECT_NEAR(cmd - rig.in.position, expected, 0.01 * expected) << "Kp " << kp;
  }
}

// With velocity feed-forward the reference is continuous and the velocity loop's integrator
// supplies the friction force, so the steady error is the encoder count, not v/Kp.
TEST(SimJoint, FeedForwardRemovesSteadyFollowingError) {
  SimJointConfig c = servo_config();
  c.model.coulomb_friction = 40;
  c.model.static_friction = 50;
  c.model.viscous_friction = 0.05;
  JointRig rig(c);
  const double v = 100.0;
  double cmd = 0;
  double max_late = 0;
  for (int k = 0; k < 1500; ++k) {
    rig.period(cmd, v);
    cmd += v * kPeriod;
    if (k > 1000) max_late = std::max(max_late, std::abs(cmd - rig.in.position));
  }
  EXPECT_LT(max_late, 2e-4);  // vs v/Kp = 1.7 mm without feed-forward
}

/// A ramp from rest at `accel` (mm/s²) over `periods`: the largest following error, each
/// period's position against where the ramp stands at the period's end.
double ramp_error(JointRig& rig, double accel, int periods) {
  double worst = 0;
  for (int k = 0; k < periods; ++k) {
    const double t = k * kPeriod;
    rig.period(0.5 * accel * t * t, accel * t);
    worst = std::max(worst, std::abs(0.5 * accel * (t + kPeriod) * (t + kPeriod) - rig.in.position));
  }
  return worst;
}

// Following error while accelerating emerges from the loops: the feed-forward velocity is
// held over the period while the needed velocity ramps on, and the velocity loop must build
// the force m·a through its error. It is proportional to the acceleration (a linear system),
// shrinks with a higher position gain, and is far larger without feed-forward.
TEST(SimJoint, FollowingErrorDuringAccelerationFollowsGains) {
  auto max_error = [](double accel, double kp, double ff) {
    SimJointConfig c = servo_config();
    c.model.position_gain = kp;
    c.model.feed_forward = ff;
    JointRig rig(c);
    return ramp_error(rig, accel, 300);
  };
  const double base = max_error(1000, 60, 1);
  EXPECT_GT(base, 1e-3);  // microns, not a constant zero
  EXPECT_NEAR(max_error(2000, 60, 1), 2 * base, 0.05 * base);
  EXPECT_LT(max_error(1000, 120, 1), 0.8 * base);
  EXPECT_GT(max_error(1000, 60, 0), 10 * base);
}

// The drive's torque feed-forward (inertia × the change of v_ff per period): the force to
// accelerate is there from the period the acceleration starts, not built out of following error
// first, so the error of the first periods is far smaller; the whole-period maps give what the
// sub-steps give. (Once the acceleration is steady the integrator holds the force either way.)
TEST(SimJoint, AccelerationFeedForwardGivesTheForceAtTheStartOfAnAcceleration) {
  auto max_error = [](double ka, bool linear_periods) {
    SimJointConfig c = servo_config();
    c.model.acceleration_feed_forward = ka;
    JointRig rig(c, linear_periods);
    return ramp_error(rig, 1000, 5);
  };
  const double without = max_error(0, true);
  const double with = max_error(1, true);
  EXPECT_LT(with, 0.6 * without) << with << " mm against " << without;  // 2.0 µm against 3.9
  EXPECT_NEAR(max_error(1, false), with, 1e-6);
}

/// A ramp from rest to 20 mm/s at 200 mm/s² on a joint with friction; the largest following
/// error of the first 50 ms.
double breakaway_error(SimJointConfig c, double friction_compensation) {
  c.model.friction_compensation = friction_compensation;
  JointRig rig(c);
  return ramp_error(rig, 200, 50);
}

// After a power-up the velocity integrator holds nothing and must build the Coulomb friction out
// of following error before the axis follows; the compensation puts it there at the start.
TEST(SimJoint, FrictionCompensationShortensTheBreakaway) {
  SimJointConfig c = servo_config();
  c.model.coulomb_friction = 40;
  c.model.static_friction = 50;
  const double without = breakaway_error(c, 0);
  const double with = breakaway_error(c, 40);
  EXPECT_GT(without, 1e-3);
  EXPECT_LT(with, 0.6 * without) << with << " mm against " << without;  // 1.4 µm against 2.8
}

// Set, not added: a force the loop already holds in the new direction is kept (the run is the
// same bit for bit as without compensation), and a loop that holds a load beyond static friction
// is moved by the compensation at most, so the load stays held.
TEST(SimJoint, FrictionCompensationKeepsWhatTheLoopHolds) {
  SimJointConfig c = servo_config();
  c.model.coulomb_friction = 40;
  c.model.static_friction = 50;
  auto loaded = [&](double compensation) {
    SimJointConfig k = c;
    k.model.friction_compensation = compensation;
    auto rig = std::make_unique<JointRig>(k);
    for (int i = 0; i < 2000; ++i) rig->period(0, 0, true, -200);  // the loop holds +200 N
    return rig;
  };
  auto up_plain = loaded(0), up_comp = loaded(40);
  EXPECT_GT(up_plain->in.effort, 200 - c.model.static_friction);  // beyond static friction
  for (int k = 1; k <= 100; ++k) {
    up_plain->period(0.5 * 200 * k * k * kPeriod * kPeriod, 200 * k * kPeriod, true, -200);
    up_comp->period(0.5 * 200 * k * k * kPeriod * kPeriod, 200 * k * kPeriod, true, -200);
    ASSERT_EQ(up_plain->in.position, up_comp->in.position) << "period " << k;
  }
  auto down_plain = loaded(0), down_comp = loaded(40);
  down_plain->period(-1e-4, -0.1, true, -200);  // 0.1 mm/s: beyond the drive's dead band
  down_comp->period(-1e-4, -0.1, true, -200);
  EXPECT_NEAR(down_comp->in.effort - down_plain->in.effort, -40, 1);  // not set to −40 N: +160 N
}

TEST(SimJoint, VelocityLimitOfDriveBoundsSpeed) {
  SimJointConfig c = servo_config();
  c.model.velocity_limit = 20;
  JointRig rig(c);
  for (int k = 0; k < 200; ++k) rig.period(100.0);
  EXPECT_NEAR(rig.joint.velocity(), 20.0, 0.05);
}

// P position and P velocity loop: force = Kv·Kp·error, so the axis cannot start while that is
// below static friction: a dead band of Fs/(Kv·Kp).
TEST(SimJoint, StaticFrictionHoldsSmallStepsWithoutIntegrators) {
  SimJointConfig c = servo_config();
  c.model.coulomb_friction = 40;
  c.model.static_friction = 50;
  c.model.velocity_integral_hz = 0;
  c.model.position_integral = 0;
  const double kv = 2 * std::numbers::pi * c.model.velocity_bandwidth_hz * c.model.inertia / 1000.0;
  const double dead_band = c.model.static_friction / (kv * c.model.position_gain);

  JointRig small(c);
  for (int k = 0; k < 500; ++k) small.period(0.5 * dead_band);
  EXPECT_EQ(small.joint.motor_position(), 0.0);  // never moved at all
  EXPECT_EQ(small.joint.velocity(), 0.0);

  JointRig large(c);
  for (int k = 0; k < 500; ++k) large.period(10 * dead_band);
  const double stuck_error = 10 * dead_band - large.joint.motor_position();
  EXPECT_GT(large.joint.motor_position(), 0.0);
  EXPECT_GT(stuck_error, 0.0);               // stopped short …
  EXPECT_LE(stuck_error, dead_band + 1e-4);  // … inside the dead band
  EXPECT_EQ(large.joint.velocity(), 0.0);

  // With a PI velocity loop the integrator winds up until it breaks the axis loose; it then
  // creeps towards the target in stick-slip steps.
  c.model.velocity_integral_hz = 30;
  JointRig pi(c);
  for (int k = 0; k < 2000; ++k) pi.period(0.5 * dead_band);
  EXPECT_NEAR(pi.joint.motor_position(), 0.5 * dead_band, 0.1 * dead_band);
}

TEST(SimJoint, ExternalEffortMustBreakStaticFriction) {
  SimJointConfig c = servo_config();
  c.model.coulomb_friction = 40;
  c.model.static_friction = 50;
  c.model.viscous_friction = 0;
  JointRig held(c);
  for (int k = 0; k < 100; ++k) held.period(0, 0, false, 49.0);
  EXPECT_EQ(held.joint.motor_position(), 0.0);

  JointRig pushed(c);
  for (int k = 0; k < 100; ++k) pushed.period(0, 0, false, 60.0);
  // (60 − 40) N / 100 kg = 0.2 m/s² = 200 mm/s² for 0.1 s.
  EXPECT_NEAR(pushed.joint.velocity(), 20.0, 0.01);
  EXPECT_NEAR(pushed.joint.motor_position(), 0.5 * 200 * 0.1 * 0.1, 0.01);
}

TEST(SimJoint, RotaryJointWorksInDegrees) {
  SimJointConfig c = servo_config();
  c.rotary = true;
  c.model.inertia = 0.5;  // kg·m²
  JointRig rig(c);
  for (int k = 0; k < 100; ++k) rig.period(0, 0, false, 1.0);  // 1 N·m
  // 2 rad/s² = 114.59 °/s² for 0.1 s.
  EXPECT_NEAR(rig.joint.velocity(), 2.0 * 180.0 / std::numbers::pi * 0.1, 1e-6);
}

TEST(SimJoint, FeedbackIsQuantisedByTheEncoder) {
  SimJointConfig c = servo_config();
  c.counts_per_unit = 200;  // 5 µm
  JointRig rig(c);
  for (int k = 0; k < 400; ++k) {
    rig.period(0.3 * std::sin(k * 0.02));
    const double counts = rig.in.position * 200;
    EXPECT_NEAR(counts, std::round(counts), 1e-9);
    EXPECT_LE(rig.in.position, rig.joint.motor_position());
    EXPECT_GT(rig.in.position, rig.joint.motor_position() - 1.0 / 200);
  }
}

// The play operator, seen exactly through a stepper (its motor sits on the step grid).
TEST(SimJoint, BacklashIsLostOnReversal) {
  SimJointConfig c;
  c.drive = JointDrive::Stepper;
  c.counts_per_unit = 1000;
  c.model.backlash = 0.02;
  JointRig rig(c);
  rig.steps(1000);
  EXPECT_DOUBLE_EQ(rig.joint.table_position(), 1.0 - 0.01);
  rig.steps(985);  // back by less than the backlash: the table stays
  EXPECT_DOUBLE_EQ(rig.joint.table_position(), 1.0 - 0.01);
  rig.steps(500);
  EXPECT_DOUBLE_EQ(rig.joint.table_position(), 0.5 + 0.01);
  rig.steps(1500);
  EXPECT_DOUBLE_EQ(rig.joint.table_position(), 1.5 - 0.01);
}

// A servo on a motor encoder closes its loop around the backlash: the motor reaches the
// command and the table ends about half the backlash behind, on the side it came from (the
// motor's small overshoot on stopping takes back a little of it).
TEST(SimJoint, ServoOnMotorEncoderLeavesBacklashInTheTable) {
  SimJointConfig c = servo_config();
  c.model.backlash = 0.02;
  JointRig rig(c);
  for (int k = 0; k < 1000; ++k) rig.period(std::min(1.0, k * 0.002), k < 500 ? 2 : 0);
  EXPECT_NEAR(rig.joint.motor_position(), 1.0, 1e-4);
  EXPECT_NEAR(rig.joint.table_position(), 0.99, 0.002);
  for (int k = 0; k < 1000; ++k) rig.period(std::max(0.0, 1.0 - k * 0.002), k < 500 ? -2 : 0);
  EXPECT_NEAR(rig.joint.motor_position(), 0.0, 1e-4);
  EXPECT_NEAR(rig.joint.table_position(), 0.01, 0.002);
}

TEST(SimJoint, MotorEncoderDoesNotSeePitchErrorButTableScaleDoes) {
  SimJointConfig c = servo_config();
  c.model.pitch_error = {{0, 0}, {100, 0.010}, {200, -0.004}};
  JointRig motor(c);
  c.model.feedback = FeedbackSource::Table;
  JointRig table(c);
  for (int k = 0; k < 3000; ++k) {
    const double cmd = std::min(150.0, 0.1 * k);
    motor.period(cmd, k * 0.1 < 150 ? 100 : 0);
    table.period(cmd, k * 0.1 < 150 ? 100 : 0);
  }
  EXPECT_NEAR(motor.in.position, 150.0, 2e-4);
  EXPECT_NEAR(motor.joint.table_position(), 150.0 + 0.003, 2e-4);
  EXPECT_NEAR(table.in.position, 150.0, 2e-4);
  EXPECT_NEAR(table.joint.table_position(), 150.0, 2e-4);
  EXPECT_NEAR(table.joint.motor_position(), 150.0 - 0.003, 2e-4);
}

// Whole periods at once (SimPeriodMap) against every sub-step with the quantised encoder, on
// mill-3axis's X drive: rests (held by static friction, creeping out of it), accelerations at
// the axis limit, reversals through zero speed, a load step, seeded random moves. The two must
// tell the same story: positions and following errors within a few encoder counts, the same
// energy, and most periods done at once.
TEST(SimJoint, WholePeriodsFollowTheSubSteps) {
  SimJointConfig c;
  c.counts_per_unit = 13107.2;
  c.model.inertia = 150;
  c.model.peak_effort = 4000;
  c.model.coulomb_friction = 40;
  c.model.static_friction = 50;
  c.model.viscous_friction = 0.05;
  c.model.backlash = 0.004;
  c.switches.noise = 0;
  JointRig fast(c, true), exact(c, false);
  SplitMix64 rng(2024);
  double x = 0, v = 0, worst_position = 0, worst_error = 0, energy_fast = 0, energy_exact = 0;
  int periods = 0;
  for (int move = 0; move < 40; ++move) {
    // A rest-to-rest move at up to 100 mm/s and 1000 mm/s² (a trapezoid), then a rest.
    const double target = 50 * rng.symmetric();
    const double peak = 20 + 80 * std::abs(rng.symmetric());
    const double load = move % 7 == 3 ? 300.0 : 0.0;
    while (std::abs(target - x) > 1e-12 || v != 0) {
      const double dir = target > x ? 1.0 : -1.0;
      const double brake = v * v / 2000;
      double v_next = std::abs(target - x) <= brake + std::abs(v) * kPeriod
                          ? std::max(0.0, std::abs(v) - 1.0)
                          : std::min(peak, std::abs(v) + 1.0);
      v_next *= dir;
      x += 0.5 * (v + v_next) * kPeriod;
      if ((target - x) * dir < 0 || v_next == 0) x = target, v_next = 0;
      v = v_next;
      fast.period(x, v, true, load);
      exact.period(x, v, true, load);
      energy_fast += fast.joint.energy_j(), energy_exact += exact.joint.energy_j();
      worst_position =
          std::max(worst_position, std::abs(fast.joint.motor_position() - exact.joint.motor_position()));
      worst_error = std::max(worst_error, std::abs((x - fast.in.position) - (x - exact.in.position)));
      ++periods;
    }
    for (int k = 0; k < 300; ++k) {
      fast.period(x, 0, true, load), exact.period(x, 0, true, load);
      worst_position =
          std::max(worst_position, std::abs(fast.joint.motor_position() - exact.joint.motor_position()));
      ++periods;
    }
  }
  const double count = 1 / c.counts_per_unit;  // 0.076 µm
  EXPECT_LT(worst_position, 0.4 * count);
  EXPECT_LE(worst_error, count + 1e-12);  // the reading may fall on the next count
  EXPECT_NEAR(energy_fast, energy_exact, 1e-4 * std::abs(energy_exact));
  EXPECT_EQ(exact.whole_periods, 0);
  EXPECT_GT(fast.whole_periods, periods * 9 / 10);
}

TEST(PitchErrorTable, InterpolatesLinearlyAndHoldsEnds) {
  PitchErrorTable t({{-10, 0.002}, {0, 0}, {50, 0.005}});
  EXPECT_EQ(t.at(-20), 0.002);
  EXPECT_EQ(t.at(-10), 0.002);
  EXPECT_EQ(t.at(0), 0.0);
  EXPECT_DOUBLE_EQ(t.at(25), 0.0025);
  EXPECT_DOUBLE_EQ(t.at(-5), 0.001);
  EXPECT_EQ(t.at(80), 0.005);
  EXPECT_EQ(PitchErrorTable().at(3), 0.0);
}

// The segment memory must not change results: random jumps agree with a fresh table.
TEST(PitchErrorTable, RandomQueriesMatchAFreshLookup) {
  std::vector<PitchPoint> pts;
  for (int i = 0; i <= 40; ++i) pts.push_back({i * 10.0, 0.001 * std::sin(i)});
  PitchErrorTable walking(pts);
  SplitMix64 rng(42);
  for (int n = 0; n < 20000; ++n) {
    const double s = 210 + 230 * rng.symmetric();
    PitchErrorTable fresh(pts);
    ASSERT_EQ(walking.at(s), fresh.at(s)) << s;
  }
}

TEST(SimJoint, IndexMarksAreCountedAndLatched) {
  SimJointConfig c = servo_config();
  c.model.index_spacing = 5.0;
  c.model.index_offset = 1.25;
  JointRig rig(c);
  double cmd = 0;
  for (int k = 0; k < 2000; ++k) rig.period(cmd += 0.02, 20);  // 0 → 40 mm
  // Marks at 1.25, 6.25, …, 36.25 have been passed (the axis lags the command a little).
  EXPECT_EQ(rig.in.index_count, 8u);
  EXPECT_EQ(rig.in.index_position, 36.25);
  for (int k = 0; k < 500; ++k) rig.period(cmd -= 0.02, -20);  // back to 30 mm
  EXPECT_EQ(rig.in.index_count, 10u);
  EXPECT_EQ(rig.in.index_position, 31.25);
}

TEST(SimJoint, StepperFollowsStepsAndLosesThemWhenDisabled) {
  SimJointConfig c;
  c.drive = JointDrive::Stepper;
  c.counts_per_unit = 400;  // steps per mm
  c.model.start_position = 1.0;
  JointRig rig(c);
  EXPECT_EQ(rig.in.position, 1.0);
  rig.steps(400 + 40);
  EXPECT_EQ(rig.in.position, 1.1);
  EXPECT_DOUBLE_EQ(rig.in.velocity, 0.1 / kPeriod);
  rig.steps(400 + 80, false);
  EXPECT_EQ(rig.in.position, 1.1);  // nothing emitted
  EXPECT_EQ(rig.joint.capabilities().drive, JointDrive::Stepper);
  EXPECT_FALSE(rig.joint.capabilities().index);
}

TEST(SimJoint, DisabledOrFaultedDriveProducesNoForce) {
  SimJointConfig c = servo_config();
  JointRig rig(c);
  rig.joint.set_fault(true);
  for (int k = 0; k < 100; ++k) rig.period(1.0);
  EXPECT_EQ(rig.joint.motor_position(), 0.0);
  EXPECT_TRUE(rig.in.amp_fault);
  rig.joint.set_fault(false);
  for (int k = 0; k < 100; ++k) rig.period(1.0, 0, false);
  EXPECT_EQ(rig.joint.motor_position(), 0.0);
  EXPECT_EQ(rig.in.effort, 0.0);
}

/// A stepper on a 5 mm screw, 200 full steps × 8 = 320 steps/mm, an 80 kg table with friction,
/// and a motor that gives 800 N at standstill, falling to nothing at 150 mm/s.
SimJointConfig dynamic_stepper() {
  SimJointConfig c;
  c.drive = JointDrive::Stepper;
  c.counts_per_unit = 320;
  c.model.inertia = 80;
  c.model.coulomb_friction = 60;
  c.model.static_friction = 75;
  c.model.viscous_friction = 0.1;
  c.model.pullout_effort = 800;
  c.model.pullout_speed = 150;
  c.stall_detector = true;
  return c;
}

/// Step counts of a rest-to-rest trapezoid of `distance` mm at `v` and `a`.
std::vector<std::int64_t> trapezoid_steps(double distance, double v, double a, double spu) {
  std::vector<std::int64_t> out;
  const double t_ramp = v / a, d_ramp = 0.5 * a * t_ramp * t_ramp;
  const double t_total = 2 * t_ramp + (distance - 2 * d_ramp) / v;
  for (double t = kPeriod; t < t_total + 0.05; t += kPeriod) {
    double x;
    if (t < t_ramp) {
      x = 0.5 * a * t * t;
    } else if (t < t_total - t_ramp) {
      x = d_ramp + v * (t - t_ramp);
    } else {
      const double r = std::max(0.0, t_total - t);
      x = distance - 0.5 * a * r * r;
    }
    out.push_back(std::llround(x * spu));
  }
  return out;
}

TEST(SimJoint, StepperWithinItsPullOutCurveMakesEveryStep) {
  JointRig rig(dynamic_stepper());
  // 500 mm/s² needs 40 N on the mass + 60 N friction; at 50 mm/s the motor still gives 533 N.
  for (std::int64_t s : trapezoid_steps(100, 50, 500, 320)) rig.steps(s);
  EXPECT_EQ(rig.in.position, 100.0);
  EXPECT_EQ(rig.joint.motor_position(), 100.0);
  EXPECT_EQ(rig.joint.lost_steps(), 0);
  EXPECT_FALSE(rig.in.stall);
}

TEST(SimJoint, OverloadedStepperStallsAndLosesSteps) {
  JointRig rig(dynamic_stepper());
  // 10 000 mm/s² needs 800 N for the mass alone: it drops out of step on the first ramp.
  bool stalled = false;
  for (std::int64_t s : trapezoid_steps(100, 120, 10000, 320)) {
    rig.steps(s);
    stalled = stalled || rig.in.stall;
  }
  EXPECT_TRUE(stalled);
  for (int k = 0; k < 500; ++k) rig.steps(32000);  // the command rests: the rotor locks again
  EXPECT_FALSE(rig.in.stall);
  EXPECT_EQ(rig.in.position, 100.0);  // the steps were emitted: open loop, the control believes it
  EXPECT_LT(rig.joint.motor_position(), 50.0);
  EXPECT_GT(rig.joint.lost_steps(), 50 * 320);
  // Locked on a step: later steps are made again, from where it stands.
  const double here = rig.joint.motor_position();
  for (int k = 1; k <= 100; ++k) rig.steps(32000 + k);
  EXPECT_DOUBLE_EQ(rig.joint.motor_position(), here + 100.0 / 320);
}

TEST(SimJoint, LoadBeyondThePullOutEffortStallsAStandingStepper) {
  SimJointConfig c = dynamic_stepper();
  c.stall_detector = false;  // no detector: the stall goes unseen
  JointRig rig(c);
  JointOutputs out;
  out.enable = true;
  rig.joint.begin_period(out, true, -2000);  // 2 kN pushing it back
  rig.joint.end_period();
  rig.joint.sample(rig.in, rig.rng);
  EXPECT_TRUE(rig.joint.stalled());
  EXPECT_FALSE(rig.in.stall);
  EXPECT_LT(rig.joint.motor_position(), 0.0);
}

TEST(SimJoint, UnpoweredStepperCoastsToAStopOnFriction) {
  JointRig rig(dynamic_stepper());
  std::int64_t s = 0;
  for (int k = 1; k <= 200; ++k) rig.steps(s = std::llround(0.5 * 500 * std::pow(k * kPeriod, 2) * 320));
  ASSERT_FALSE(rig.joint.stalled());
  const double v = rig.in.velocity;  // about 500 mm/s² · 0.2 s = 100 mm/s
  EXPECT_NEAR(v, 100, 1);
  const double at = rig.joint.motor_position();
  for (int k = 0; k < 2000; ++k) rig.steps(s, false);
  // Coulomb 60 N and viscous friction on 80 kg: at most v²/(2·60/80 m/s²) of coasting.
  const double coast = rig.joint.motor_position() - at;
  EXPECT_GT(coast, 0.0);
  EXPECT_LE(coast, v * v / (2 * 60.0 / 80 * 1000) + v * kPeriod);
  EXPECT_EQ(rig.joint.velocity(), 0.0);
}

TEST(SimJoint, ManualJointFollowsTheHandNotTheCommand) {
  SimJointConfig c;
  c.drive = JointDrive::Manual;
  c.counts_per_unit = 1000;  // a 1 µm scale
  JointRig rig(c);
  EXPECT_EQ(rig.joint.capabilities().drive, JointDrive::Manual);
  for (int k = 0; k < 100; ++k) rig.period(50.0);  // commands do nothing
  EXPECT_EQ(rig.in.position, 0.0);
  rig.joint.set_hand_target(-20.0, 10.0);
  for (int k = 0; k < 1000; ++k) rig.period(50.0);
  EXPECT_LT(rig.in.position, -9.0);  // 10 mm/s after a short run-up
  EXPECT_GT(rig.in.position, -10.0);
  for (int k = 0; k < 2000; ++k) rig.period(50.0);
  EXPECT_EQ(rig.in.position, -20.0);
  EXPECT_EQ(rig.joint.velocity(), 0.0);
}

TEST(SimJoint, AnalogHomeSensorGivesLevelAndComparator) {
  SimJointConfig c = servo_config();
  c.switches.home = {true, 10.0, 12.0};
  c.switches.home_sensor = {true, 0.5, 0.5, 0.05, 0.0, 0.002};
  c.model.start_position = 9.0;
  JointRig rig(c);
  EXPECT_TRUE(rig.joint.capabilities().home_level);
  EXPECT_DOUBLE_EQ(rig.in.home_level, 0.0);  // 1 mm before the zone: 0.5 − 1/0.5, clamped
  EXPECT_FALSE(rig.in.home);
  const auto at = [&](double x) {
    for (int k = 0; k < 300; ++k) rig.period(x);
  };
  at(9.9);
  EXPECT_NEAR(rig.in.home_level, 0.3, 1e-3);
  EXPECT_FALSE(rig.in.home);
  at(10.001);
  EXPECT_NEAR(rig.in.home_level, 0.502, 1e-3);
  EXPECT_TRUE(rig.in.home);
  at(9.99);  // inside the hysteresis band (off below level 0.45, at 9.975)
  EXPECT_TRUE(rig.in.home);
  at(9.97);
  EXPECT_FALSE(rig.in.home);
  at(11.0);
  EXPECT_EQ(rig.in.home_level, 1.0);
}

TEST(SimProximity, TemperatureWidensTheZoneAboutItsMiddle) {
  SimProximity p({true, 10.0, 12.0}, {true, 0.5, 0.5, 0.05, 0.0, 0.002});
  SplitMix64 rng(1);
  const auto edges = [&](double temperature) {
    double rise = 0, fall = 0;
    bool was = false;
    for (int i = 0; i <= 40000; ++i) {
      const double x = 9.0 + 4.0 * i / 40000;
      const bool on = p.update(x, temperature, rng);
      if (on && !was) rise = x;
      if (!on && was) fall = x;
      was = on;
    }
    return std::pair{rise, fall};
  };
  const auto [r20, f20] = edges(20);
  const auto [r30, f30] = edges(30);
  EXPECT_NEAR(r20, 10.0, 1e-4);
  EXPECT_NEAR(r30, 10.0 - 0.02, 1e-4);  // 2 µm/K × 10 K earlier
  EXPECT_NEAR(f30 - f20, 0.02, 1e-4);   // and the falling edge as much later
  EXPECT_NEAR((r30 + f30) / 2, (r20 + f20) / 2, 1e-4);
}

}  // namespace
}  // namespace opencnc::machine
