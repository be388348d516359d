// SPDX-License-Identifier: GPL-3.0-or-later
// Look-ahead window: curvature-step density, widening for the moving average (settling), braking
// prefix, backward pass, soft links.
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
/// Short blocks are split only where a limit falls below this share of their own: lesser ones
/// cost little over the block's length, and every cut costs the settling a pass over the ranges.
constexpr double kShortSplitShare = 0.5;

bool is_stop(const traj::MotionBlock& b) {
  return b.kind == BlockKind::Marker && b.marker != traj::MarkerKind::Report;
}
bool has_step(const Pose& s) {
  for (double v : s.v) {
    if (v > 0) return true;
  }
  return false;
}
bool lower(double limit, double own, double share) {
  return limit < own * share;
}

}  // namespace

Lookahead::Lookahead(const WindowParams& p) : p_(p) {
  if (widening()) {
    half_window_ = 0.5 * p.filter_s + 3 * p.period_s;
    cap_window_ = 0.5 * p.filter_s;
    jerk_window_ = 4 * p.period_s;
    reach_ = std::max(p.v_bound * half_window_, p.step_window_s);
  }
}

PlannedBlock& Lookahead::next_slot() {
  PlannedBlock& pb = pending_.spare();
  pb.raw = RawLimits{};
  pb.v_max = pb.junction = 0;
  pb.step = Pose{};
  pb.piece = false;
  return pb;
}

void Lookahead::push_next() {
  PlannedBlock& pb = pending_.spare();
  const bool marker = pb.b.kind == BlockKind::Marker;
  if (cut_ && !marker) {  // the blocks before were settled as if a stop came here
    pb.junction = 0;
    cut_ = false;
  }
  if (!marker && pb.junction <= 0) ++epoch_;  // from rest: nothing before reaches it
  pb.step_sum = pb.step;
  Range& r = ranges_.append();
  r.start = total_s_;
  r.end = total_s_ + pb.b.length;
  r.cap = pb.raw.cap;
  r.accel = pb.raw.accel;
  r.jerk = pb.raw.jerk;
  r.junction = pb.junction;
  r.epoch = epoch_;
  r.marker = marker;
  r.scaled = false;
  if (marker && is_stop(pb.b)) ++epoch_;  // a stop: the generator waits there for the average
  total_s_ = r.end;
  pending_.commit_spare();
  if (widening() && !marker) {
    if (has_step(pb.step)) scale_near_step(pending_.size() - 1);
    if (r.start < scaled_until_ && !r.scaled) {
      const RawLimits s = block_limits(pb.b, pb.v_max, *p_.limits, 1 - p_.limits->step_share);
      r.cap = std::min(r.cap, s.cap);
      r.accel = std::min(r.accel, s.accel);
      r.jerk = std::min(r.jerk, s.jerk);
      r.scaled = true;
    }
    add_steps(pending_.size() - 1);
  }
  dirty_ = true;
}

void Lookahead::reopen() noexcept {
  finished_ = false;
  prev_stop_ = true;
  pinned_ = 0;
  ++epoch_;
}

// A curvature step is sampled with the jerk share η; the blocks around it, within the trace's
// finite differences of it, keep within 1 − η (their limits are computed again).
void Lookahead::scale_near_step(std::size_t m) {
  const double at = range_of(m).start;
  const double reach = p_.step_window_s + p_.v_bound * jerk_window_;
  scaled_until_ = at + reach;
  for (std::size_t j = m; j-- > 0;) {
    Range& r = range_of(j);
    if (r.end < at - reach) break;
    if (r.marker || r.scaled) continue;  // (the scaled limits do not depend on which step asks)
    const RawLimits s = block_limits(pending_[j].b, pending_[j].v_max, *p_.limits, 1 - p_.limits->step_share);
    r.cap = std::min(r.cap, s.cap);
    r.accel = std::min(r.accel, s.accel);
    r.jerk = std::min(r.jerk, s.jerk);
    r.scaled = true;
  }
}

