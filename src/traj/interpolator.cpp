// SPDX-License-Identifier: GPL-3.0-or-later
// The servo-period step of the trajectory: 1-D generator along s, moving average, geometry.
#include "opencnc/traj/interpolator.hpp"

#include <algorithm>
#include <cmath>

#include "braking.hpp"
#include "opencnc/traj/path_eval.hpp"

namespace opencnc::traj {

using detail::end_speed_limit;

namespace {

constexpr double kSnap = 1e-10;  ///< s-units: a block end nearer than this counts as reached
constexpr int kMaxPieces = static_cast<int>(BlockQueue::kCapacity) + 8;
constexpr int kMaxSoftHops = 16;
constexpr int kMaxBoundaryScan = 256;

bool is_stop_marker(const MotionBlock& b) noexcept {
  return b.kind == BlockKind::Marker && b.marker != MarkerKind::Report && b.marker != MarkerKind::None;
}

/// ∫ s dt over a piece of duration t from (s0, v) with constant acceleration a.
double piece_integral(double s0, double v, double a, double t) noexcept {
  return t * (s0 + t * (0.5 * v + t * a / 6.0));
}

}  // namespace

Interpolator::Interpolator(BlockQueue& queue, const InterpolatorConfig& config, const Pose& start) noexcept
    : queue_(&queue), config_(config) {
  config_.filter_ticks = std::clamp(config_.filter_ticks, 1, kMaxFilterTicks);
  restart(start);
}

void Interpolator::restart(const Pose& start) noexcept {
  position_ = start;
  ticks_ = 0;
  state_ = RunState::Idle;
  started_ = false;
  u_seq_ = f_seq_ = report_seq_ = queue_->popped();
  u_start_ = s_u_ = v_u_ = 0;
  f_start_ = s_f_ = 0;
  still_ticks_ = config_.filter_ticks;
  history_.fill(0.0);
  history_pos_ = 0;
  acc_lo_.fill(0.0);
  acc_hi_.fill(0.0);
  period_lo_ = period_hi_ = 0;
  commit_end_ = full_end_ = -1e300;
  hold_ = aborting_ = waiting_ = false;
  released_seq_ = stop_seq_ = kNoBlock;
  step_from_seq_ = 0;
  dwell_ticks_left_ = 0;
  shown_ = Shown{};
  sync_ = Sync::Off;
  sync_target_ = sync_lag_ = prev_revs_ = 0;
  sync_lost_ = false;
  tap_ = Tap::Off;
  tap_locked_ = tap_reverse_ = false;
  tap_depth_ = tap_v_ = tap_lag_ = tap_rev0_ = tap_revs_ = 0;
  tap_dir_ = 1;
}

double Interpolator::target_speed(const TickInput& in, const MotionBlock& b) const noexcept {
  const bool ovr = (b.flags & kFeedOverrideAllowed) != 0;
  const double fo = ovr ? std::clamp(in.feed_override, 0.0, config_.max_feed_override) : 1.0;
  double nominal = 0;
  switch (b.feed_class) {
    case FeedClass::Rapid:
      nominal = b.feed * (ovr ? std::clamp(in.rapid_override, 0.0, 1.0) : 1.0);
      break;
    case FeedClass::Feed:
      nominal = b.feed * fo;
      break;
    case FeedClass::PerRevolution:
      nominal = b.feed * std::fabs(in.spindle_rev_s) * fo;
      break;
    case FeedClass::SpindleSync:
      nominal = b.feed * std::fabs(in.spindle_rev_s);
      break;
  }
  return std::min(nominal, b.v_cap);
}

void Interpolator::handle_commands(const TickInput& in) noexcept {
  if (in.abort && !aborting_ && state_ != RunState::Aborted && state_ != RunState::Finished) aborting_ = true;
  hold_ = in.feed_hold;
  if (!in.single_block) stop_seq_ = kNoBlock;
}

// With jerk limits the commanded position is the average of the generator's over the last T, so
// its jerk is (a(t) − a(t − T))/T: each acceleration of this period stays within Δ = J·T of those
// of the period a window earlier (J the jerk budget where the commanded position is). After
// accelerating, the generator therefore may not brake fully until that period has left the window
// (at worst it coasts): the braking limits allow for that coast (docs/planner.md, "Jerk").
Interpolator::Turn Interpolator::turn_bounds(const TickInput& in) noexcept {
  Turn t;
  const int m = config_.filter_ticks;
  if (m <= 1) return t;
  const std::size_t avail = queue_->available();
  // The budget where the commanded position is; resting at the end of its block (a corner taken
  // at rest, where the window's ranges stop), the motion leaves along the next block: its budget
  // too.
  double jerk = 0;
  const std::size_t f_index = index_of(f_seq_);
  for (std::size_t i = f_index, n = 0; i < avail && n < 8; ++i, ++n) {
    const MotionBlock& b = queue_->peek(i);
    if (b.kind == BlockKind::Marker) continue;
    if (jerk > 0) {
      jerk = std::min(jerk, b.jerk);
      break;
    }
    jerk = b.jerk;
    if (i != f_index || s_f_ - f_start_ < b.length) break;
  }
  if (jerk <= 0) return t;
  t.active = true;
  const double T = m * config_.period_s;
  t.delta = jerk * T * (aborting_ ? std::max(1.0, in.abort_decel_scale) : 1.0);
  const auto slot = [&](int k) { return static_cast<std::size_t>((history_pos_ + k) % m); };
  t.lo_old = acc_hi_[slot(0)];
  t.hi_old = acc_lo_[slot(0)];
  int last = 0;
  for (int k = 1; k < m; ++k) {
    if (acc_hi_[slot(k)] > 0) last = k;
  }
  t.coast_hist = last * config_.period_s;
  t.coast_full = m * config_.period_s;
  // The budgets a coast may cross. If this period accelerates, the coast after it stays within
  // (v + M·T_servo)·(T_servo + T) of the generator (M the planner's bound of every budget, the
  // most v can gain in the period); the coasts the history asks for stay within the regions the
  // accelerating periods committed to (commit_end_), which only shrink as the generator moves
  // on. Over the region the largest budget, and M beyond the queued data or the scan (blocks
  // that arrive later never raise it): a plan found feasible stays so.
  const std::size_t u = index_of(u_seq_);
  const double big =
      config_.max_path_accel > 0 ? config_.max_path_accel : (u < avail ? queue_->peek(u).accel : 0.0);
  full_end_ = s_u_ + (v_u_ + big * config_.period_s) * (config_.period_s + t.coast_full);
  if (t.coast_hist <= 0) commit_end_ = -1e300;
  const double hist_end = commit_end_;
  double start = u_start_;
  t.coast_accel_full = t.coast_accel_hist = 0;
  std::size_t i = u;
  int n = 0;
  const double scan_end = std::max(full_end_, hist_end);  // the junctions within either are limits too
  for (; i < avail && n < kCoastScan && start < scan_end; ++i, ++n) {
    const double a = queue_->peek(i).accel;
    if (start < full_end_) t.coast_accel_full = std::max(t.coast_accel_full, a);
    if (start < hist_end) t.coast_accel_hist = std::max(t.coast_accel_hist, a);
    start += queue_->peek(i).length;
  }
  if (start < full_end_) t.coast_accel_full = std::max(t.coast_accel_full, big);
  if (start < hist_end) t.coast_accel_hist = std::max(t.coast_accel_hist, big);
  const double scale = aborting_ ? std::max(1.0, in.abort_decel_scale) : 1.0;
  t.coast_accel_full *= scale;
  t.coast_accel_hist *= scale;
  coast_count_ = n;
  coast_from_ = u_seq_;
  return t;
}

// One piece of constant acceleration inside block `b` (at queue index `index`): chooses the
// acceleration from the target speed and every braking limit, then moves until the block end or
// the end of the period.
void Interpolator::step_piece(const TickInput& in, const MotionBlock& b, std::size_t index, const Turn& turn,
                              double& tau, double& integral) noexcept {
  const std::size_t avail = queue_->available();
  const double x = s_u_ - u_start_;
  const double rem = b.length - x;
  const double A = b.accel;
  const double v = v_u_;
  const double c_s = b.brake_prefix + 2.0 * A * x;

  double v_tgt = target_speed(in, b);
  if (aborting_ || (hold_ && (b.flags & kFeedHoldAllowed) != 0)) v_tgt = 0;
  // An abort may brake harder than the block's budget (a power-fail stop short of energy); the
  // junction limits below keep the budget, so they never ask for more than the plan did.
  const double a_min = aborting_ ? -A * std::max(1.0, in.abort_decel_scale) : -A;
  double a = std::clamp((v_tgt - v) / tau, a_min, A);
  const bool follow = b.feed_class == FeedClass::SpindleSync && !aborting_;
  if (follow) a = sync_acceleration(b, tau);
  const double a_follow = a;
  // Braking limits: the largest acceleration with which each stays reachable. With jerk limits
  // the generator may have to coast before it brakes; every limit then holds the same coast, so
  // they are gathered as the lowest K, for a coast after this period if it accelerates (the full
  // window) and if it does not (what the history asks for).
  double a_full = A, k_min = 1e300;
  const auto limit = [&](double K, std::size_t q_index, double vq) {
    if (turn.active) {
      k_min = std::min(k_min, K);
      return;
    }
    const double ve = end_speed_limit(K, v, A, tau);
    double aq;
    if (ve >= 0) {
      aq = (ve - v) / tau;
    } else if (q_index == index + 1 && rem > 0) {
      aq = (vq * vq - v * v) / (2.0 * rem);  // reach vq exactly at the block end
    } else {
      aq = -A;
    }
    a_full = std::min(a_full, aq);
  };

  // The next junction: the planner's backward pass holds every later hard limit in v_entry.
  if (index + 1 < avail) {
    const double e = queue_->peek(index + 1).v_entry;
    limit(e * e + 2.0 * A * rem, index + 1, e);
  }
  // Entry speeds assume braking can begin at once; a coast may carry the motion past the next
  // junction, so every junction the coast can reach is a limit of its own (the first one beyond
  // its reach holds every later one: its braking curve lies below theirs).
  if (turn.active) {
    const std::size_t last =
        std::min(avail, index_of(coast_from_) + static_cast<std::size_t>(coast_count_) + 1);
    for (std::size_t k = index + 2; k < last; ++k) {
      const MotionBlock& q = queue_->peek(k);
      limit(q.v_entry * q.v_entry + q.brake_prefix - c_s, k, q.v_entry);
    }
  }
  // The end of the queued data: stopping there must stay possible.
  {
    const MotionBlock& last = queue_->peek(avail - 1);
    limit(last.brake_prefix + 2.0 * last.accel * last.length - c_s, avail, 0.0);
  }
  // Lower nominal speeds further on (override-dependent, so checked here rather than planned).
  // Points farther than any coast and braking from here can reach cannot bind.
  double reach_bound = (v + A * tau) * (v + A * tau);
  if (turn.active) reach_bound += 2.0 * turn.coast_accel_full * (v + A * tau) * (tau + turn.coast_full);
  std::uint64_t c = b.next_soft;
  for (int hop = 0; hop < kMaxSoftHops && c != kNoBlock && c > b.seq; ++hop) {
    const std::size_t ci = index_of(c);
    if (ci >= avail) break;
    const MotionBlock& q = queue_->peek(ci);
    const double reach = q.brake_prefix - c_s;
    if (reach >= reach_bound) break;  // later points have a larger reach still
    if (q.kind != BlockKind::Marker) {
      const double vq = target_speed(in, q);
      limit(vq * vq + reach, ci, vq);
    }
    c = q.next_soft;
  }
  // A committed single-block stop.
  if (stop_seq_ != kNoBlock && stop_seq_ > b.seq) {
    const std::size_t si = index_of(stop_seq_);
    if (si < avail) limit(queue_->peek(si).brake_prefix - c_s, si, 0.0);
  }
  if (turn.active) {
    // Braking: if this period accelerates it commits the full window; a piece earlier in this
    // period that accelerated has committed it already.
    const auto bound = [&](double coast, double a_coast) {
      if (k_min >= 1e300) return A;
      const double ve = end_speed_limit(k_min, v, A, tau, coast, a_coast);
      return ve >= 0 ? (ve - v) / tau : -A;
    };
    a_full = bound(turn.coast_full, turn.coast_accel_full);
    const double a_hist = period_hi_ > 0 ? a_full : bound(turn.coast_hist, turn.coast_accel_hist);
    // Within Δ of the acceleration a window earlier (0 is always allowed: the planner keeps
    // every budget within Δ), and no positive acceleration unless braking stays possible
    // after the full coast it commits to.
    const double lo = std::min(0.0, turn.lo_old - turn.delta), hi = std::max(0.0, turn.hi_old + turn.delta);
    a = std::clamp(a, std::max(a_min, lo), std::min(A, hi));
    a = std::min(a, a_full > 0 ? a_full : std::min(a_hist, 0.0));
  } else {
    a = std::min(a, a_full);
  }
  a = std::clamp(a, a_min, A);
  // Braking for a limit ahead (the end of the thread): the motion leaves the spindle.
  if (follow && sync_ == Sync::Locked && a < a_follow - 1e-9 * A) sync_ = Sync::CatchUp;

  period_lo_ = std::min(period_lo_, a);
  period_hi_ = std::max(period_hi_, a);
  double t = tau;
  bool stops = false;
  if (a < 0 && v + a * tau <= 0) {
    t = v / -a;
    stops = true;
  }
  const double ds = v * t + 0.5 * a * t * t;
  if (ds >= rem - kSnap) {
    const double disc = v * v + 2.0 * a * rem;
    double t1 = disc > 0 ? 2.0 * rem / (v + std::sqrt(disc)) : t;
    if (!(t1 <= t)) t1 = t;
    integral += piece_integral(s_u_, v, a, t1);
    v_u_ = std::max(0.0, v + a * t1);
    // Where the next block must be entered at rest the limits brought v to zero; drop the rounding.
    if (index + 1 < avail && queue_->peek(index + 1).v_entry == 0) v_u_ = 0;
    tau -= t1;
    u_start_ += b.length;
    s_u_ = u_start_;
    ++u_seq_;
    return;
  }
  integral += piece_integral(s_u_, v, a, t);
  s_u_ += ds;
  v_u_ = stops ? 0.0 : v + a * t;
  tau -= t;
  if (stops) {
    integral += s_u_ * tau;
    tau = 0;
  }
}

// G33: the spindle encoder sets the target. Waiting at the start of a synchronised run for the
// index (the encoder crossing a whole revolution) makes every pass of a thread start at the same
// spindle angle; then the motion speeds up to the spindle's rate and keeps the distance it lags
// by from then on, so that the pitch is exact and the phase the same on every pass.
void Interpolator::update_sync(const TickInput& in) noexcept {
  const double revs = in.spindle_revs;
  const double turned = std::fabs(revs - prev_revs_);
  const std::size_t index = index_of(u_seq_);
  const bool in_sync_block = index < queue_->available() && queue_->peek(index).kind != BlockKind::Marker &&
                             queue_->peek(index).feed_class == FeedClass::SpindleSync &&
                             (queue_->peek(index).flags & kRigidTap) == 0;  // the tap follows on its own
  if (!in_sync_block) {
    sync_ = Sync::Off;
  } else {
    const MotionBlock& b = queue_->peek(index);
    if (sync_ == Sync::Off && v_u_ == 0) sync_ = Sync::WaitIndex;
    if (sync_ == Sync::WaitIndex) {
      if (std::floor(revs) != std::floor(prev_revs_)) {
        const double index_rev = revs > prev_revs_ ? std::floor(revs) : std::ceil(revs);
        sync_target_ = s_u_ + b.feed * std::fabs(revs - index_rev);
        sync_ = Sync::CatchUp;
      }
    } else if (sync_ != Sync::Off) {
      sync_target_ += b.feed * turned;
    }
  }
  prev_revs_ = revs;
}

double Interpolator::sync_acceleration(const MotionBlock& b, double tau) noexcept {
  const double A = b.accel, v = v_u_, s = s_u_;
  const double v_t = b.feed * std::fabs(sync_rev_s_);
  if (sync_ == Sync::CatchUp && std::fabs(v_t - v) <= A * tau) {
    sync_ = Sync::Locked;
    sync_lag_ = sync_target_ - (s + 0.5 * (v + v_t) * tau);
  }
  if (sync_ != Sync::Locked) return std::clamp((v_t - v) / tau, -A, A);
  const double a = 2.0 * (sync_target_ - sync_lag_ - s - v * tau) / (tau * tau);
  if (std::fabs(a) > A) {  // the spindle changed speed faster than the axes can follow
    sync_lost_ = true;
    sync_ = Sync::CatchUp;
  }
  return std::clamp(a, -A, A);
}

double Interpolator::advance_unfiltered(const TickInput& in) noexcept {
  double tau = config_.period_s, integral = 0;
  const double s_before = s_u_;
  const std::size_t avail = queue_->available();
  const Turn turn = turn_bounds(in);
  period_lo_ = period_hi_ = 0;
  for (int i = 0; i < kMaxPieces && tau > 0; ++i) {
    const std::size_t index = index_of(u_seq_);
    if (index >= avail || u_seq_ == stop_seq_) {
      v_u_ = 0;  // end of the queued data or a single-block stop: the limits brought v to 0 here
      break;
    }
    const MotionBlock& b = queue_->peek(index);
    if (b.kind == BlockKind::Marker) {
      if (is_stop_marker(b) && released_seq_ != b.seq) {
        v_u_ = 0;
        break;
      }
      ++u_seq_;
      continue;
    }
    if (b.length - (s_u_ - u_start_) <= kSnap) {
      u_start_ += b.length;
      s_u_ = u_start_;
      ++u_seq_;
      continue;
    }
    // A corner passed at zero speed: the moving average must reach it before the motion goes on,
    // or the commanded path would round it off. With jerk limits it also rests there for the three
    // periods the trace's third difference spans: a difference across the corner would add the
    // kink of the axes' directions (Δg' times the motion within a period) to their jerk.
    const int rest = config_.filter_ticks > 1 ? config_.filter_ticks + 3 : config_.filter_ticks;
    if (b.v_entry == 0 && s_u_ == u_start_ && v_u_ == 0 && still_ticks_ < rest) break;
    if (b.flags & kRigidTap) {  // reached at rest; run_tap() moves the tap
      v_u_ = 0;
      break;
    }
    if (b.feed_class == FeedClass::SpindleSync && (sync_ == Sync::Off || sync_ == Sync::WaitIndex)) break;
    step_piece(in, b, index, turn, tau, integral);
  }
  if (tau > 0) integral += s_u_ * tau;
  if (turn.active && period_hi_ > 0)
    commit_end_ = std::max(commit_end_, full_end_);  // the coast it commits to
  still_ticks_ = (s_u_ == s_before && v_u_ == 0) ? still_ticks_ + 1 : 0;
  return integral;
}

double Interpolator::filter(double integral) noexcept {
  const int m = config_.filter_ticks;
  if (m <= 1) return s_u_;
  history_[static_cast<std::size_t>(history_pos_)] = integral;
  acc_lo_[static_cast<std::size_t>(history_pos_)] = period_lo_;
  acc_hi_[static_cast<std::size_t>(history_pos_)] = period_hi_;
  history_pos_ = history_pos_ + 1 == m ? 0 : history_pos_ + 1;
  if (still_ticks_ >= m) return s_u_;  // the window holds only the resting position
  double sum = 0;
  for (int i = 0; i < m; ++i) sum += history_[static_cast<std::size_t>(i)];
  return std::max(s_f_, sum / (m * config_.period_s));
}

void Interpolator::advance_filtered(TickOutput& out) noexcept {
  const std::size_t avail = queue_->available();
  for (int i = 0; i < kMaxPieces; ++i) {
    const std::size_t index = index_of(f_seq_);
    if (index >= avail || f_seq_ >= u_seq_) break;  // never ahead of the generator's block
    const MotionBlock& b = queue_->peek(index);
    // Exactly: a commanded position put on the next block early would jump by the difference.
    if (s_f_ < f_start_ + b.length) break;
    f_start_ += b.length;
    ++f_seq_;
  }
  // Markers the commanded position has passed, oldest first, a bounded number per tick.
  while (report_seq_ < f_seq_ && out.event_count < kMaxTickEvents) {
    const MotionBlock& b = queue_->peek(index_of(report_seq_));
    if (b.kind == BlockKind::Marker) {
      out.events[static_cast<std::size_t>(out.event_count++)] = TickEvent{b.seq, b.marker, b.action};
    }
    ++report_seq_;
  }
}

void Interpolator::release_marker() noexcept {
  released_seq_ = u_seq_;
  waiting_ = false;
}

// Stop markers: once the commanded position has settled on one, do what it asks.
void Interpolator::update_waiting(const TickInput& in) noexcept {
  const bool settled = v_u_ == 0 && still_ticks_ >= config_.filter_ticks;
  const std::size_t avail = queue_->available();
  const std::size_t index = index_of(u_seq_);
  if (u_seq_ == stop_seq_ && settled) {
    state_ = RunState::WaitingCycleStart;
    if (in.cycle_start) {
      step_from_seq_ = stop_seq_;
      stop_seq_ = kNoBlock;
    }
    return;
  }
  if (index >= avail || !settled) return;
  const MotionBlock& m = queue_->peek(index);
  if (!is_stop_marker(m) || released_seq_ == m.seq) return;
  if (!waiting_) {
    waiting_ = true;
    dwell_ticks_left_ =
        m.marker == MarkerKind::Dwell
            ? static_cast<std::uint64_t>(std::llround(std::max(0.0, m.value) / config_.period_s))
            : 0;
  }
  switch (m.marker) {
    case MarkerKind::Dwell:
      state_ = RunState::Dwelling;
      if ((m.flags & kWaitInPosition) != 0 && !in.in_position) {
        waiting_in_position_ = true;  // the drives still settle: the marker's action must wait
        break;
      }
      if (dwell_ticks_left_ == 0 || --dwell_ticks_left_ == 0) release_marker();
      break;
    case MarkerKind::ProgramStop:
      state_ = RunState::WaitingCycleStart;
      if (in.cycle_start) release_marker();
      break;
    case MarkerKind::OptionalStop:
      state_ = RunState::WaitingCycleStart;
      if (!in.optional_stop || in.cycle_start) release_marker();
      break;
    case MarkerKind::SpindleWait:
      state_ = RunState::WaitingSpindle;
      if (in.spindle_at_speed) release_marker();
      break;
    case MarkerKind::Sync:
      state_ = RunState::WaitingSync;
      if (in.sync_done) release_marker();
      break;
    case MarkerKind::ProgramEnd:
      state_ = RunState::Finished;
      break;
    case MarkerKind::None:
    case MarkerKind::Report:
      break;
  }
}

void Interpolator::commit_single_block_stop(std::size_t available) noexcept {
  const std::size_t index = index_of(u_seq_);
  if (index >= available) return;
  const MotionBlock& cur = queue_->peek(index);
  const double c_s = cur.brake_prefix + 2.0 * cur.accel * (s_u_ - u_start_);
  for (std::size_t k = index + 1, n = 0; k < available && n < kMaxBoundaryScan; ++k, ++n) {
    const MotionBlock& prev = queue_->peek(k - 1);
    const MotionBlock& next = queue_->peek(k);
    if (next.seq <= step_from_seq_ || prev.segment == next.segment) continue;
    if (is_stop_marker(next)) return;  // the motion stops there anyway
    if (v_u_ * v_u_ <= next.brake_prefix - c_s) {
      stop_seq_ = next.seq;
      return;
    }
  }
}

void Interpolator::pop_and_rebase() noexcept {
  const std::uint64_t keep = std::min(f_seq_, report_seq_);
  const std::uint64_t first = queue_->popped();
  if (keep <= first) return;
  const std::size_t n = static_cast<std::size_t>(keep - first);
  double shift = 0;
  for (std::size_t i = 0; i < n; ++i) shift += queue_->peek(i).length;
  queue_->pop(n);
  if (shift == 0) return;
  // Keep s small so that its resolution stays far below a nanometre on long programs.
  s_u_ -= shift;
  u_start_ -= shift;
  s_f_ -= shift;
  f_start_ -= shift;
  commit_end_ -= shift;
  sync_target_ -= shift;
  const double shift_dt = shift * config_.period_s;
  for (int i = 0; i < config_.filter_ticks; ++i) history_[static_cast<std::size_t>(i)] -= shift_dt;
}

void Interpolator::fill_output(TickOutput& out, double s_prev) noexcept {
  const std::size_t avail = queue_->available();
  const std::size_t index = index_of(f_seq_);
  if (index < avail) {
    const MotionBlock& b = queue_->peek(index);
    const double x = std::clamp(s_f_ - f_start_, 0.0, b.length);
    position_ = position_at(b, x);
    shown_ = Shown{b.seq, b.segment, b.segment_first, b.segment_last, b.line, b.context, x, b.segment_offset};
  } else if (index == avail && avail > 0) {
    const MotionBlock& b = queue_->peek(avail - 1);
    position_ = position_at(b, b.length);
    shown_ = Shown{b.seq, b.segment, b.segment_first, b.segment_last, b.line, b.context, b.length,
                   b.segment_offset};
  }
  out.path_velocity = (s_f_ - s_prev) / config_.period_s;
  const std::size_t u_index = index_of(u_seq_);
  out.path_acceleration =
      u_index < avail && queue_->peek(u_index).kind != BlockKind::Marker ? queue_->peek(u_index).accel : 0.0;
  out.state = state_;
  write_shown(out);
  out.spindle_synced = sync_ == Sync::Locked;
  out.sync_lost = sync_lost_;
  out.tap_reverse = false;
  out.tap_speed_scale = 1;
  out.waiting_in_position = waiting_in_position_;
}

// The commanded position and the block shown there.
void Interpolator::write_shown(TickOutput& out) const noexcept {
  out.position = position_;
  out.block_seq = shown_.seq;
  out.segment = shown_.segment;
  out.segment_first = shown_.segment_first;
  out.segment_last = shown_.segment_last;
  out.line = shown_.line;
  out.context = shown_.context;
  out.block_offset = shown_.offset;
  out.segment_offset = shown_.segment_offset + shown_.offset;
}

void Interpolator::tick(const TickInput& in, TickOutput& out) noexcept {
  ++ticks_;
  out.event_count = 0;
  waiting_in_position_ = false;
  if (state_ == RunState::Aborted || state_ == RunState::Finished) {
    const double s_now = s_f_;
    fill_output(out, s_now);
    return;
  }
  handle_commands(in);
  const std::size_t avail = queue_->available();
  if (avail > 0) started_ = true;
  if (in.single_block && stop_seq_ == kNoBlock && !aborting_) commit_single_block_stop(avail);

  if (ticks_ == 1) prev_revs_ = in.spindle_revs;
  sync_rev_s_ = in.spindle_rev_s;
  update_sync(in);
  double s_prev = s_f_;
  const bool tapping = run_tap(in);                // a rigid tap moves on its own; the path waits
  if (tapping && tap_ == Tap::Off) s_prev = s_f_;  // it ended: s moved past it, the tool did not
  const double integral = tapping ? s_u_ * config_.period_s : advance_unfiltered(in);
  s_f_ = filter(integral);
  advance_filtered(out);

  const bool settled = tap_ == Tap::Off && v_u_ == 0 && still_ticks_ >= config_.filter_ticks;
  const std::size_t index = index_of(u_seq_);
  const bool moving = !settled;
  if (aborting_) {
    state_ = RunState::Aborting;
    if (settled) {
      fill_output(out, s_prev);
      queue_->pop(queue_->available());
      state_ = RunState::Aborted;
      out.state = state_;
      return;
    }
  } else if (!started_) {
    state_ = RunState::Idle;
  } else if (hold_ && index < avail && (queue_->peek(index).flags & kFeedHoldAllowed) != 0 && !waiting_) {
    state_ = moving ? RunState::Holding : RunState::Held;
  } else {
    state_ = RunState::Running;
    if (settled && index >= avail) state_ = RunState::Starved;
    update_waiting(in);
  }
  fill_output(out, s_prev);
  if (tap_ != Tap::Off) show_tap(out);
  pop_and_rebase();
}

}  // namespace opencnc::traj
