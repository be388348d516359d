// SPDX-License-Identifier: GPL-3.0-or-later
// Look-ahead window: widening for the moving average, curvature-step density, braking prefix,
// backward pass, soft links.
#include "lookahead.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "path_geometry.hpp"

namespace opencnc::plan::detail {

using traj::BlockKind;
using traj::FeedClass;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::size_t kSoftScan = 64;
constexpr double kMinPiece = 1e-4;   ///< blocks are not split into pieces shorter than this
constexpr double kSplitGain = 1e-3;  ///< nor for a limit less than this much (relative) lower

bool is_marker(const PlannedBlock& p) {
  return p.b.kind == BlockKind::Marker;
}
bool is_stop(const traj::MotionBlock& b) {
  return b.kind == BlockKind::Marker && b.marker != traj::MarkerKind::Report;
}
double end_s(const PlannedBlock& p) {
  return p.start_s + p.b.length;
}
bool has_step(const Pose& s) {
  for (double v : s.v) {
    if (v > 0) return true;
  }
  return false;
}

}  // namespace

PlannedBlock& Lookahead::next_slot() {
  PlannedBlock& pb = window_.spare();
  pb.cap_raw = pb.accel_raw = pb.junction = 0;
  pb.step = Pose{};
  return pb;
}

void Lookahead::push_next() {
  PlannedBlock& pb = window_.spare();
  pb.start_s = total_s_;
  pb.cap = pb.cap_raw;
  pb.accel = pb.accel_raw;
  pb.local = pb.entry = pb.prefix = 0;
  pb.step_sum = pb.step;
  total_s_ += pb.b.length;
  window_.commit_spare();
  if (widening() && !is_marker(pb)) {
    add_steps(window_.size() - 1);
    widen_last();
  }
  dirty_ = true;
}

// Curvature steps closer than three servo periods of travel add up in a sampled jerk, so each
// step's speed limit uses the sum of the steps around it: v² · Σ|Δg''| ≤ (4/3)·η·J·T_servo.
void Lookahead::add_steps(std::size_t m) {
  PlannedBlock& nb = window_[m];
  if (!has_step(nb.step)) return;
  const auto limit = [this](const Pose& sum) {
    double v = kInf;
    for (int i = 0; i < kAxisCount; ++i) {
      const double budget = p_.step_budget[static_cast<std::size_t>(i)];
      if (budget > 0 && sum[i] > 0) v = std::min(v, std::sqrt(budget / sum[i]));
    }
    return v;
  };
  lowered_.clear();
  for (std::size_t j = m; j-- > 0;) {
    PlannedBlock& jb = window_[j];
    if (nb.start_s - jb.start_s > p_.step_window_s) break;
    if (is_marker(jb) || !has_step(jb.step)) continue;
    for (int i = 0; i < kAxisCount; ++i) {
      jb.step_sum[i] += nb.step[i];
      nb.step_sum[i] += jb.step[i];
    }
    const double v = limit(jb.step_sum);
    if (v < jb.junction) {
      jb.junction = v;
      lowered_.push_back({jb.start_s, v});
    }
  }
  nb.junction = std::min(nb.junction, limit(nb.step_sum));
  // Widen the lowered junction limits only now: splitting blocks moves them in the deque.
  for (const auto& [at, v] : lowered_) limit_range(at - v * p_.filter_s, at + v * p_.filter_s, v, kInf);
}

// The limits of the new last block reach back over the blocks before it, and theirs reach
// forward over it.
void Lookahead::widen_last() {
  const PlannedBlock m = window_.back();
  const double T = p_.filter_s;
  const double start = m.start_s, end = end_s(m);
  for (std::size_t j = window_.size(); j-- > 0;) {
    const PlannedBlock jb = window_[j];
    if (jb.start_s >= start) continue;  // the new block (or a piece of it)
    if (start - end_s(jb) >= reach_) break;
    if (is_marker(jb)) continue;
    limit_range(start, end_s(jb) + jb.cap_raw * T, jb.cap_raw, jb.accel_raw);
    if (jb.junction > 0 && jb.junction < kInf)
      limit_range(start, jb.start_s + jb.junction * T, jb.junction, kInf);
  }
  limit_range(start - m.cap_raw * T, end, m.cap_raw, m.accel_raw);
  if (m.junction > 0 && m.junction < kInf)
    limit_range(start - m.junction * T, start + m.junction * T, m.junction, kInf);
}

// Lowers cap and budget of the path between s = from and s = to, splitting blocks that reach
// beyond it (only unsettled blocks are ever in range).
void Lookahead::limit_range(double from, double to, double cap, double accel) {
  if (!(to > from)) return;
  for (std::size_t k = window_.size(); k-- > settled_;) {
    const double s0 = window_[k].start_s, s1 = end_s(window_[k]);
    if (s1 <= from) break;
    if (s0 >= to || is_marker(window_[k])) continue;
    const double lo = std::max(from, s0), hi = std::min(to, s1);
    if (!(hi > lo)) continue;
    PlannedBlock& whole = window_[k];
    // A rigid tap's blocks stay whole (the tap runs them as one motion): they take the lower
    // limits throughout.
    if (!(cap < whole.cap * (1 - kSplitGain) || accel < whole.accel * (1 - kSplitGain)) ||
        (whole.b.flags & traj::kRigidTap)) {
      whole.cap = std::min(whole.cap, cap);  // too small a change to be worth a split
      whole.accel = std::min(whole.accel, accel);
      continue;
    }
    if (s1 - hi > kMinPiece && hi - s0 > kMinPiece) split(k, hi - s0);
    std::size_t target = k;
    if (lo - s0 > kMinPiece) {
      split(k, lo - s0);
      target = k + 1;
    }
    PlannedBlock& t = window_[target];
    t.cap = std::min(t.cap, cap);
    t.accel = std::min(t.accel, accel);
  }
}

