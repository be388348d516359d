// SPDX-License-Identifier: GPL-3.0-or-later
// The look-ahead window: blocks waiting to be published, their widened limits, the braking prefix
// and the backward pass that makes each block's entry speed final.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "opencnc/traj/block_queue.hpp"
#include "ring.hpp"

namespace opencnc::plan::detail {

/// A block in the window with the planner's working values.
struct PlannedBlock {
  traj::MotionBlock b;   ///< geometry, identity, class, nominal speed
  double cap_raw = 0;    ///< speed cap of the block itself
  double accel_raw = 0;  ///< acceleration budget of the block itself
  double junction = 0;   ///< speed limit where the block starts (0: stop there, +∞: none)
  Pose step{};           ///< per axis |Δg''| where the block starts (curvature step, jerk only)
  // Working values.
  double start_s = 0;  ///< s of the block's start since the run began
  double cap = 0;      ///< cap widened by the moving average (≤ cap_raw)
  double accel = 0;    ///< budget widened by the moving average (≤ accel_raw)
  double local = 0;    ///< largest entry speed from the block's own limits
  double entry = 0;    ///< backward pass result
  double prefix = 0;   ///< braking prefix C at the start
  Pose step_sum{};     ///< curvature steps within one jerk window of this one
};

/// What the window needs to know about the moving average and the jerk limits.
struct WindowParams {
  double filter_s = 0;  ///< moving-average length T (0: jerk not limited, nothing is widened)
  double v_bound = 0;   ///< no speed along s exceeds this
  /// Per axis: Σ v²·|Δg''| over the curvature steps met within three servo periods may not
  /// exceed this ((4/3)·η·J·T_servo); 0 where jerk is not limited.
  std::array<double, kAxisCount> step_budget{};
  double step_window_s = 0;  ///< path length of three servo periods at v_bound
};

/// Holds planned blocks until their entry speed can no longer change.
///
/// With a moving average of length T on s (jerk limits), the speed and acceleration commanded at
/// a point are averages of the generator's values over the last T, which covers at most v·T of
/// path. While the average is inside block b that span is at most cap_b·T, so the generator runs
/// against widened limits: block b's cap and budget apply from cap_b·T before it to cap_b·T after
/// it, a junction limit v_j over ±v_j·T. Blocks are split where such a range ends inside them.
/// See docs/planner.md.
class Lookahead {
 public:
  explicit Lookahead(const WindowParams& p)
      : p_(p), reach_(std::max(p.v_bound * p.filter_s, p.step_window_s)) {}

  /// The slot for the next block, its working values cleared: fill `b` and the raw limits,
  /// then add it with push_next().
  PlannedBlock& next_slot();
  void push_next();
  /// No more blocks will come: everything becomes final.
  void finish() noexcept {
    finished_ = true;
    dirty_ = true;
  }
  /// After finish() and once every block has been published: blocks may come again, the first
  /// from rest (a stream's sync point).
  void reopen() noexcept {
    finished_ = false;
    prev_stop_ = true;
    settled_ = pinned_ = 0;
  }

  std::size_t size() const noexcept { return window_.size(); }
  bool empty() const noexcept { return window_.empty(); }
  /// Blocks at the front whose published values are final.
  std::size_t publishable() {
    refresh();
    return pinned_;
  }
  /// Blocks at the front whose widened limits are final (a forced publish may take these).
  std::size_t settled() {
    refresh();
    return settled_;
  }

  /// Whether the front block's soft link can be decided now: the window holds enough blocks
  /// after it (or a lower one among them, or nothing more comes). Its link then does not depend
  /// on how far the program had been read when it was published (a stream's pieces).
  bool front_link_decided() const;
  /// Writes the front block as it goes to the queue with sequence number `seq`.
  void front_for_queue(std::uint64_t seq, traj::MotionBlock& out);
  /// Removes the front block (publishable() or settled() > 0).
  void pop_front();

 private:
  bool widening() const noexcept { return p_.filter_s > 0; }
  void add_steps(std::size_t m);
  void widen_last();
  void limit_range(double from, double to, double cap, double accel);
  void split(std::size_t k, double x);
  void refresh() {
    if (dirty_) settle();
    dirty_ = false;
  }
  void settle();
  void backward_pass(std::size_t first_new);
  std::uint64_t soft_link(std::uint64_t seq);
  std::uint64_t find_soft_link(std::uint64_t seq) const;

  WindowParams p_;
  double reach_ = 0;  ///< the widest range any limit is widened over
  Ring<PlannedBlock> window_;
  double total_s_ = 0;        ///< s at the end of the last pushed block
  std::size_t settled_ = 0;   ///< front blocks with final widened limits, prefix and local
  std::size_t pinned_ = 0;    ///< front blocks with a final entry speed
  double next_prefix_ = 0;    ///< C at the end of the settled blocks
  double prev_path_cap_ = 0;  ///< cap of the last settled path block (for the next junction)
  bool prev_stop_ = true;     ///< the last settled block was a stop (or nothing yet)
  bool finished_ = false;
  bool dirty_ = false;  ///< blocks pushed since the last settle()
  // The last soft link handed out: blocks with the same class and nominal speed share it.
  std::uint64_t last_link_ = traj::kNoBlock;
  traj::FeedClass last_link_class_ = traj::FeedClass::Feed;
  double last_link_feed_ = -1;
  std::vector<std::pair<double, double>> lowered_;  ///< scratch: junctions whose limit dropped
};

}  // namespace opencnc::plan::detail
