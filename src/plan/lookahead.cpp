// SPDX-License-Identifier: GPL-3.0-or-later
// Look-ahead window: widening for the moving average, braking prefix, backward pass, soft links.
#include "lookahead.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace opencnc::plan::detail {

using traj::BlockKind;
using traj::FeedClass;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::size_t kSoftScan = 64;

bool is_stop(const traj::MotionBlock& b) {
  return b.kind == BlockKind::Marker && b.marker != traj::MarkerKind::Report;
}

}  // namespace

void Lookahead::push(const PlannedBlock& block) {
  PlannedBlock pb = block;
  pb.start_s = total_s_;
  pb.cap = pb.cap_raw;
  pb.accel = pb.accel_raw;
  total_s_ += pb.b.length;
  window_.push_back(pb);
  if (filter_s_ > 0 && pb.b.kind != BlockKind::Marker) widen(window_.size() - 1);
  dirty_ = true;
}

void Lookahead::finish() {
  finished_ = true;
  dirty_ = true;
}

// Applies the widened limits between the new block m and the blocks within reach before it
// (blocks further back are unaffected both ways, and those are the settled ones).
void Lookahead::widen(std::size_t m) {
  PlannedBlock& nb = window_[m];
  const double T = filter_s_;
  if (nb.junction > 0 && nb.junction < kInf) nb.cap = std::min(nb.cap, nb.junction);
  for (std::size_t j = m; j-- > 0;) {
    PlannedBlock& jb = window_[j];
    const double gap = nb.start_s - (jb.start_s + jb.b.length);
    if (gap >= reach_) break;
    if (jb.b.kind == BlockKind::Marker) continue;
    if (gap < nb.cap_raw * T) jb.cap = std::min(jb.cap, nb.cap_raw);
    if (gap < jb.cap_raw * T) nb.cap = std::min(nb.cap, jb.cap_raw);
    if (nb.junction > 0 && gap < nb.junction * T) jb.cap = std::min(jb.cap, nb.junction);
    if (jb.junction > 0 && nb.start_s - jb.start_s < jb.junction * T) nb.cap = std::min(nb.cap, jb.junction);
    jb.accel = std::min(jb.accel, nb.accel_raw);
    nb.accel = std::min(nb.accel, jb.accel_raw);
  }
}

// Blocks whose widened limits can no longer change get their prefix and own entry limit.
void Lookahead::settle() {
  const std::size_t first_new = settled_;
  while (settled_ < window_.size()) {
    PlannedBlock& pb = window_[settled_];
    if (!finished_ && filter_s_ > 0 && total_s_ - (pb.start_s + pb.b.length) < reach_) break;
    pb.prefix = next_prefix_;
    if (pb.b.kind == BlockKind::Marker) {
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
      f.feed == last_link_feed_ && f.feed_class != FeedClass::SpindleSync) {
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
    if (q.feed_class != f.feed_class || q.feed_class == FeedClass::SpindleSync || q.feed < f.feed) return seq + k;
  }
  if (finished_ && n == window_.size()) return traj::kNoBlock;
  return seq + n;  // not decided yet: the tick continues the walk from that block's own link
}

traj::MotionBlock Lookahead::front_for_queue(std::uint64_t seq) {
  const PlannedBlock& pb = window_.front();
  traj::MotionBlock b = pb.b;
  b.seq = seq;
  b.v_cap = pb.cap;
  b.accel = pb.accel;
  b.v_entry = pb.entry;
  b.brake_prefix = pb.prefix;
  b.next_soft = soft_link(seq);
  return b;
}

void Lookahead::pop_front() {
  window_.pop_front();
  if (settled_ > 0) --settled_;
  if (pinned_ > 0) --pinned_;
}

}  // namespace opencnc::plan::detail
