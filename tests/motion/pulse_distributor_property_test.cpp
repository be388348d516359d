// SPDX-License-Identifier: GPL-3.0-or-later
// PulseDistributor over seeded random moves of 1 to 9 axes: the step sequences against their
// definitions, the deviation bounds of docs/pulse-distribution.md, totals, advance() = step()s.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "opencnc/motion/pulse_distributor.hpp"

namespace {

using opencnc::motion::kMaxPulseAxes;
using opencnc::motion::PulseDistributor;
using opencnc::motion::PulseMethod;
using opencnc::motion::PulseStatus;
using opencnc::motion::StepCount;

__extension__ using Int128 = __int128;

Int128 abs128(Int128 v) {
  return v < 0 ? -v : v;
}

// mt19937_64 is fully specified by the standard and the mapping to ranges is ours, so the cases
// are the same with every standard library.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : gen_(seed) {}
  std::uint64_t below(std::uint64_t n) { return gen_() % n; }
  int axes() { return 1 + static_cast<int>(below(kMaxPulseAxes)); }

 private:
  std::mt19937_64 gen_;
};

// Each axis: zero one time in five, otherwise a length of up to `max_bits` bits (log-uniform, so
// that very unequal axes are common) with a random sign.
std::vector<StepCount> random_move(Rng& rng, int axes, int max_bits) {
  std::vector<StepCount> move(axes);
  for (StepCount& inc : move) {
    if (rng.below(5) == 0) continue;
    const int bits = static_cast<int>(rng.below(max_bits + 1));
    inc = 1 + static_cast<StepCount>(rng.below(std::uint64_t{1} << bits));
    if (rng.below(2) == 1) inc = -inc;
  }
  return move;
}

StepCount length(StepCount inc) {
  return inc < 0 ? -inc : inc;
}

// One node on an axis's path from the root: the step total of the child that leads to the axis
// and that of its sibling.
struct Level {
  StepCount own;
  StepCount sibling;
};

// The vector method straight from its definition, written independently of the library: leaves
// are the axes plus a zero pad for an odd count, pairs of neighbours, and a node over more than
// one pair splits them into floor(half) and the rest. Each node takes the step that leaves its
// deviation F = x*b - y*a smallest in magnitude, the first child on a tie.
class ReferenceTree {
 public:
  explicit ReferenceTree(const std::vector<StepCount>& move) : paths_(move.size() + move.size() % 2) {
    for (StepCount inc : move) lengths_.push_back(length(inc));
    if (move.size() % 2 == 1) lengths_.push_back(0);
    build(0, static_cast<int>(lengths_.size()));
    paths_.resize(move.size());
  }

  // The axis of the next feed step.
  int step() {
    int id = 0;
    for (;;) {
      Node& n = nodes_[static_cast<std::size_t>(id)];
      const StepCount up = n.f + n.b;
      const StepCount down = n.f - n.a;
      const bool first = abs128(up) <= abs128(down);
      n.f = first ? up : down;
      const int child = first ? n.first : n.second;
      if (child < 0) return first ? n.lo : n.mid;
      id = child;
    }
  }

  const std::vector<Level>& path(int axis) const { return paths_[static_cast<std::size_t>(axis)]; }

 private:
  struct Node {
    int lo, mid;
    int first, second;  // child node index, or -1 for a leaf
    StepCount a, b, f;
  };

  StepCount sum(int lo, int hi) const {
    StepCount s = 0;
    for (int i = lo; i < hi; ++i) s += lengths_[static_cast<std::size_t>(i)];
    return s;
  }

  // The node over leaves [lo, hi); returns its index.
  int build(int lo, int hi) {
    const int id = static_cast<int>(nodes_.size());
    const int pairs = (hi - lo) / 2;
    const int mid = pairs == 1 ? lo + 1 : lo + 2 * (pairs / 2);
    nodes_.push_back({lo, mid, -1, -1, sum(lo, mid), sum(mid, hi), 0});
    const StepCount a = nodes_.back().a;
    const StepCount b = nodes_.back().b;
    for (int i = lo; i < hi; ++i)
      paths_[static_cast<std::size_t>(i)].push_back(i < mid ? Level{a, b} : Level{b, a});
    if (pairs > 1) {
      const int first = build(lo, mid);
      const int second = build(mid, hi);
      nodes_[static_cast<std::size_t>(id)].first = first;
      nodes_[static_cast<std::size_t>(id)].second = second;
    }
    return id;
  }

