// SPDX-License-Identifier: GPL-3.0-or-later
// The look-ahead window: blocks waiting to be published, their limits widened for the moving
// average, the braking prefix and the backward pass that makes each block's entry speed final.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "block_limits.hpp"
#include "opencnc/traj/block_queue.hpp"
#include "ring.hpp"

namespace opencnc::plan::detail {

/// A block as the planner hands it to the window.
struct PlannedBlock {
  traj::MotionBlock b;   ///< geometry, identity, class, nominal speed
  RawLimits raw{};       ///< cap, acceleration and jerk budget of the block itself
  double v_max = 0;      ///< the fastest it is ever commanded (for limits computed again)
  double junction = 0;   ///< speed limit where the block starts (0: stop there, +∞: none)
  Pose step{};           ///< per axis |Δg''| where the block starts (curvature step, jerk only)
  Pose step_sum{};       ///< the window's: curvature steps within three servo periods of this one
  bool piece = false;    ///< a piece of a longer block: settled (split at its ranges) as a long one
};

/// A settled block: final limits, braking prefix and entry speed.
struct SettledBlock {
  traj::MotionBlock b;
  double start_s = 0;  ///< s of the block's start since the run began
  double cap = 0;      ///< widened for the moving average (≤ the block's own)
  double accel = 0;
  double jerk = 0;
  double local = 0;   ///< largest entry speed from the block's own limits
  double entry = 0;   ///< backward pass result
  double prefix = 0;  ///< braking prefix C at the start
};

/// What the window needs to know about the moving average and the jerk limits.
struct WindowParams {
  double filter_s = 0;  ///< moving-average length T (0: jerk not limited, nothing is widened)
  double period_s = 1e-3;
  double v_bound = 0;  ///< no speed along s exceeds this
  /// Per axis: Σ v²·|Δg''| over the curvature steps met within three servo periods may not
  /// exceed this ((4/3)·η·J·T_servo); 0 where jerk is not limited.
  std::array<double, kAxisCount> step_budget{};
  double step_window_s = 0;  ///< path length of three servo periods at v_bound
  /// The limits of blocks next to a curvature step are computed again with this much of the
  /// jerk (1 − η) and these parameters.
  const LimitParams* limits = nullptr;
  /// A forced publish (the window full and nothing final) waits until the window holds at least
  /// this many blocks and this much path (the braking distance from v_bound): the look-ahead
  /// never limits the speed before that. `hard_blocks` bounds the memory whatever the path.
  std::size_t soft_blocks = 0;
  double soft_length = 0;
  std::size_t hard_blocks = 16384;
};

/// Holds planned blocks until their entry speed can no longer change.
///
/// With a moving average of length T on s (jerk limits), the speed and acceleration commanded at
/// a point are averages of the generator's values over the last T, during which the generator
/// stays within c·T/2 of the commanded point (c: the speed it does not exceed there). So block
/// b's cap applies to the generator from c_b·T/2 before b to as far after it, and a junction
/// limit v_j over v_j·T/2 around it (the commanded speed at every instant is then within them,
/// and the trace's finite differences are averages of the continuous derivatives); its budget
/// over c_b·(T/2 + 3 periods) (the periods keep every budget near the commanded point within
/// the jerk budget there times T, which the tick's braking relies on), and the jerk budget
/// (used where the commanded point is) over ±4 periods of travel. Ranges do
/// not reach across a stop (the generator waits there until the average has arrived). A block
/// settles once every block whose ranges may reach it is known; then its widened limits are the
/// lowest of the ranges over it, and a long block is split where they change. See docs/planner.md.
class Lookahead {
 public:
  explicit Lookahead(const WindowParams& p);

  /// The slot for the next block: fill `b`, `raw`, `v_max`, `junction` and `step`, then add it
  /// with push_next().
  PlannedBlock& next_slot();
  void push_next();
  /// No more blocks will come: everything becomes final.
  void finish() noexcept {
    finished_ = true;
    dirty_ = true;
  }
  /// After finish() and once every block has been published: blocks may come again, the first
  /// from rest (a stream's sync point).
  void reopen() noexcept;

