// SPDX-License-Identifier: GPL-3.0-or-later
// Vector distribution (a tree of 2-axis least-deviation interpolators) and DDA step generation.
//
// Vector method (multi-axis "motion vector distribution", after the 5-axis EDM controller paper in
// shared/reference/001): axes are paired, each pair is a 2-axis least-deviation line interpolator,
// and the pairs are paired again as 2-axis lines over their step totals, up to one root. A feed step
// walks from the root to one axis. A node with children of totals a and b, after x and y feed steps
// of its children, has deviation F = x*b - y*a; stepping the first child adds b, the second subtracts
// a, and it takes the step that leaves |F| smaller (ties to the first), i.e. the first iff
// 2F <= a - b. That keeps F in (-S/2, S/2] for S = a+b, so after t = x+y feed steps
//     x(t) = floor((t*a + floor(S/2)) / S)      (t*a/S rounded half up),
// which is what lets advance() jump to any feed step in O(N). Bounds: docs/pulse-distribution.md.
//
// DDA: feed step k moves every axis i whose position floor((k*|ai| + floor(n/2)) / n) grows, with
// n = max|ai|, i.e. accumulators of capacity n started half full.
#include "opencnc/motion/pulse_distributor.hpp"

#include <algorithm>
#include <type_traits>

namespace opencnc::motion {

static_assert(std::is_trivially_copyable_v<PulseDistributor>, "must be able to live in shared memory");
static_assert(std::is_standard_layout_v<PulseDistributor>);

namespace {

// Products of two step counts (each <= 2^62) need 128 bits.
__extension__ using Int128 = __int128;

constexpr std::uint8_t kLeafBit = 0x80;

// Children of every pair node for one axis count, in preorder (a child after its parent).
struct TreeShape {
  int node_count = 0;
  std::array<std::array<std::uint8_t, 2>, PulseDistributor::kMaxPairNodes> children{};
};

constexpr std::uint8_t leaf(int axis) {
  return static_cast<std::uint8_t>(axis | kLeafBit);
}

// Appends the node over pairs [lo, hi) (pair p = leaves 2p and 2p+1) and returns its index. The
// smaller half goes first, which gives the paper's layouts: six axes = a pair and a group of four,
// eight = two groups of four; nine axes (plus the zero pad) = a group of four and a group of six.
constexpr std::uint8_t add_subtree(TreeShape& shape, int lo, int hi) {
  const auto id = static_cast<std::uint8_t>(shape.node_count++);
  if (hi - lo == 1) {
    shape.children[id] = {leaf(2 * lo), leaf(2 * lo + 1)};
    return id;
  }
  const int mid = lo + (hi - lo) / 2;
  const std::uint8_t first = add_subtree(shape, lo, mid);
  const std::uint8_t second = add_subtree(shape, mid, hi);
  shape.children[id] = {first, second};
  return id;
}

constexpr auto kTreeShapes = [] {
  std::array<TreeShape, kMaxPulseAxes + 1> shapes{};
  for (int axes = 1; axes <= kMaxPulseAxes; ++axes) add_subtree(shapes[axes], 0, (axes + 1) / 2);
  return shapes;
}();
static_assert(kTreeShapes[kMaxPulseAxes].node_count == PulseDistributor::kMaxPairNodes);

// floor(done * part / whole + 1/2): the steps a share `part` of `whole` has taken after `done`.
constexpr StepCount round_share(StepCount done, StepCount part, StepCount whole) noexcept {
  return static_cast<StepCount>((Int128{done} * part + whole / 2) / whole);
}

constexpr bool in_range(Int128 steps) noexcept {
  return steps >= -kMaxPulseSteps && steps <= kMaxPulseSteps;
}

}  // namespace

PulseDistributor::PulseDistributor(PulseMethod method) noexcept : method_(method) {}

PulseStatus PulseDistributor::start(std::span<const StepCount> increments) noexcept {
  if (increments.empty() || increments.size() > static_cast<std::size_t>(kMaxPulseAxes)) {
    return PulseStatus::BadAxis;
  }
  const int axes = static_cast<int>(increments.size());
  StepCount sum = 0;
  StepCount longest = 0;
  for (int i = 0; i < axes; ++i) {
    const StepCount inc = increments[i];
    if (inc < -kMaxPulseSteps || inc > kMaxPulseSteps) return PulseStatus::MoveTooLong;
    const StepCount len = inc < 0 ? -inc : inc;
    if (len > kMaxPulseSteps - sum) return PulseStatus::MoveTooLong;
    if (!in_range(Int128{position(i)} + inc)) return PulseStatus::PositionOutOfRange;
    sum += len;
    longest = std::max(longest, len);
  }

  for (int i = 0; i < kMaxPulseAxes; ++i) origin_[i] = position(i);
  length_.fill(0);
  progress_.fill(0);
  negative_mask_ = 0;
  for (int i = 0; i < axes; ++i) {
    const StepCount inc = increments[i];
    length_[i] = inc < 0 ? -inc : inc;
    if (inc < 0) negative_mask_ = static_cast<std::uint16_t>(negative_mask_ | (1u << i));
  }
  axis_count_ = static_cast<std::uint8_t>(axes);
  done_ = 0;
  if (method_ == PulseMethod::Vector) {
    total_ = sum;
    start_vector();
  } else {
    total_ = longest;
    start_dda();
  }
  return PulseStatus::Ok;
}

void PulseDistributor::start_vector() noexcept {
  const TreeShape& shape = kTreeShapes[axis_count_];
  node_count_ = static_cast<std::uint8_t>(shape.node_count);
  auto total_of = [this](std::uint8_t child) {
    if (child & kLeafBit) return length_[child & ~kLeafBit];
    return nodes_[child].first_total + nodes_[child].second_total;
  };
  for (int id = node_count_ - 1; id >= 0; --id) {  // children first: they sit after their parent
    PairNode& node = nodes_[id];
    node.first = shape.children[id][0];
    node.second = shape.children[id][1];
    node.first_total = total_of(node.first);
    node.second_total = total_of(node.second);
    node.deviation = 0;
    node.threshold = (node.first_total - node.second_total) >> 1;  // arithmetic shift: floor
  }
}

void PulseDistributor::start_dda() noexcept {
  accumulator_.fill(0);
  for (int i = 0; i < axis_count_; ++i) accumulator_[i] = total_ / 2;
}

StepPulses PulseDistributor::step() noexcept {
  if (done_ == total_) return {0, negative_mask_};
  ++done_;
  const std::uint16_t mask = method_ == PulseMethod::Vector ? step_vector() : step_dda();
  return {mask, negative_mask_};
}

std::uint16_t PulseDistributor::step_vector() noexcept {
  // Walk from the root (node 0) to a leaf; a path never has more nodes than the tree.
  std::uint8_t code = 0;
  for (int level = 0; level < node_count_; ++level) {
    PairNode& node = nodes_[code];
    if (node.deviation <= node.threshold) {
      node.deviation += node.second_total;
      code = node.first;
    } else {
      node.deviation -= node.first_total;
      code = node.second;
    }
    if (code & kLeafBit) {
      const int axis = code & ~kLeafBit;
      ++progress_[axis];
      return static_cast<std::uint16_t>(1u << axis);
    }
  }
  return 0;  // unreachable: every path ends at a leaf, and a child without steps is never chosen
}

std::uint16_t PulseDistributor::step_dda() noexcept {
  std::uint16_t mask = 0;
  for (int i = 0; i < axis_count_; ++i) {
    accumulator_[i] += length_[i];
    if (accumulator_[i] >= total_) {
      accumulator_[i] -= total_;
      ++progress_[i];
      mask = static_cast<std::uint16_t>(mask | (1u << i));
    }
  }
  return mask;
}

StepCount PulseDistributor::advance(StepCount count) noexcept {
  if (count <= 0) return 0;
  return advance_to(count < total_ - done_ ? done_ + count : total_);
}

StepCount PulseDistributor::advance_to(StepCount index) noexcept {
  index = std::min(index, total_);
  if (index <= done_) return 0;
  const StepCount taken = index - done_;
  jump(index);
  return taken;
}

StepCount PulseDistributor::advance_to_fraction(StepCount num, StepCount den) noexcept {
  if (den <= 0 || num < 0 || num > den) return 0;
  return advance_to(static_cast<StepCount>(Int128{total_} * num / den));
}

void PulseDistributor::jump(StepCount index) noexcept {
  done_ = index;
  if (method_ == PulseMethod::Vector) {
    jump_vector(index);
  } else {
    jump_dda(index);
  }
}

void PulseDistributor::jump_vector(StepCount index) noexcept {
  std::array<StepCount, kMaxPairNodes> node_done{};
  node_done[0] = index;
  auto hand_out = [&](std::uint8_t child, StepCount steps) {
    if (child & kLeafBit) {
      progress_[child & ~kLeafBit] = steps;
    } else {
      node_done[child] = steps;
    }
  };
  for (int id = 0; id < node_count_; ++id) {  // parents first, so node_done[id] is known
    PairNode& node = nodes_[id];
    const StepCount t = node_done[id];
    const StepCount whole = node.first_total + node.second_total;
    const StepCount x = whole == 0 ? 0 : round_share(t, node.first_total, whole);
    node.deviation = static_cast<StepCount>(Int128{x} * whole - Int128{t} * node.first_total);
    hand_out(node.first, x);
    hand_out(node.second, t - x);
  }
}

void PulseDistributor::jump_dda(StepCount index) noexcept {
  for (int i = 0; i < axis_count_; ++i) {
    const Int128 scaled = Int128{index} * length_[i] + total_ / 2;
    progress_[i] = static_cast<StepCount>(scaled / total_);
    accumulator_[i] = static_cast<StepCount>(scaled % total_);
  }
}

PulseStatus PulseDistributor::set_position(int axis, StepCount steps) noexcept {
  if (axis < 0 || axis >= kMaxPulseAxes) return PulseStatus::BadAxis;
  const bool negative = (negative_mask_ >> axis) & 1u;
  const Int128 origin = Int128{steps} + (negative ? progress_[axis] : -progress_[axis]);
  const Int128 end = origin + (negative ? -length_[axis] : length_[axis]);
  if (!in_range(steps) || !in_range(origin) || !in_range(end)) return PulseStatus::PositionOutOfRange;
  origin_[axis] = static_cast<StepCount>(origin);
  return PulseStatus::Ok;
}

StepCount PulseDistributor::position(int axis) const noexcept {
  if (axis < 0 || axis >= kMaxPulseAxes) return 0;
  const bool negative = (negative_mask_ >> axis) & 1u;
  return origin_[axis] + (negative ? -progress_[axis] : progress_[axis]);
}

}  // namespace opencnc::motion
