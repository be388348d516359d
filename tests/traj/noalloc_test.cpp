// SPDX-License-Identifier: GPL-3.0-or-later
// tick() must not allocate: this executable replaces operator new and counts the calls made
// while the interpolator ticks (planning between ticks may allocate).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <new>

#include "../support/counting_new.hpp"
#include "opencnc/analysis/reference_programs.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/traj/interpolator.hpp"

using opencnc::test::g_allocations;
using opencnc::test::g_armed;

using namespace opencnc;

namespace {

/// Runs `program` to the end with some operator activity, arming the counter around tick().
long allocations_in_ticks(const canon::Program& program, const plan::MachineLimits& limits) {
  plan::Planner planner(limits);
  EXPECT_TRUE(planner.start(program));
  auto queue = std::make_unique<traj::BlockQueue>();
  traj::Interpolator interp(*queue, planner.interpolator_config(), program.start());
  traj::TickInput in;
  traj::TickOutput out;
  g_allocations = 0;
  for (int n = 0; n < 2000000 && out.state != traj::RunState::Finished; ++n) {
    planner.pump(*queue);
    in.feed_override = 0.5 + 0.5 * ((n / 700) % 3);
    in.feed_hold = (n % 5000) > 4700;
    in.single_block = (n / 20000) % 2 == 1;
    in.cycle_start = n % 300 == 0;
    g_armed = true;
    interp.tick(in, out);
    g_armed = false;
  }
  EXPECT_EQ(out.state, traj::RunState::Finished);
  return g_allocations.load();
}

}  // namespace

TEST(InterpolatorAllocations, NoneInsideTickWithoutJerkLimit) {
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);
  const analysis::PathMode mode{canon::MotionControl::Continuous, 0.01, 0};
  EXPECT_EQ(allocations_in_ticks(analysis::spiral_program(3000, 6000, mode), limits), 0);
}

TEST(InterpolatorAllocations, NoneInsideTickWithMovingAverage) {
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 2e5);
  const analysis::PathMode mode{canon::MotionControl::Continuous, 0.1, 0};
  EXPECT_EQ(allocations_in_ticks(analysis::small_arcs_program(200, 0.3, 90, 3000, mode), limits), 0);
}

TEST(InterpolatorAllocations, NoneInsideTickWhileRigidTapping) {
  // G33.1 in and out of a hole, the spindle (a speed ramp) answering the tick's reversal.
  canon::ProgramBuilder b;
  b.set_feed_rate(600);
  Pose start{}, bottom{}, next{};
  start[Axis::Z] = 2;
  bottom[Axis::Z] = -10;
  next[Axis::X] = 5;
  next[Axis::Z] = 2;
  b.straight_traverse(0, start);
  b.start_speed_feed_synch(0, 1.5, false);
  b.rigid_tap(1, bottom, 2.0);
  b.stop_speed_feed_synch();
  b.straight_feed(2, next);
  const canon::Program program = b.take();
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);
  plan::Planner planner(limits);
  ASSERT_TRUE(planner.start(program));
  auto queue = std::make_unique<traj::BlockQueue>();
  traj::Interpolator interp(*queue, planner.interpolator_config(), program.start());
  traj::TickInput in;
  traj::TickOutput out;
  double rps = 0, revs = 0.25;
  g_allocations = 0;
  for (int n = 0; n < 100000 && out.state != traj::RunState::Finished; ++n) {
    planner.pump(*queue);
    in.spindle_revs = revs;
    in.spindle_rev_s = rps;
    g_armed = true;
    interp.tick(in, out);
    g_armed = false;
    const double target = (out.tap_reverse ? -out.tap_speed_scale : 1.0) * 500.0 / 60.0,
                 dv = 4000.0 / 60.0 * 1e-3;
    const double v = std::fabs(target - rps) <= dv ? target : rps + std::copysign(dv, target - rps);
    revs += 0.5 * (rps + v) * 1e-3;
    rps = v;
  }
  EXPECT_EQ(out.state, traj::RunState::Finished);
  EXPECT_EQ(g_allocations.load(), 0);
}
