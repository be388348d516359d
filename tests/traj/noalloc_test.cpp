// SPDX-License-Identifier: GPL-3.0-or-later
// tick() must not allocate: this executable replaces operator new and counts the calls made
// while the interpolator ticks (planning between ticks may allocate).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>

#include "../support/counting_new.hpp"
#include "opencnc/analysis/reference_programs.hpp"
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