  std::size_t size() const noexcept { return settled_.size() + pending_.size(); }
  bool empty() const noexcept { return settled_.empty() && pending_.empty(); }
  /// Whether the planner should read further before publishing by force (see WindowParams).
  bool wants_more() const noexcept;
  /// Blocks at the front whose published values are final.
  std::size_t publishable() {
    refresh();
    return pinned_;
  }
  /// Blocks at the front whose widened limits are final (a forced publish may take these).
  std::size_t settled() {
    refresh();
    return settled_.size();
  }

  /// Whether the front block's soft link can be decided now: enough settled blocks after it (or
  /// a lower one among them, or nothing more comes). Its link then does not depend on how far the
  /// program had been read when it was published (a stream's pieces).
  bool front_link_decided();
  /// Writes the front block as it goes to the queue with sequence number `seq`.
  void front_for_queue(std::uint64_t seq, traj::MotionBlock& out);
  /// Removes the front block (publishable() or settled() > 0).
  void pop_front();

 private:
  /// The raw limits of one block, kept while they may still widen a block being settled.
  struct Range {
    double start = 0, end = 0;  ///< s of the block
    double cap = 0, accel = 0, jerk = 0;
    double junction = 0;      ///< speed limit at its start
    std::uint64_t epoch = 0;  ///< stops before it: ranges reach only blocks of the same epoch
    bool marker = false;
    bool scaled = false;  ///< its limits already hold with the jerk share left by curvature steps
  };
  struct Widened {
    double cap, accel, jerk;
  };

  bool widening() const noexcept { return p_.filter_s > 0; }
  void add_steps(std::size_t m);
  void scale_near_step(std::size_t m);
  void refresh() {
    if (dirty_) settle();
    dirty_ = false;
  }
  bool can_settle_front() const noexcept;
  void settle();
  void settle_front();
  Widened widened_over(double from, double to, std::uint64_t epoch, const Range& own) const;
  void append_settled(const traj::MotionBlock& b, double start_s, const Widened& w, double junction);
  void backward_pass(std::size_t first_new);
  std::uint64_t soft_link(std::uint64_t seq);
  std::uint64_t find_soft_link(std::uint64_t seq) const;
  Range& range_of(std::size_t pending_index) noexcept {
    return ranges_[ranges_.size() - pending_.size() + pending_index];
  }

  WindowParams p_;
  double half_window_ = 0;      ///< T/2 + 3 periods: how far (per unit of speed) budget ranges reach
  double cap_window_ = 0;       ///< T/2: how far (per unit of speed) cap and junction ranges reach
  double jerk_window_ = 0;      ///< 4 periods: how far (per unit of speed) jerk ranges reach
  double reach_ = 0;            ///< the farthest any range reaches back from its block
  Ring<PlannedBlock> pending_;  ///< pushed, limits not yet final
  Ring<Range> ranges_;          ///< raw limits: every pending block's and earlier ones still in reach
  std::uint64_t epoch_ = 0;     ///< of the last pushed block
  double total_s_ = 0;          ///< s at the end of the last pushed block
  double scaled_until_ = -1;    ///< blocks starting before this s are next to a curvature step
  bool cut_ = false;            ///< the hard limit was reached: a stop after the pending blocks

  Ring<SettledBlock> settled_;
  std::size_t pinned_ = 0;    ///< front settled blocks with a final entry speed
  double next_prefix_ = 0;    ///< C at the end of the settled blocks
  double prev_path_cap_ = 0;  ///< cap of the last settled path block (for the next junction)
  bool prev_stop_ = true;     ///< the last settled block was a stop (or nothing yet)
  bool finished_ = false;
  bool dirty_ = false;  ///< blocks pushed since the last settle()
  // The last soft link handed out: blocks with the same class and nominal speed share it.
  std::uint64_t last_link_ = traj::kNoBlock;
  traj::FeedClass last_link_class_ = traj::FeedClass::Feed;
  double last_link_feed_ = -1;
  std::vector<double> cuts_;  ///< scratch: where a long block is split
};

}  // namespace opencnc::plan::detail
