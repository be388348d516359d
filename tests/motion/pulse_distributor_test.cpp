// SPDX-License-Identifier: GPL-3.0-or-later
// PulseDistributor: exact small moves worked out by hand, limits, positions and the API contract.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "opencnc/motion/pulse_distributor.hpp"

namespace {

using opencnc::motion::kMaxPulseSteps;
using opencnc::motion::PulseDistributor;
using opencnc::motion::PulseMethod;
using opencnc::motion::PulseStatus;
using opencnc::motion::StepCount;
using opencnc::motion::StepPulses;

// The step masks of a whole move, taken one feed step at a time.
std::vector<unsigned> masks_of(PulseMethod method, std::vector<StepCount> increments) {
  PulseDistributor d(method);
  EXPECT_EQ(d.start(increments), PulseStatus::Ok);
  std::vector<unsigned> masks;
  while (!d.done()) masks.push_back(d.step().step_mask);
  EXPECT_EQ(d.step().step_mask, 0u) << "a finished move emits no more steps";
  return masks;
}

// Same observable state now, and the same feed steps and positions from here to the end of the move.
void expect_same_future(PulseDistributor a, PulseDistributor b) {
  EXPECT_EQ(a.feed_steps_total(), b.feed_steps_total());
  EXPECT_EQ(a.axis_count(), b.axis_count());
  for (int guard = 0; guard < 10'000; ++guard) {
    ASSERT_EQ(a.feed_steps_done(), b.feed_steps_done());
    for (int i = 0; i < opencnc::motion::kMaxPulseAxes; ++i) ASSERT_EQ(a.position(i), b.position(i)) << i;
    if (a.done() && b.done()) return;
    ASSERT_EQ(a.step(), b.step());
  }
  FAIL() << "move longer than this helper expects";
}

TEST(PulseDistributor, SingleAxis) {
  EXPECT_EQ(masks_of(PulseMethod::Vector, {5}), std::vector<unsigned>(5, 0b1));
  EXPECT_EQ(masks_of(PulseMethod::Dda, {5}), std::vector<unsigned>(5, 0b1));
}

TEST(PulseDistributor, VectorTwoAxes) {
  // F = x*b - y*a; the first axis steps iff 2F <= a - b.
  // (3,3): F 0 -> 3 -> 0 -> ...: the axes alternate, X first on the tie.
  EXPECT_EQ(masks_of(PulseMethod::Vector, {3, 3}), (std::vector<unsigned>{1, 2, 1, 2, 1, 2}));
  // (2,1): threshold 0; F 0 -> 1 -> -1 -> 0.
  EXPECT_EQ(masks_of(PulseMethod::Vector, {2, 1}), (std::vector<unsigned>{1, 2, 1}));
  // (1,3): threshold -1; F 0 -> -1 -> 2 -> 1 -> 0: Y X Y Y.
  EXPECT_EQ(masks_of(PulseMethod::Vector, {1, 3}), (std::vector<unsigned>{2, 1, 2, 2}));
}

TEST(PulseDistributor, VectorPairsOfPairs) {
  // Four unit axes: the root alternates between the pairs (XY) and (ZA), each pair between its axes.
  EXPECT_EQ(masks_of(PulseMethod::Vector, {1, 1, 1, 1}), (std::vector<unsigned>{1, 4, 2, 8}));
  // Six unit axes = pair (0,1) + group of four ((2,3),(4,5)). Root a=2, b=4: the first pair
  // has taken floor((2t+3)/6) steps after t, i.e. the root goes group, pair, group, group, pair, group.
  EXPECT_EQ(masks_of(PulseMethod::Vector, {1, 1, 1, 1, 1, 1}),
            (std::vector<unsigned>{1u << 2, 1u << 0, 1u << 4, 1u << 3, 1u << 1, 1u << 5}));
  // Three axes get a zero fourth: the pair (Z, pad) only ever steps Z.
  EXPECT_EQ(masks_of(PulseMethod::Vector, {1, 1, 2}), (std::vector<unsigned>{1, 4, 2, 4}));
}

TEST(PulseDistributor, VectorBoundIsReached) {
  // (1, 127, 1, 127): axis 3 sits under the root (own 128 of 256, sibling 128) and its pair
  // (own 127, sibling 1), so B = 127/(2*128) + 1/2 = 255/256 step, and the sequence reaches it:
  // max over k of |p*256 - 127*k| is 255.
  PulseDistributor d(PulseMethod::Vector);
  ASSERT_EQ(d.start(std::vector<StepCount>{1, 127, 1, 127}), PulseStatus::Ok);
  StepCount worst = 0;
  while (!d.done()) {
    d.step();
    worst = std::max(worst, std::abs(d.position(3) * 256 - 127 * d.feed_steps_done()));
  }
  EXPECT_EQ(worst, 255);
}

TEST(PulseDistributor, DdaSteps) {
  // n = 3, accumulators start at 1: Y's position floor((2k+1)/3) is 1, 1, 2.
  EXPECT_EQ(masks_of(PulseMethod::Dda, {3, 2}), (std::vector<unsigned>{0b11, 0b01, 0b11}));
  // Equal increments step together.
  EXPECT_EQ(masks_of(PulseMethod::Dda, {4, 4, 4}), std::vector<unsigned>(4, 0b111));
  // n = 4, Y=1: floor((k+2)/4) turns 1 at k=2.
  EXPECT_EQ(masks_of(PulseMethod::Dda, {4, 1}), (std::vector<unsigned>{0b01, 0b11, 0b01, 0b01}));
}

TEST(PulseDistributor, ZeroMove) {
  for (PulseMethod method : {PulseMethod::Vector, PulseMethod::Dda}) {
    PulseDistributor d(method);
    ASSERT_EQ(d.start(std::vector<StepCount>{7, -2}), PulseStatus::Ok);
    d.advance(1000);
    ASSERT_EQ(d.start(std::vector<StepCount>{0, 0, 0}), PulseStatus::Ok);
    EXPECT_TRUE(d.done());
    EXPECT_EQ(d.feed_steps_total(), 0);
    EXPECT_EQ(d.step(), StepPulses{});
    EXPECT_EQ(d.advance(5), 0);
    EXPECT_EQ(d.advance_to_fraction(1, 1), 0);
    EXPECT_EQ(d.position(0), 7);
    EXPECT_EQ(d.position(1), -2);
    EXPECT_EQ(d.position(2), 0);
  }
}

TEST(PulseDistributor, NegativeDirections) {
  for (PulseMethod method : {PulseMethod::Vector, PulseMethod::Dda}) {
    PulseDistributor pos(method);
    PulseDistributor neg(method);
    ASSERT_EQ(pos.start(std::vector<StepCount>{3, 2, 5}), PulseStatus::Ok);
    ASSERT_EQ(neg.start(std::vector<StepCount>{-3, 2, -5}), PulseStatus::Ok);
    EXPECT_EQ(neg.negative_mask(), 0b101);
    while (!pos.done()) {
      const StepPulses p = pos.step();
      const StepPulses n = neg.step();
      EXPECT_EQ(n.step_mask, p.step_mask) << "direction never changes which axes step";
      EXPECT_EQ(n.negative_mask, 0b101);
      EXPECT_EQ(p.negative_mask, 0);
      for (int i = 0; i < 3; ++i) EXPECT_EQ(neg.position(i), (i == 1 ? 1 : -1) * pos.position(i));
    }
    EXPECT_TRUE(neg.done());
    EXPECT_EQ(neg.position(0), -3);
    EXPECT_EQ(neg.position(1), 2);
    EXPECT_EQ(neg.position(2), -5);
  }
}

TEST(PulseDistributor, FeedStepTotals) {
  PulseDistributor v(PulseMethod::Vector);
  PulseDistributor dda(PulseMethod::Dda);
  const std::vector<StepCount> move{4, -9, 0, 2, -1};
  ASSERT_EQ(v.start(move), PulseStatus::Ok);
  ASSERT_EQ(dda.start(move), PulseStatus::Ok);
  EXPECT_EQ(v.feed_steps_total(), 16);   // one axis per feed step: Σ|ai|
  EXPECT_EQ(dda.feed_steps_total(), 9);  // one DDA iteration per feed step: max|ai|
  EXPECT_EQ(v.axis_count(), 5);
}

TEST(PulseDistributor, HugeCounts) {
  // Near the limit, where a naive x*b - y*a or k*|ai| would overflow 64 bits.
  const StepCount big = kMaxPulseSteps / 2;
  const StepCount tera = StepCount{1} << 40;
  const std::vector<StepCount> move{big - tera - 3, -big, 3, 0, -tera};  // Σ|ai| = kMaxPulseSteps
  for (PulseMethod method : {PulseMethod::Vector, PulseMethod::Dda}) {
    PulseDistributor d(method);
    ASSERT_EQ(d.start(move), PulseStatus::Ok);
    const StepCount total = d.feed_steps_total();
    EXPECT_EQ(total, method == PulseMethod::Vector ? kMaxPulseSteps : big);
    // Half way, X is within a step of half its travel.
    EXPECT_EQ(d.advance_to_fraction(1, 2), total / 2);
    EXPECT_LE(std::abs(d.position(0) - move[0] / 2), 1);
    EXPECT_LE(std::abs(d.position(1) - move[1] / 2), 1);
    // The last feed steps, one by one: every axis ends exactly on its target.
    EXPECT_EQ(d.advance_to(total - 50), total - 50 - total / 2);
    StepCount pulses = 0;
    while (!d.done()) pulses += std::popcount(d.step().step_mask);
    EXPECT_LE(pulses, method == PulseMethod::Vector ? 50 : 50 * 4);
    EXPECT_GE(pulses, 50);
    for (int i = 0; i < 5; ++i) EXPECT_EQ(d.position(i), move[i]) << "axis " << i;
  }
}

TEST(PulseDistributor, RejectsBadMovesAndChangesNothing) {
  PulseDistributor d(PulseMethod::Vector);
  ASSERT_EQ(d.start(std::vector<StepCount>{10, 4}), PulseStatus::Ok);
  d.advance(3);
  ASSERT_EQ(d.set_position(2, kMaxPulseSteps), PulseStatus::Ok);
  const PulseDistributor before = d;

  EXPECT_EQ(d.start(std::vector<StepCount>{}), PulseStatus::BadAxis);
  EXPECT_EQ(d.start(std::vector<StepCount>(10, 1)), PulseStatus::BadAxis);
  EXPECT_EQ(d.start(std::vector<StepCount>{kMaxPulseSteps - 10, 11}), PulseStatus::MoveTooLong);
  EXPECT_EQ(d.start(std::vector<StepCount>{INT64_MIN}), PulseStatus::MoveTooLong);
  EXPECT_EQ(d.start(std::vector<StepCount>(9, INT64_MAX)), PulseStatus::MoveTooLong);
  EXPECT_EQ(d.start(std::vector<StepCount>{-1, 0, 1}), PulseStatus::PositionOutOfRange);
  EXPECT_EQ(d.set_position(9, 0), PulseStatus::BadAxis);
  EXPECT_EQ(d.set_position(-1, 0), PulseStatus::BadAxis);
  EXPECT_EQ(d.set_position(2, kMaxPulseSteps + 1), PulseStatus::PositionOutOfRange);
  EXPECT_EQ(d.set_position(0, kMaxPulseSteps - 1), PulseStatus::PositionOutOfRange)
      << "the rest of the move would run out of range";
  expect_same_future(before, d);

  EXPECT_EQ(d.advance(-4), 0);
  EXPECT_EQ(d.advance_to(1), 0) << "never backward";
  EXPECT_EQ(d.advance_to_fraction(1, 0), 0);
  EXPECT_EQ(d.advance_to_fraction(3, 2), 0);
  EXPECT_EQ(d.advance_to_fraction(-1, 2), 0);
  expect_same_future(before, d);
}

TEST(PulseDistributor, LimitsAreInclusive) {
  PulseDistributor d(PulseMethod::Vector);
  EXPECT_EQ(d.start(std::vector<StepCount>{kMaxPulseSteps - 5, 5}), PulseStatus::Ok);
  EXPECT_EQ(d.set_position(3, -kMaxPulseSteps), PulseStatus::Ok);
  EXPECT_EQ(d.position(3), -kMaxPulseSteps);
  d.advance_to_fraction(1, 1);
  EXPECT_EQ(d.position(0), kMaxPulseSteps - 5);
}

TEST(PulseDistributor, PositionsCarryAcrossMoves) {
  PulseDistributor d(PulseMethod::Dda);
  ASSERT_EQ(d.start(std::vector<StepCount>{10, -6, 2}), PulseStatus::Ok);
  EXPECT_EQ(d.advance(100), 10);
  ASSERT_EQ(d.start(std::vector<StepCount>{-4, 0}), PulseStatus::Ok);  // fewer axes: Z keeps its place
  EXPECT_EQ(d.advance(2), 2);
  EXPECT_EQ(d.position(0), 8);
  EXPECT_EQ(d.position(1), -6);
  // A new move mid-way starts from where the axes are and drops the rest of the old one.
  ASSERT_EQ(d.start(std::vector<StepCount>{1, 1, 1}), PulseStatus::Ok);
  d.advance_to_fraction(1, 1);
  EXPECT_EQ(d.position(0), 9);
  EXPECT_EQ(d.position(1), -5);
  EXPECT_EQ(d.position(2), 3);
}

TEST(PulseDistributor, SetPositionDuringMove) {
  PulseDistributor d(PulseMethod::Vector);
  ASSERT_EQ(d.start(std::vector<StepCount>{-8, 8}), PulseStatus::Ok);
  d.advance(8);
  ASSERT_EQ(d.position(0), -4);
  ASSERT_EQ(d.set_position(0, 100), PulseStatus::Ok);  // homed here
  EXPECT_EQ(d.position(0), 100);
  d.advance(8);
  EXPECT_EQ(d.position(0), 96) << "the rest of the move keeps its length";
  EXPECT_EQ(d.position(1), 8);
  EXPECT_EQ(d.position(9), 0);
}

TEST(PulseDistributor, AdvanceMatchesStepping) {
  for (PulseMethod method : {PulseMethod::Vector, PulseMethod::Dda}) {
    PulseDistributor stepped(method);
    PulseDistributor jumped(method);
    const std::vector<StepCount> move{37, -11, 0, 23, 5, -64, 1};
    ASSERT_EQ(stepped.start(move), PulseStatus::Ok);
    ASSERT_EQ(jumped.start(move), PulseStatus::Ok);
    for (StepCount k = 0; k < 30; ++k) stepped.step();
    EXPECT_EQ(jumped.advance(30), 30);
    expect_same_future(stepped, jumped);
    EXPECT_EQ(jumped.advance(INT64_MAX), jumped.feed_steps_total() - 30) << "no overflow near the end";
    for (int i = 0; i < 7; ++i) EXPECT_EQ(jumped.position(i), move[i]);
  }
}

}  // namespace
