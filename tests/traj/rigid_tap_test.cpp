// SPDX-License-Identifier: GPL-3.0-or-later
// Rigid tapping (G33.1) in the interpolator, planned from a canonical program and driven by a
// spindle model that answers the tick's reversal request with its own acceleration: the tap keeps
// its thread both ways, reverses at depth, comes back out, returns onto its start and the program
// goes on; abort retracts; a moving-average filter does not disturb it.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/traj/interpolator.hpp"

using namespace opencnc;
using namespace opencnc::traj;

namespace {

constexpr double kPitch = 1.5;  // mm per revolution
constexpr double kStartZ = 2.0, kBottomZ = -10.0;

Pose xyz(double x, double y, double z) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

/// A spindle with a speed ramp: clockwise at `rpm`, turned the other way at `scale` times the
/// speed while the tick asks (as the servo's spindle output does).
struct SpindleModel {
  double rpm = 500, accel_rpm_s = 4000;
  double rps = 0, revs = 0.3;
  void step(const TickOutput& out, double dt) {
    const double target = (out.tap_reverse ? -out.tap_speed_scale : 1.0) * rpm / 60.0;
    const double dv = accel_rpm_s / 60.0 * dt;
    const double next = std::fabs(target - rps) <= dv ? target : rps + std::copysign(dv, target - rps);
    revs += 0.5 * (rps + next) * dt;
    rps = next;
  }
};

canon::Program tap_program(double scale) {
  canon::ProgramBuilder b;
  b.set_feed_rate(600);
  b.straight_traverse(0, xyz(0, 0, kStartZ));
  b.start_speed_feed_synch(0, kPitch, false);
  b.rigid_tap(1, xyz(0, 0, kBottomZ), scale);
  b.stop_speed_feed_synch();
  b.straight_feed(2, xyz(5, 0, kStartZ));
  return b.take();
}

struct Sample {
  TickOutput out;
  double revs, rps;
};

struct TapRun {
  std::vector<Sample> samples;
  RunState end = RunState::Idle;
};

TapRun run(const canon::Program& program, const plan::MachineLimits& limits, std::uint64_t abort_at = 0) {
  plan::Planner planner(limits);
  EXPECT_TRUE(planner.start(program));
  auto queue = std::make_unique<BlockQueue>();
  Interpolator interp(*queue, planner.interpolator_config(), program.start());
  SpindleModel spindle;
  TickInput in;
  TickOutput out;
  TapRun r;
  for (std::uint64_t n = 0; n < 100000; ++n) {
    planner.pump(*queue);
    in.spindle_revs = spindle.revs;
    in.spindle_rev_s = spindle.rps;
    in.abort = abort_at != 0 && n == abort_at;
    in.feed_hold = n % 400 > 300;  // the tap does not stop for it (LinuxCNC)
    interp.tick(in, out);
    r.samples.push_back({out, spindle.revs, spindle.rps});
    spindle.step(out, 1e-3);
    if (out.state == RunState::Finished || out.state == RunState::Aborted) break;
  }
  r.end = out.state;
  return r;
}

const plan::MachineLimits kMill = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);

}  // namespace