// Curvature steps closer than three servo periods of travel add up in a sampled jerk, so each
// step's speed limit uses the sum of the steps around it: v² · Σ|Δg''| ≤ (4/3)·η·J·T_servo.
void Lookahead::add_steps(std::size_t m) {
  PlannedBlock& nb = pending_[m];
  if (!has_step(nb.step)) return;
  const auto limit = [this](const Pose& sum) {
    double v = kInf;
    for (int i = 0; i < kAxisCount; ++i) {
      const double budget = p_.step_budget[static_cast<std::size_t>(i)];
      if (budget > 0 && sum[i] > 0) v = std::min(v, std::sqrt(budget / sum[i]));
    }
    return v;
  };
  const double at = range_of(m).start;
  for (std::size_t j = m; j-- > 0;) {
    PlannedBlock& jb = pending_[j];
    Range& jr = range_of(j);
    if (at - jr.start > p_.step_window_s) break;
    if (jr.marker || !has_step(jb.step)) continue;
    for (int i = 0; i < kAxisCount; ++i) {
      jb.step_sum[i] += nb.step[i];
      nb.step_sum[i] += jb.step[i];
    }
    jr.junction = std::min(jr.junction, limit(jb.step_sum));
  }
  Range& nr = range_of(m);
  nr.junction = std::min(nr.junction, limit(nb.step_sum));
}

bool Lookahead::can_settle_front() const noexcept {
  if (finished_ || cut_ || !widening()) return true;
  const Range& r = ranges_[ranges_.size() - pending_.size()];
  return epoch_ > r.epoch || total_s_ - r.end >= reach_;
}

bool Lookahead::wants_more() const noexcept {
  const std::size_t n = size();
  if (n >= p_.hard_blocks) return false;
  if (n < p_.soft_blocks) return true;
  if (!pending_.empty() && !can_settle_front()) return true;
  const double from = !settled_.empty() ? settled_.front().start_s : total_s_;
  return total_s_ - from < p_.soft_length;
}

// The lowest raw limits of the ranges that reach [from, to] (the block's own among them).
Lookahead::Widened Lookahead::widened_over(double from, double to, std::uint64_t epoch,
                                           const Range& own) const {
  Widened w{own.cap, own.accel, own.jerk};
  for (std::size_t j = 0; j < ranges_.size(); ++j) {
    const Range& r = ranges_[j];
    if (r.start - reach_ >= to) break;  // ranges are in order of their start
    if (r.marker || r.epoch != epoch) continue;
    const double cc = r.cap * cap_window_;
    if (r.start - cc < to && r.end + cc > from) w.cap = std::min(w.cap, r.cap);
    const double c = r.cap * half_window_;
    if (r.start - c < to && r.end + c > from) w.accel = std::min(w.accel, r.accel);
    const double cj = r.cap * jerk_window_;
    if (r.start - cj < to && r.end + cj > from) w.jerk = std::min(w.jerk, r.jerk);
    if (r.junction > 0 && r.junction < kInf) {
      const double v = r.junction * cap_window_;
      if (r.start - v < to && r.start + v > from) w.cap = std::min(w.cap, r.junction);
    }
  }
  return w;
}

void Lookahead::append_settled(const traj::MotionBlock& b, double start_s, const Widened& w,
                               double junction) {
  SettledBlock& sb = settled_.append();
  sb.b = b;
  sb.start_s = start_s;
  sb.prefix = next_prefix_;
  sb.entry = 0;
  if (b.kind == BlockKind::Marker) {
    sb.local = is_stop(b) ? 0.0 : kInf;
    sb.cap = sb.accel = sb.jerk = 0;
    if (is_stop(b)) prev_stop_ = true;
    return;
  }
  sb.cap = w.cap;
  sb.accel = w.accel;
  sb.jerk = w.jerk;
  sb.local = std::min({junction, sb.cap, prev_stop_ ? 0.0 : prev_path_cap_});
  prev_path_cap_ = sb.cap;
  prev_stop_ = false;
  next_prefix_ += 2.0 * sb.accel * b.length;
}

