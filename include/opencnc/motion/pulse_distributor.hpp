// SPDX-License-Identifier: GPL-3.0-or-later
// Step distribution for stepper axes: turns a straight move of N axes into feed steps
// (step masks + direction bits), by vector distribution or by a DDA.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "opencnc/core/axes.hpp"

namespace opencnc::motion {

/// Steps on one axis, or feed steps of a move.
using StepCount = std::int64_t;

/// Axes one distributor drives. Slot i is increments[i] of the move (a stepper channel), not Axis(i).
inline constexpr int kMaxPulseAxes = kAxisCount;
/// Largest Σ|increment| of one move and largest |position|: keeps every intermediate inside int64.
inline constexpr StepCount kMaxPulseSteps = StepCount{1} << 62;

/// How a move is cut into feed steps (docs/pulse-distribution.md has the method and its bounds).
enum class PulseMethod : std::uint8_t {
  Vector,  ///< one axis per feed step, Σ|ai| feed steps: a tree of 2-axis least-deviation interpolators
  Dda,     ///< all axes whose accumulator overflows step together, max|ai| feed steps
};

/// Outcome of PulseDistributor::start() and set_position().
enum class PulseStatus : std::uint8_t {
  Ok,
  BadAxis,             ///< axis count outside 1..kMaxPulseAxes, or axis index out of range
  MoveTooLong,         ///< Σ|increment| above kMaxPulseSteps
  PositionOutOfRange,  ///< a position would leave [-kMaxPulseSteps, kMaxPulseSteps]
};

/// One feed step as a step/dir driver consumes it: set DIR lines from negative_mask, then pulse
/// the STEP lines in step_mask. Plain data; real-time safe.
struct StepPulses {
  std::uint16_t step_mask = 0;      ///< bit i: axis i takes one step now
  std::uint16_t negative_mask = 0;  ///< bit i: axis i moves toward negative (constant for a move)
  constexpr bool operator==(const StepPulses&) const noexcept = default;
};

/// Distributes the steps of straight moves over up to nine stepper axes so that they move
/// together along the line. Fixed-size plain data (trivially copyable, no pointers), so it may
/// live in shared memory. Not thread-safe: one owner thread (servo or step generator) calls it.
class PulseDistributor {
 public:
  /// Any thread; real-time safe. Idle, every position zero.
  explicit PulseDistributor(PulseMethod method = PulseMethod::Vector) noexcept;

  /// Owner thread; real-time safe, O(N). Begins a move of increments[i] steps on axis i
  /// (N = increments.size()) from the current positions; an unfinished move is dropped where it
  /// stands. A rejected move changes nothing.
  PulseStatus start(std::span<const StepCount> increments) noexcept;

  /// Owner thread; real-time safe, O(log N) for Vector, O(N) for Dda. The next feed step; empty
  /// step mask once the move is done.
  StepPulses step() noexcept;

  /// Owner thread; real-time safe, O(N) whatever the count. Takes up to `count` feed steps at once
  /// (a servo period that carries many) and returns how many it took; the state is exactly the
  /// one `count` calls of step() would leave.
  StepCount advance(StepCount count) noexcept;
  /// Owner thread; real-time safe, O(N). Moves forward to feed step `index` of the move (never
  /// back; clamped to the total); returns the feed steps taken.
  StepCount advance_to(StepCount index) noexcept;
  /// Owner thread; real-time safe, O(N). Moves forward to feed step floor(total * num / den) of the
  /// move, for 0 <= num <= den, den > 0 (anything else takes no step); returns the feed steps taken.
  StepCount advance_to_fraction(StepCount num, StepCount den) noexcept;

  /// Owner thread; real-time safe. Redefines the position of `axis` (e.g. after homing); a move in
  /// progress carries on relative to it.
  PulseStatus set_position(int axis, StepCount steps) noexcept;

  /// Owner thread (or any reader of a consistent copy); real-time safe. Accessors.
  PulseMethod method() const noexcept { return method_; }
  int axis_count() const noexcept { return axis_count_; }
  /// Feed steps of the current move: Σ|ai| for Vector, max|ai| for Dda.
  StepCount feed_steps_total() const noexcept { return total_; }
  StepCount feed_steps_done() const noexcept { return done_; }
  bool done() const noexcept { return done_ == total_; }
  std::uint16_t negative_mask() const noexcept { return negative_mask_; }
  /// Position of `axis` in steps (0 for an index out of range).
  StepCount position(int axis) const noexcept;

  /// Leaves of the vector method's pair tree (axes padded to an even count) and its pair nodes.
  static constexpr int kMaxLeaves = kMaxPulseAxes + 1;
  static constexpr int kMaxPairNodes = kMaxLeaves - 1;

 private:
  // One 2-axis least-deviation interpolator of the vector method. Its children are axes or
  // other nodes; x and y count the feed steps each child has taken.
  struct PairNode {
    StepCount first_total = 0;   // a: feed steps of the first child over the whole move
    StepCount second_total = 0;  // b
    StepCount deviation = 0;     // F = x*b - y*a, kept in (-(a+b)/2, (a+b)/2]
    StepCount threshold = 0;     // floor((a-b)/2): the first child steps while F <= threshold
    std::uint8_t first = 0;      // child code: node index, or axis index | kLeafBit
    std::uint8_t second = 0;
  };

  void start_vector() noexcept;
  void start_dda() noexcept;
  std::uint16_t step_vector() noexcept;
  std::uint16_t step_dda() noexcept;
  void jump(StepCount index) noexcept;
  void jump_vector(StepCount index) noexcept;
  void jump_dda(StepCount index) noexcept;

  PulseMethod method_;
  std::uint8_t axis_count_ = 0;
  std::uint8_t node_count_ = 0;
  std::uint16_t negative_mask_ = 0;
  StepCount total_ = 0;
  StepCount done_ = 0;
  std::array<StepCount, kMaxPulseAxes> origin_{};       // position at the start of the move
  std::array<StepCount, kMaxLeaves> length_{};          // |increment|; slot N is the zero pad axis
  std::array<StepCount, kMaxLeaves> progress_{};        // steps taken, toward |increment|
  std::array<StepCount, kMaxPulseAxes> accumulator_{};  // Dda: (k*|ai| + floor(n/2)) mod n, n = max|ai|
  std::array<PairNode, kMaxPairNodes> nodes_{};         // Vector: pair tree in preorder, root first
};

}  // namespace opencnc::motion