  std::vector<StepCount> lengths_;
  std::vector<Node> nodes_;
  std::vector<std::vector<Level>> paths_;
};

// |p - L*k/K| * K: how far an axis of length L at p after k of K feed steps is from the line.
Int128 scaled_error(StepCount p, StepCount k, StepCount length, StepCount total) {
  return abs128(Int128{p} * total - Int128{length} * k);
}

// Nodes on an axis's path whose sibling total is nonzero: each may add half a step.
int active_depth(const std::vector<Level>& path) {
  return static_cast<int>(
      std::count_if(path.begin(), path.end(), [](const Level& l) { return l.sibling != 0; }));
}

// The corollary of the bound below: |p - L*k/K| <= depth/2 (<= 1 up to four axes). Exact for any move.
bool within_depth_bound(StepCount p, StepCount k, StepCount length, StepCount total, int depth) {
  return 2 * scaled_error(p, k, length, total) <= Int128{depth} * total;
}

// The documented bound for an axis of length L, in exact integers:
//   |p - L*k/K| <= B = Σ over the nodes on its path whose sibling total is nonzero of L / (2*own).
// Multiplying by 2*K*P, P = Π own: 2*|p*K - L*k| * P <= K * L * Σ P/own. The products fit 128 bits
// for moves of up to 2^20 feed steps.
class VectorBound {
 public:
  VectorBound(StepCount length, StepCount total, const std::vector<Level>& path)
      : length_(length), total_(total), depth_(active_depth(path)) {
    EXPECT_LE(total, StepCount{1} << 20) << "too long for the exact bound in 128 bits";
    if (length == 0) return;  // B = 0: the axis never moves
    for (const Level& level : path) {
      if (level.sibling != 0) product_ *= level.own;
    }
    Int128 sum = 0;
    for (const Level& level : path) {
      if (level.sibling != 0) sum += product_ / level.own;
    }
    rhs_ = Int128{total_} * length_ * sum;
  }
  bool holds(StepCount p, StepCount k) const {
    return 2 * scaled_error(p, k, length_, total_) * product_ <= rhs_;
  }
  bool holds_depth(StepCount p, StepCount k) const {
    return within_depth_bound(p, k, length_, total_, depth_);
  }
  int depth() const { return depth_; }

 private:
  StepCount length_;
  StepCount total_;
  int depth_;
  Int128 product_ = 1;
  Int128 rhs_ = 0;
};

// Steps a whole vector-method move and checks every feed step against the reference tree and the
// bounds.
void check_vector_move(const std::vector<StepCount>& move) {
  PulseDistributor d(PulseMethod::Vector);
  EXPECT_EQ(d.start(move), PulseStatus::Ok);
  ReferenceTree ref(move);
  const int axes = static_cast<int>(move.size());
  StepCount sum = 0;
  for (StepCount inc : move) sum += length(inc);
  EXPECT_EQ(d.feed_steps_total(), sum) << "one axis per feed step";

  std::vector<VectorBound> bounds;
  for (int i = 0; i < axes; ++i) bounds.emplace_back(length(move[i]), sum, ref.path(i));
  for (StepCount k = 1; k <= sum; ++k) {
    EXPECT_FALSE(d.done());
    const unsigned mask = d.step().step_mask;
    const int axis = ref.step();
    if (mask != 1u << axis) {
      ADD_FAILURE() << "feed step " << k << ": mask " << mask << ", least deviation says axis " << axis;
      return;
    }
    for (int i = 0; i < axes; ++i) {
      const StepCount p = length(d.position(i));
      const VectorBound& bound = bounds[static_cast<std::size_t>(i)];
      if (!bound.holds(p, k) || !bound.holds_depth(p, k) || (axes <= 4 && bound.depth() > 2)) {
        ADD_FAILURE() << "axis " << i << " out of its bound at feed step " << k;
        return;
      }
    }
  }
  for (int i = 0; i < axes; ++i) EXPECT_EQ(d.position(i), move[i]) << "every axis ends on its target";
  EXPECT_TRUE(d.done());
  EXPECT_EQ(d.step().step_mask, 0u);
}