void Lookahead::split(std::size_t k, double x) {
  PlannedBlock tail = window_[k];
  PlannedBlock& head = window_[k];
  trim_end(head.b, head.b.length - x);
  trim_start(tail.b, x);
  rebase(tail.b, end_point(head.b));
  tail.start_s = head.start_s + x;
  tail.junction = kInf;
  tail.step = Pose{};
  tail.step_sum = Pose{};
  window_.insert(k + 1, tail);
}

// Blocks whose widened limits can no longer change get their prefix and own entry limit.
void Lookahead::settle() {
  const std::size_t first_new = settled_;
  while (settled_ < window_.size()) {
    PlannedBlock& pb = window_[settled_];
    if (!finished_ && widening() && total_s_ - end_s(pb) < reach_) break;
    pb.prefix = next_prefix_;
    if (is_marker(pb)) {
      pb.local = is_stop(pb.b) ? 0.0 : kInf;
      pb.accel = 0;
      pb.cap = 0;
      if (is_stop(pb.b)) prev_stop_ = true;
    } else {
      pb.local = std::min({pb.junction, pb.cap, prev_stop_ ? 0.0 : prev_path_cap_});
      prev_path_cap_ = pb.cap;
      prev_stop_ = false;
      next_prefix_ += 2.0 * pb.accel * pb.b.length;
    }
    ++settled_;
  }
  if (settled_ > first_new || finished_) backward_pass(first_new);
}

// Entry speeds from the end of the settled blocks backward, assuming a stop after them:
// E_k = min(local_k, √(E_{k+1}² + 2·a_k·L_k)). Later blocks only ever raise these values, so the
// sweep stops where an older value does not change; a block whose entry equals its own limit is
// final, and so is everything before it.
void Lookahead::backward_pass(std::size_t first_new) {
  double after = 0;
  for (std::size_t k = settled_; k-- > 0;) {
    PlannedBlock& pb = window_[k];
    const double e = std::min(pb.local, std::sqrt(after * after + 2.0 * pb.accel * pb.b.length));
    if (k < first_new && e == pb.entry) break;
    pb.entry = e;
    after = e;
  }
  if (finished_ && settled_ == window_.size()) {
    pinned_ = settled_;
    return;
  }
  for (std::size_t k = settled_; k-- > pinned_;) {
    if (window_[k].entry == window_[k].local) {
      pinned_ = k + 1;
      break;
    }
  }
}

std::uint64_t Lookahead::soft_link(std::uint64_t seq) {
  const traj::MotionBlock& f = window_.front().b;
  if (f.kind == BlockKind::Marker) return traj::kNoBlock;
  // Same class and nominal speed as the block before: the first lower one further on is the same.
  if (last_link_ != traj::kNoBlock && last_link_ > seq && f.feed_class == last_link_class_ &&
      f.feed == last_link_feed_) {
    return last_link_;
  }
  last_link_class_ = f.feed_class;
  last_link_feed_ = f.feed;
  last_link_ = find_soft_link(seq);
  return last_link_;
}

std::uint64_t Lookahead::find_soft_link(std::uint64_t seq) const {
  const traj::MotionBlock& f = window_.front().b;
  const std::size_t n = std::min(window_.size(), kSoftScan + 1);
  for (std::size_t k = 1; k < n; ++k) {
    const traj::MotionBlock& q = window_[k].b;
    if (q.kind == BlockKind::Marker) continue;
    if (q.feed_class != f.feed_class || q.feed < f.feed) return seq + k;
  }
  if (finished_ && n == window_.size()) return traj::kNoBlock;
  return seq + n;  // not decided yet: the tick continues the walk from that block's own link
}

bool Lookahead::front_link_decided() const {
  if (finished_ || window_.size() > kSoftScan || window_.empty()) return true;
  const traj::MotionBlock& f = window_.front().b;
  if (f.kind == BlockKind::Marker) return true;
  for (std::size_t k = 1; k < window_.size(); ++k) {
    const traj::MotionBlock& q = window_[k].b;
    if (q.kind == BlockKind::Marker) continue;
    if (q.feed_class != f.feed_class || q.feed < f.feed) return true;
  }
  return false;
}

void Lookahead::front_for_queue(std::uint64_t seq, traj::MotionBlock& out) {
  const PlannedBlock& pb = window_.front();
  out = pb.b;
  out.seq = seq;
  out.v_cap = pb.cap;
  out.accel = pb.accel;
  out.v_entry = pb.entry;
  out.brake_prefix = pb.prefix;
  out.next_soft = soft_link(seq);
}

void Lookahead::pop_front() {
  window_.pop_front();
  if (settled_ > 0) --settled_;
  if (pinned_ > 0) --pinned_;
}

}  // namespace opencnc::plan::detail