TEST(RigidTap, FollowsTheSpindleInReversesAtDepthComesOutAndEndsOnItsStart) {
  const TapRun r = run(tap_program(2.0), kMill);
  ASSERT_EQ(r.end, RunState::Finished);
  // While locked, depth − pitch · (spindle revolutions) stays constant in and out: the tap keeps
  // to one thread through the reversal.
  double lag = 0, z_min = 1e9, z_max = -1e9;
  bool have_lag = false, reversed = false, restored = false;
  double first_reverse_z = 0;
  for (const Sample& s : r.samples) {
    const double z = s.out.position[Axis::Z];
    if (s.out.spindle_synced) {
      const double phase = (kStartZ - z) - kPitch * s.revs;
      if (!have_lag) {
        lag = phase;
        have_lag = true;
      }
      EXPECT_NEAR(phase, lag, 1e-9);
      z_min = std::min(z_min, z);
      z_max = std::max(z_max, z);
    }
    if (s.out.tap_reverse && !reversed) {
      reversed = true;
      first_reverse_z = z;
      EXPECT_DOUBLE_EQ(s.out.tap_speed_scale, 2.0);
    }
    if (reversed && !s.out.tap_reverse && !restored) {
      restored = true;
      EXPECT_GE(z, kStartZ - 1e-9);  // the spindle turns back only once the tap is out
    }
  }
  ASSERT_TRUE(have_lag && reversed && restored);
  EXPECT_LE(first_reverse_z, kBottomZ + 1e-9);           // reversal asked at the depth
  EXPECT_GT(first_reverse_z, kBottomZ - kPitch * 0.01);  // within one period's travel of it
  // The spindle's deceleration takes the tap past the depth and past its start (LinuxCNC too):
  // 500 rpm stopping at 4000 rpm/s turns 0.52 rev, 1000 rpm 2.08 rev.
  EXPECT_NEAR(kBottomZ - z_min, kPitch * (500.0 / 60) * (500.0 / 60) / (2 * 4000.0 / 60), 0.02);
  EXPECT_NEAR(z_max - kStartZ, kPitch * (1000.0 / 60) * (1000.0 / 60) / (2 * 4000.0 / 60), 0.05);
  // Where in its move the machine is (for status and recovery) grows from 0 to the depth on
  // the way in (move 1) and again on the way out (move 2), never backwards.
  for (std::uint64_t move : {1u, 2u}) {
    double last_offset = -1;
    for (const Sample& s : r.samples) {
      if (s.out.segment != move) continue;
      EXPECT_GE(s.out.segment_offset, last_offset - 1e-12) << move;
      last_offset = s.out.segment_offset;
    }
    EXPECT_NEAR(last_offset, kStartZ - kBottomZ, 1e-9) << move;
  }
  // Then the tap goes back onto its start and the program goes on from there.
  bool at_start = false;
  for (const Sample& s : r.samples) {
    if (s.out.segment == 3 && !at_start) {
      at_start = true;
      EXPECT_NEAR(s.out.position[Axis::Z], kStartZ, 1e-9);
    }
  }
  const Pose end = r.samples.back().out.position;
  EXPECT_DOUBLE_EQ(end[Axis::X], 5.0);
  EXPECT_NEAR(end[Axis::Z], kStartZ, 1e-12);
  // Speed and acceleration of Z stay within the axis limits all along (the spindle ramps slowly
  // enough: 1.5 mm × 66.7 rev/s² = 100 mm/s²).
  for (std::size_t k = 2; k < r.samples.size(); ++k) {
    const double z0 = r.samples[k].out.position[Axis::Z], za = r.samples[k - 1].out.position[Axis::Z],
                 zb = r.samples[k - 2].out.position[Axis::Z];
    EXPECT_LE(std::fabs(z0 - za) / 1e-3, 100 * (1 + 1e-9)) << k;
    EXPECT_LE(std::fabs(z0 - 2 * za + zb) / 1e-6, 1000 * (1 + 1e-6)) << k;
  }
}

TEST(RigidTap, AMovingAverageFilterLeavesTheTapAndThePathAroundItContinuous) {
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);
  const TapRun r = run(tap_program(1.0), limits);
  ASSERT_EQ(r.end, RunState::Finished);
  for (std::size_t k = 1; k < r.samples.size(); ++k) {
    const Pose& a = r.samples[k - 1].out.position;
    const Pose& b = r.samples[k].out.position;
    double step = 0;
    for (int i = 0; i < 3; ++i) step += (b[i] - a[i]) * (b[i] - a[i]);
    EXPECT_LE(std::sqrt(step), 100 * 1e-3 * (1 + 1e-9)) << k;  // no jump
  }
  EXPECT_NEAR(r.samples.back().out.position[Axis::Z], kStartZ, 1e-12);
}

TEST(RigidTap, AnAbortDuringTheTapTakesItOutFirst) {
  // Abort 0.5 s into the motion, when the tap is some 5 mm deep.
  const TapRun full = run(tap_program(1.0), kMill);
  std::uint64_t deep = 0;
  for (std::uint64_t n = 0; n < full.samples.size(); ++n) {
    if (full.samples[n].out.position[Axis::Z] < kStartZ - 5) {
      deep = n;
      break;
    }
  }
  ASSERT_GT(deep, 0u);
  const TapRun r = run(tap_program(1.0), kMill, deep);
  ASSERT_EQ(r.end, RunState::Aborted);
  double z_min = 1e9;
  for (const Sample& s : r.samples) z_min = std::min(z_min, s.out.position[Axis::Z]);
  EXPECT_GT(z_min, kBottomZ);                                           // it never went to the depth
  EXPECT_NEAR(r.samples.back().out.position[Axis::Z], kStartZ, 1e-12);  // out, on its start
  EXPECT_DOUBLE_EQ(r.samples.back().out.position[Axis::X], 0.0);        // and no further
}