// The worst depth bound per axis count, as the table in docs/pulse-distribution.md gives it:
// slot by slot, d/2 with every axis moving.
TEST(PulseDistributorProperty, TreeDepthsMatchTheDocumentedTable) {
  const std::vector<std::vector<int>> depths{{0},
                                             {1, 1},
                                             {2, 2, 1},
                                             {2, 2, 2, 2},
                                             {2, 2, 3, 3, 2},
                                             {2, 2, 3, 3, 3, 3},
                                             {3, 3, 3, 3, 3, 3, 2},
                                             {3, 3, 3, 3, 3, 3, 3, 3},
                                             {3, 3, 3, 3, 3, 3, 4, 4, 3}};
  for (int axes = 1; axes <= kMaxPulseAxes; ++axes) {
    const ReferenceTree ref(std::vector<StepCount>(static_cast<std::size_t>(axes), 1));
    for (int i = 0; i < axes; ++i)
      EXPECT_EQ(active_depth(ref.path(i)), depths[axes - 1][i]) << axes << " axes, slot " << i;
  }
}

TEST(PulseDistributorProperty, VectorIsLeastDeviationWithinBound) {
  Rng rng(20240611);
  for (int c = 0; c < 20'000; ++c) {
    const auto move = random_move(rng, rng.axes(), static_cast<int>(rng.below(10)));
    SCOPED_TRACE(::testing::Message() << "case " << c);
    check_vector_move(move);
    if (HasFailure()) return;
  }
  for (int c = 0; c < 30; ++c) {  // long moves with very unequal axes
    const auto move = random_move(rng, rng.axes(), 16);
    SCOPED_TRACE(::testing::Message() << "long case " << c);
    check_vector_move(move);
    if (HasFailure()) return;
  }
}

// Steps a whole DDA move: K = max|ai| feed steps, each moving the axes whose position
// floor((k*L + floor(K/2)) / K) grows, hence within half a step of L*k/K.
void check_dda_move(const std::vector<StepCount>& move) {
  PulseDistributor d(PulseMethod::Dda);
  EXPECT_EQ(d.start(move), PulseStatus::Ok);
  const int axes = static_cast<int>(move.size());
  StepCount longest = 0;
  StepCount sum = 0;
  int major = 0;
  for (int i = 0; i < axes; ++i) {
    if (length(move[i]) > longest) major = i;
    longest = std::max(longest, length(move[i]));
    sum += length(move[i]);
  }
  EXPECT_EQ(d.feed_steps_total(), longest) << "one DDA iteration per feed step";
  StepCount pulses = 0;
  for (StepCount k = 1; k <= longest; ++k) {
    EXPECT_FALSE(d.done());
    const unsigned mask = d.step().step_mask;
    pulses += std::popcount(mask);
    EXPECT_TRUE(mask & (1u << major)) << "the longest axis steps on every feed step";
    for (int i = 0; i < axes; ++i) {
      const StepCount len = length(move[i]);
      const StepCount p = length(d.position(i));
      const Int128 ideal = Int128{k} * len;
      if (p != static_cast<StepCount>((ideal + longest / 2) / longest) ||
          2 * scaled_error(p, k, len, longest) > longest) {
        ADD_FAILURE() << "axis " << i << " off at feed step " << k;
        return;
      }
    }
  }
  EXPECT_EQ(pulses, sum) << "Σ|ai| pulses in all";
  for (int i = 0; i < axes; ++i) EXPECT_EQ(d.position(i), move[i]);
  EXPECT_TRUE(d.done());
}

TEST(PulseDistributorProperty, DdaWithinHalfAStep) {
  Rng rng(7);
  for (int c = 0; c < 20'000; ++c) {
    SCOPED_TRACE(::testing::Message() << "case " << c);
    check_dda_move(random_move(rng, rng.axes(), static_cast<int>(rng.below(10))));
    if (HasFailure()) return;
  }
}

