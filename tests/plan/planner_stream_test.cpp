// SPDX-License-Identifier: GPL-3.0-or-later
// The planner fed a growing program (streaming): the same blocks as the whole program planned at
// once, whatever the pieces the moves arrive in; a flush at a sync point stops the motion there.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "opencnc/analysis/reference_programs.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/plan/planner.hpp"

using namespace opencnc;
using traj::MotionBlock;

namespace {

const plan::MachineLimits kMill = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);
const plan::MachineLimits kMillJerk =
    plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);

/// Plans `p` whole, draining the queue as a tick would (`drain` blocks per pump).
std::vector<MotionBlock> plan_whole(const canon::Program& p, const plan::MachineLimits& limits,
                                    std::size_t drain) {
  plan::Planner planner(limits);
  EXPECT_TRUE(planner.start(p));
  auto q = std::make_unique<traj::BlockQueue>();
  std::vector<MotionBlock> out;
  for (;;) {
    const plan::PlanStatus s = planner.pump(*q);
    const std::size_t n = std::min(drain, q->available());
    for (std::size_t i = 0; i < n; ++i) out.push_back(q->peek(i));
    q->pop(n);
    if (s == plan::PlanStatus::Finished && q->available() == 0) break;
    EXPECT_NE(s, plan::PlanStatus::Failed);
  }
  return out;
}

/// The same program made readable in random pieces while the queue drains.
std::vector<MotionBlock> plan_streamed(const canon::Program& p, const plan::MachineLimits& limits,
                                       std::size_t drain, std::uint64_t seed) {
  plan::Planner planner(limits);
  EXPECT_TRUE(planner.start_stream(p));
  std::mt19937_64 rng(seed);
  auto q = std::make_unique<traj::BlockQueue>();
  std::vector<MotionBlock> out;
  std::size_t readable = 0;
  for (;;) {
    if (readable < p.size() && (planner.wants_input() || rng() % 3 == 0)) {
      readable = std::min(p.size(), readable + 1 + static_cast<std::size_t>(rng() % 700));
      planner.stream_readable(readable);
      if (readable == p.size()) planner.stream_end();
    }
    const plan::PlanStatus s = planner.pump(*q);
    const std::size_t n = std::min(drain, q->available());
    for (std::size_t i = 0; i < n; ++i) out.push_back(q->peek(i));
    q->pop(n);
    if (s == plan::PlanStatus::Finished && q->available() == 0) break;
    EXPECT_NE(s, plan::PlanStatus::Failed);
  }
  return out;
}

TEST(PlannerStream, BlocksAreTheWholeProgramsWhateverThePieces) {
  const analysis::PathMode g64{canon::MotionControl::Continuous, 0.01, 0.01};
  const analysis::PathMode q0{canon::MotionControl::Continuous, 0.01, 0};
  for (const analysis::PathMode& mode : {g64, q0}) {
    const canon::Program p = analysis::spiral_program(4000, 6000, mode);
    const std::vector<MotionBlock> whole = plan_whole(p, kMill, 50);
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const std::vector<MotionBlock> streamed = plan_streamed(p, kMill, 50, seed);
      ASSERT_EQ(streamed.size(), whole.size()) << seed;
      for (std::size_t i = 0; i < whole.size(); ++i) {
        ASSERT_EQ(std::memcmp(&streamed[i], &whole[i], sizeof(MotionBlock)), 0)
            << "block " << i << " seed " << seed << " v_entry " << streamed[i].v_entry << " " << whole[i].v_entry
            << " next_soft " << streamed[i].next_soft << " " << whole[i].next_soft;
      }
    }
  }
}

TEST(PlannerStream, HalvedBezierBlocksAreTheWholeProgramsToo) {
  // 0.05 mm CAM moves along a clothoid (curvature growing with the length, to 15 /mm): with jerk
  // limits a fitted run's Bézier block is halved where its halves' caps differ, as the planner
  // emits it, so the halves must not depend on how far the program had been read.
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_motion_control_mode(canon::MotionControl::Continuous, 0.01);
  b.set_naivecam_tolerance(0);
  canon::SegmentId id = 0;
  Pose at;
  b.straight_traverse(id++, at);
  b.set_feed_rate(6000);
  for (int i = 1; i <= 300; ++i) {
    const double t = 0.05 * i;
    at[Axis::X] += 0.05 * std::cos(0.5 * t * t);
    at[Axis::Y] += 0.05 * std::sin(0.5 * t * t);
    b.straight_feed(id++, at);
  }
  b.program_end();
  const canon::Program p = b.take();
  const std::vector<MotionBlock> whole = plan_whole(p, kMillJerk, 50);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<MotionBlock> streamed = plan_streamed(p, kMillJerk, 50, seed);
    ASSERT_EQ(streamed.size(), whole.size()) << seed;
    for (std::size_t i = 0; i < whole.size(); ++i)
      ASSERT_EQ(std::memcmp(&streamed[i], &whole[i], sizeof(MotionBlock)), 0)
          << "block " << i << " seed " << seed;
  }
}

}  // namespace
