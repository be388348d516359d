// SPDX-License-Identifier: GPL-3.0-or-later
// Reference scenarios: the dense spiral at feed with and without merging, the square under G61
// and G64, chains of small arcs, holds inside blends and on tiny segments, overrides changing
// mid-move, and bit-for-bit repeatability.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "opencnc/analysis/reference_programs.hpp"
#include "opencnc/analysis/simulate.hpp"
#include "opencnc/canon/program_builder.hpp"

using namespace opencnc;
using analysis::PathMode;

namespace {

const plan::MachineLimits kMill = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);
const plan::MachineLimits kMillJerk =
    plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);
constexpr PathMode kG64{canon::MotionControl::Continuous, 0.01, 0.01};
constexpr PathMode kG64Q0{canon::MotionControl::Continuous, 0.01, 0};

void expect_clean(const analysis::SimulationResult& r, double tolerance) {
  EXPECT_TRUE(r.finished) << r.report.summary();
  EXPECT_EQ(r.report.limit_violations, 0u) << r.report.summary();
  EXPECT_LE(r.report.max_contour_error_mm, tolerance * (1 + 1e-9)) << r.report.summary();
  EXPECT_LE(r.report.max_corner_miss_mm, tolerance * (1 + 1e-9)) << r.report.summary();
}

}  // namespace

TEST(TrajectoryScenario, DenseSpiralRunsAtTheFeedWithAndWithoutMerging) {
  for (const PathMode& mode : {kG64, kG64Q0}) {
    const analysis::SimulationResult r =
        analysis::simulate(analysis::spiral_program(20000, 6000, mode), kMill);
    expect_clean(r, mode.p);
    const double lower_bound = r.report.path_length_mm / 100.0;
    EXPECT_LE(r.motion_time_s, 1.03 * lower_bound) << "Q " << mode.q;
  }
}

TEST(TrajectoryScenario, SquareContinuousIsNeverSlowerThanExactStop) {
  const analysis::SimulationResult g61 =
      analysis::simulate(analysis::square_program(100, 6000, {canon::MotionControl::ExactPath}), kMill);  // G61
  const analysis::SimulationResult g64 = analysis::simulate(analysis::square_program(100, 6000, kG64), kMill);
  expect_clean(g61, 1e-9);
  expect_clean(g64, kG64.p);
  EXPECT_LE(g61.motion_time_s, 4.448);  // LinuxCNC 2.9, same limits
  EXPECT_LE(g64.motion_time_s, 4.493);
  EXPECT_LE(g64.motion_time_s, g61.motion_time_s);
}

// A zigzag of 0.05 mm hairpins (X back and forth, Y creeping 0.1 µm a move) under G64 P0.01: the
// moves overlap, so a path along their middles stays within 0.1 µm of them; the blends must still
// pass within P of every turning point, with and without jerk limits.
TEST(TrajectoryScenario, HairpinsAreBlendedWithinTheToleranceOfTheirTurningPoints) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_motion_control_mode(canon::MotionControl::Continuous, 0.01);
  b.set_feed_rate(6000);
  for (int i = 0; i < 200; ++i) {
    Pose p;
    p[Axis::X] = (i % 2) * 0.05;
    p[Axis::Y] = i * 1e-4;
    b.straight_feed(static_cast<canon::SegmentId>(i), p);
  }
  const canon::Program program = b.take();
  for (const plan::MachineLimits& limits : {kMill, kMillJerk}) {
    const analysis::SimulationResult r = analysis::simulate(program, limits);
    EXPECT_TRUE(r.finished) << r.report.summary();
    EXPECT_EQ(r.report.limit_violations, 0u) << r.report.summary();
    EXPECT_LE(r.report.max_contour_error_mm, 0.01) << r.report.summary();
    // The blends turn within 0.01 mm of the hairpins' ends at about 6 mm/s: 6 µm between samples,
    // which the checker's arc through three of them resolves to within 1 %.
    EXPECT_LE(r.report.max_corner_miss_mm, 0.01 * 1.01) << r.report.summary();
    // From tip to tip at least 0.05 − 2 × 0.01 mm a move: every hairpin is run.
    EXPECT_GT(r.report.path_length_mm, 0.95 * 200 * (0.05 - 2 * 0.01)) << r.report.summary();
  }
}

TEST(TrajectoryScenario, SmallAlternatingArcsKeepTheAccelerationLimit) {
  const PathMode p01{canon::MotionControl::Continuous, 0.1, 0.1};
  const analysis::SimulationResult r =
      analysis::simulate(analysis::small_arcs_program(2000, 0.3, 90, 3000, p01), kMill);
  expect_clean(r, p01.p);
  EXPECT_LE(r.motion_time_s, 73.715);  // LinuxCNC 2.9 (which overshoots its limits there)
  const analysis::SimulationResult j =
      analysis::simulate(analysis::small_arcs_program(300, 0.3, 180, 3000, p01), kMillJerk);
  expect_clean(j, p01.p);
}