// Any mix of step(), advance(), advance_to() and advance_to_fraction() leaves exactly the state
// that stepping one feed step at a time leaves: same positions, same feed steps afterwards.
void check_advance_matches_stepping(Rng& rng, PulseMethod method, const std::vector<StepCount>& move) {
  PulseDistributor stepped(method);
  PulseDistributor mixed(method);
  ASSERT_EQ(stepped.start(move), PulseStatus::Ok);
  ASSERT_EQ(mixed.start(move), PulseStatus::Ok);
  const StepCount total = mixed.feed_steps_total();
  for (int op = 0; op < 40 && !mixed.done(); ++op) {
    const StepCount before = mixed.feed_steps_done();
    switch (rng.below(4)) {
      case 0:
        ASSERT_EQ(mixed.step(), stepped.step());
        break;
      case 1:
        mixed.advance(static_cast<StepCount>(rng.below(static_cast<std::uint64_t>(total) / 4 + 2)));
        break;
      case 2:
        mixed.advance_to(static_cast<StepCount>(rng.below(static_cast<std::uint64_t>(total) + 1)));
        break;
      default: {
        const auto den = static_cast<StepCount>(1 + rng.below(1000));
        mixed.advance_to_fraction(static_cast<StepCount>(rng.below(static_cast<std::uint64_t>(den) + 1)),
                                  den);
      }
    }
    ASSERT_GE(mixed.feed_steps_done(), before);
    while (stepped.feed_steps_done() < mixed.feed_steps_done()) stepped.step();
    for (int i = 0; i < kMaxPulseAxes; ++i) ASSERT_EQ(mixed.position(i), stepped.position(i));
  }
  while (!stepped.done()) ASSERT_EQ(mixed.step(), stepped.step());
  EXPECT_TRUE(mixed.done());
}

TEST(PulseDistributorProperty, AdvanceMatchesStepping) {
  Rng rng(99);
  for (int c = 0; c < 3'000; ++c) {
    SCOPED_TRACE(::testing::Message() << "case " << c);
    const auto move = random_move(rng, rng.axes(), static_cast<int>(rng.below(12)));
    check_advance_matches_stepping(rng, PulseMethod::Vector, move);
    check_advance_matches_stepping(rng, PulseMethod::Dda, move);
    if (HasFailure()) return;
  }
}

// Moves of up to 2^58 steps per axis: jump to a random feed step, then step on and compare with
// jumping straight there; the depth bound holds throughout (in 128-bit arithmetic).
TEST(PulseDistributorProperty, HugeMovesStayExact) {
  Rng rng(31337);
  for (int c = 0; c < 2'000; ++c) {
    SCOPED_TRACE(::testing::Message() << "case " << c);
    const auto move = random_move(rng, rng.axes(), 58);
    for (PulseMethod method : {PulseMethod::Vector, PulseMethod::Dda}) {
      PulseDistributor stepped(method);
      ASSERT_EQ(stepped.start(move), PulseStatus::Ok);
      const StepCount total = stepped.feed_steps_total();
      ReferenceTree ref(move);
      stepped.advance_to(static_cast<StepCount>(rng.below(static_cast<std::uint64_t>(total) + 1)));
      for (int s = 0; s < 16 && !stepped.done(); ++s) {
        stepped.step();
        PulseDistributor jumped(method);
        ASSERT_EQ(jumped.start(move), PulseStatus::Ok);
        jumped.advance_to(stepped.feed_steps_done());
        const StepCount k = stepped.feed_steps_done();
        for (int i = 0; i < static_cast<int>(move.size()); ++i) {
          const StepCount p = length(stepped.position(i));
          ASSERT_EQ(jumped.position(i), stepped.position(i));
          const StepCount len = length(move[i]);
          const bool within = method == PulseMethod::Vector
                                  ? within_depth_bound(p, k, len, total, active_depth(ref.path(i)))
                                  : 2 * scaled_error(p, k, len, total) <= total;
          ASSERT_TRUE(within) << "axis " << i << " at feed step " << k;
        }
      }
      stepped.advance_to(total);
      for (int i = 0; i < static_cast<int>(move.size()); ++i) ASSERT_EQ(stepped.position(i), move[i]);
    }
  }
}

}  // namespace