// The front pending block's limits are final: widen them, split the block where they change
// (long blocks only), and append the pieces to the settled blocks.
void Lookahead::settle_front() {
  const PlannedBlock& pb = pending_.front();
  const Range own = ranges_[ranges_.size() - pending_.size()];
  if (pb.b.kind == BlockKind::Marker || !widening()) {
    append_settled(pb.b, own.start, Widened{own.cap, own.accel, own.jerk}, own.junction);
  } else {
    const double share = pb.b.length <= 0.5 * reach_ && !pb.piece ? kShortSplitShare : 1 - kSplitGain;
    // Where a lower range begins or ends inside the block.
    cuts_.clear();
    // A limit that begins or ends within kMinPiece of the block's end is cut 1.5 kMinPiece from
    // it (the piece then holds it a little longer than needed; the pieces below skip cuts closer
    // than kMinPiece): dropping the cut would hold it over the whole block (a 10 µm hairpin
    // blend's 0.005 mm/s over each 1.6 mm move beside it).
    const bool splittable = pb.b.length > 4 * kMinPiece;
    const auto cut_at = [&](double x) {
      if (splittable && x > own.start && x < own.end)
        cuts_.push_back(std::clamp(x, own.start + 1.5 * kMinPiece, own.end - 1.5 * kMinPiece));
    };
    for (std::size_t j = 0; j < ranges_.size(); ++j) {
      const Range& r = ranges_[j];
      if (r.start - reach_ >= own.end) break;
      if (r.marker || r.epoch != own.epoch) continue;
      if (lower(r.cap, own.cap, share)) {
        cut_at(r.start - r.cap * cap_window_);
        cut_at(r.end + r.cap * cap_window_);
      }
      if (lower(r.accel, own.accel, share)) {
        cut_at(r.start - r.cap * half_window_);
        cut_at(r.end + r.cap * half_window_);
      }
      if (lower(r.jerk, own.jerk, share)) {
        cut_at(r.start - r.cap * jerk_window_);
        cut_at(r.end + r.cap * jerk_window_);
      }
      if (r.junction > 0 && r.junction < kInf && lower(r.junction, own.cap, share)) {
        cut_at(r.start - r.junction * cap_window_);
        cut_at(r.start + r.junction * cap_window_);
      }
    }
    std::sort(cuts_.begin(), cuts_.end());
    // Of cuts closer than kMinPiece keep the later one in the block's first half (where limits
    // mostly end: the piece before holds them) and the earlier one in its second half (where they
    // mostly begin), so that the moved cuts above do not swallow a neighbour's.
    std::size_t kept = 0;
    const double middle = 0.5 * (own.start + own.end);
    for (std::size_t k = 0; k < cuts_.size(); ++k) {
      if (kept > 0 && cuts_[k] - cuts_[kept - 1] < kMinPiece) {
        if (cuts_[k] < middle) cuts_[kept - 1] = cuts_[k];
        continue;
      }
      cuts_[kept++] = cuts_[k];
    }
    cuts_.resize(kept);
    // The pieces between the cuts (none shorter than kMinPiece), then each run of pieces with the
    // same limits as one block.
    traj::MotionBlock rest = pb.b;
    double at = own.start;
    bool first = true;
    std::size_t c = 0;
    while (at < own.end) {
      while (c < cuts_.size() && cuts_[c] - at < kMinPiece) ++c;
      double next = c < cuts_.size() ? cuts_[c] : own.end;
      const Widened piece = widened_over(at, next, own.epoch, own);
      for (;;) {  // run on while the next piece has the same limits
        std::size_t c2 = c + 1;
        while (c2 < cuts_.size() && cuts_[c2] - next < kMinPiece) ++c2;
        if (next >= own.end) break;
        const double after_end = c2 < cuts_.size() ? cuts_[c2] : own.end;
        const Widened after = widened_over(next, after_end, own.epoch, own);
        if (after.cap != piece.cap || after.accel != piece.accel || after.jerk != piece.jerk) break;
        c = c2;
        next = after_end;
      }
      traj::MotionBlock head = rest;
      if (next < own.end) {
        trim_end(head, head.length - (next - at));
        trim_start(rest, next - at);
        rebase(rest, end_point(head));
      }
      append_settled(head, at, piece, first ? own.junction : kInf);
      first = false;
      at = next;
      ++c;
    }
  }
  pending_.pop_front();
  // Ranges that can no longer reach the next block to settle.
  const double next_start = pending_.empty() ? total_s_ : ranges_[ranges_.size() - pending_.size()].start;
  while (ranges_.size() > pending_.size() && ranges_.front().end + reach_ < next_start) ranges_.pop_front();
}