// Holds placed by where the commanded position is: inside a corner blend, on a segment shorter
// than one period of travel; then resume.
TEST(TrajectoryScenario, HoldsInsideBlendsAndOnTinySegmentsResumeOnThePath) {
  for (const plan::MachineLimits& lim : {kMill, kMillJerk}) {
    const canon::Program spiral = analysis::spiral_program(4000, 6000, kG64Q0);
    analysis::SimulationOptions o;
    auto hold_from = std::make_shared<std::uint64_t>(0);
    auto holds = std::make_shared<int>(0);
    o.inputs = [=](std::uint64_t n, const traj::TickOutput& prev, traj::TickInput& in) {
      // Every 1.7 s hold for 0.3 s, wherever the path is (blend or tiny segment: both dense here).
      if (*hold_from == 0 && n % 1700 == 1000 && prev.state == traj::RunState::Running) {
        *hold_from = n;
        ++*holds;
      }
      in.feed_hold = *hold_from != 0 && n < *hold_from + 300;
      if (*hold_from != 0 && n >= *hold_from + 300) *hold_from = 0;
    };
    bool saw_held = false;
    o.observe = [&](std::uint64_t, const traj::TickOutput& out) {
      saw_held = saw_held || out.state == traj::RunState::Held;
    };
    const analysis::SimulationResult r = analysis::simulate(spiral, lim, o);
    expect_clean(r, kG64Q0.p);
    EXPECT_TRUE(saw_held);
    EXPECT_GE(*holds, 2);
  }
}

TEST(TrajectoryScenario, OverridesChangingMidMoveKeepTheLimits) {
  for (const plan::MachineLimits& lim : {kMill, kMillJerk}) {
    analysis::SimulationOptions o;
    o.inputs = [](std::uint64_t n, const traj::TickOutput&, traj::TickInput& in) {
      static constexpr double kSteps[] = {1.0, 2.0, 0.1, 1.5, 0.0, 0.7};
      in.feed_override = kSteps[(n / 333) % 6];
      in.rapid_override = 0.25;
    };
    expect_clean(analysis::simulate(analysis::square_program(50, 6000, kG64), lim, o), kG64.p);
    expect_clean(analysis::simulate(analysis::small_arcs_program(200, 0.3, 90, 3000, kG64), lim, o), kG64.p);
  }
}

TEST(TrajectoryScenario, VirtualTimeRunsAreBitForBitRepeatable) {
  const canon::Program spiral = analysis::spiral_program(3000, 6000, kG64Q0);
  const auto run = [&](const plan::MachineLimits& lim) {
    std::vector<Pose> trace;
    analysis::SimulationOptions o;
    o.check = false;
    o.inputs = [](std::uint64_t n, const traj::TickOutput&, traj::TickInput& in) {
      in.feed_override = (n / 500) % 2 ? 0.6 : 1.3;
      in.feed_hold = n % 2000 > 1800;
    };
    o.observe = [&](std::uint64_t, const traj::TickOutput& out) { trace.push_back(out.position); };
    analysis::simulate(spiral, lim, o);
    return trace;
  };
  for (const plan::MachineLimits& lim : {kMill, kMillJerk}) {
    const std::vector<Pose> a = run(lim), b = run(lim);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_TRUE(a == b);  // exact equality of every coordinate of every sample
  }
}

// G33: the motion waits for the spindle index, catches up, then follows the encoder exactly;
// the thread's phase is the same whatever the spindle's angle when the move was reached.
TEST(TrajectoryScenario, SpindleSynchronisedMotionFollowsTheEncoderWithARepeatablePhase) {
  const auto program = [] {
    canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
    Pose p;
    p[Axis::X] = 10;
    b.straight_traverse(0, p);
    b.set_spindle_speed(0, 600);
    b.start_spindle_clockwise(0);
    b.start_speed_feed_synch(0, 1.5, false);  // G33 K1.5, in two moves: the lock holds across them
    p[Axis::Z] = -8;
    b.straight_feed(1, p);
    p[Axis::Z] = -20;
    b.straight_feed(2, p);
    b.stop_speed_feed_synch();
    p[Axis::Z] = 5;
    b.straight_traverse(3, p);
    b.program_end();
    return b.take();
  }();
  const auto pass = [&](double phase) {
    analysis::SimulationOptions o;
    o.inputs = [phase](std::uint64_t n, const traj::TickOutput&, traj::TickInput& in) {
      in.spindle_rev_s = 10;  // 600 rpm
      in.spindle_revs = phase + 10 * static_cast<double>(n) * 1e-3;
    };
    double locked_constant = 0, worst = 0;
    int locked = 0;
    o.observe = [&](std::uint64_t n, const traj::TickOutput& out) {
      if (!out.spindle_synced) return;
      const double c = out.position[Axis::Z] + 1.5 * (phase + 10 * static_cast<double>(n) * 1e-3);
      if (locked++ == 0) locked_constant = c;
      worst = std::max(worst, std::fabs(c - locked_constant));
    };
    const analysis::SimulationResult r = analysis::simulate(program, kMill, o);
    EXPECT_TRUE(r.finished);
    EXPECT_EQ(r.report.limit_violations, 0u) << r.report.summary();
    EXPECT_GT(locked, 1000);  // most of the 20 mm at 15 mm/s
    EXPECT_LT(worst, 1e-9);   // z + pitch · revolutions stays constant: exact pitch
    return std::fmod(locked_constant + 1500, 1.5);
  };
  EXPECT_NEAR(pass(0.1), pass(0.73), 1e-9);
}