void Lookahead::settle() {
  const std::size_t first_new = settled_.size();
  while (!pending_.empty()) {
    if (!can_settle_front()) {
      if (pending_.size() < p_.hard_blocks) break;
      cut_ = true;  // so many blocks within the reach: a stop after them keeps the memory bounded
    }
    settle_front();
  }
  if (settled_.size() > first_new || finished_) backward_pass(first_new);
}

// Entry speeds from the end of the settled blocks backward, assuming a stop after them:
// E_k = min(local_k, √(E_{k+1}² + 2·a_k·L_k)). Later blocks only ever raise these values, so the
// sweep stops where an older value does not change; a block whose entry equals its own limit is
// final, and so is everything before it.
void Lookahead::backward_pass(std::size_t first_new) {
  double after = 0;
  for (std::size_t k = settled_.size(); k-- > 0;) {
    SettledBlock& sb = settled_[k];
    const double e = std::min(sb.local, std::sqrt(after * after + 2.0 * sb.accel * sb.b.length));
    if (k < first_new && e == sb.entry) break;
    sb.entry = e;
    after = e;
  }
  if (finished_ && pending_.empty()) {
    pinned_ = settled_.size();
    return;
  }
  for (std::size_t k = settled_.size(); k-- > pinned_;) {
    if (settled_[k].entry == settled_[k].local) {
      pinned_ = k + 1;
      break;
    }
  }
}

std::uint64_t Lookahead::soft_link(std::uint64_t seq) {
  const traj::MotionBlock& f = settled_.front().b;
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
  const traj::MotionBlock& f = settled_.front().b;
  const std::size_t n = std::min(settled_.size(), kSoftScan + 1);
  for (std::size_t k = 1; k < n; ++k) {
    const traj::MotionBlock& q = settled_[k].b;
    if (q.kind == BlockKind::Marker) continue;
    if (q.feed_class != f.feed_class || q.feed < f.feed) return seq + k;
  }
  if (finished_ && pending_.empty() && n == settled_.size()) return traj::kNoBlock;
  return seq + n;  // not decided yet: the tick continues the walk from that block's own link
}

bool Lookahead::front_link_decided() {
  refresh();
  if ((finished_ && pending_.empty()) || settled_.size() > kSoftScan || settled_.empty()) return true;
  const traj::MotionBlock& f = settled_.front().b;
  if (f.kind == BlockKind::Marker) return true;
  for (std::size_t k = 1; k < settled_.size(); ++k) {
    const traj::MotionBlock& q = settled_[k].b;
    if (q.kind == BlockKind::Marker) continue;
    if (q.feed_class != f.feed_class || q.feed < f.feed) return true;
  }
  return false;
}

void Lookahead::front_for_queue(std::uint64_t seq, traj::MotionBlock& out) {
  const SettledBlock& sb = settled_.front();
  out = sb.b;
  out.seq = seq;
  out.v_cap = sb.cap;
  out.accel = sb.accel;
  out.jerk = std::isfinite(sb.jerk) ? sb.jerk : 0.0;
  out.v_entry = sb.entry;
  out.brake_prefix = sb.prefix;
  out.next_soft = soft_link(seq);
}

void Lookahead::pop_front() {
  settled_.pop_front();
  if (pinned_ > 0) --pinned_;
}

}  // namespace opencnc::plan::detail
