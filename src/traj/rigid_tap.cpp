// SPDX-License-Identifier: GPL-3.0-or-later
// Rigid tapping (G33.1) in the servo period: the tap follows the spindle encoder in to the
// programmed depth, asks for the spindle's reversal and keeps following it through the stop and
// out to its start, asks for the spindle's original direction and follows it again until the
// spindle turns forward, then goes back onto its start on its own (LinuxCNC's rigid tap states).
#include <algorithm>
#include <cmath>

#include "braking.hpp"
#include "opencnc/traj/interpolator.hpp"

namespace opencnc::traj {

// The tap owns the period (the path generator waits at the start of the tap's blocks, which it
// reaches at rest): true while it runs, including the period in which it ends.
bool Interpolator::run_tap(const TickInput& in) noexcept {
  if (tap_ == Tap::Off && !start_tap(in)) return false;
  const MotionBlock& b = queue_->peek(index_of(u_seq_));
  const double revs = in.spindle_revs;
  if (tap_ == Tap::WaitIndex) {
    // As for G33: start at the spindle's index, so that every tap meets its thread.
    if (aborting_) {
      tap_ = Tap::Off;
      tap_revs_ = revs;
      return false;
    }
    if (std::floor(revs) != std::floor(tap_revs_)) {
      tap_dir_ = revs > tap_revs_ ? 1.0 : -1.0;
      tap_rev0_ = revs > tap_revs_ ? std::floor(revs) : std::ceil(revs);
      tap_ = Tap::In;
    }
  }
  if (tap_ == Tap::Placing) {
    place_tap(b);
  } else if (tap_ != Tap::WaitIndex) {
    follow_spindle(in, b);
    const double turned = tap_dir_ * (revs - tap_revs_);
    switch (tap_) {
      case Tap::In:  // at depth (or told to abort): the spindle reverses, the tap stays with it
        if (tap_depth_ >= b.length || aborting_) {
          tap_reverse_ = true;
          tap_ = Tap::Reversing;
        }
        break;
      case Tap::Reversing:
        if (turned < 0) tap_ = Tap::Out;
        break;
      case Tap::Out:  // back at the start: the spindle's own direction again
        if (tap_depth_ <= 0) {
          tap_reverse_ = false;
          tap_ = Tap::Restoring;
        }
        break;
      case Tap::Restoring:  // the spindle turns forward again: the tap is free of it
        if (turned > 0) {
          tap_ = Tap::Placing;
          tap_locked_ = false;
        }
        break;
      default:
        break;
    }
  }
  tap_revs_ = revs;
  return true;
}

// A tap starts at rest at the start of its block, the average of the moving-average filter
// arrived there, its way out queued behind it; an abort before it starts skips it.
bool Interpolator::start_tap(const TickInput& in) noexcept {
  const std::size_t index = index_of(u_seq_);
  if (index + 1 >= queue_->available() || aborting_) return false;
  const MotionBlock& b = queue_->peek(index);
  if ((b.flags & kRigidTap) == 0 || (b.flags & kTapReturn) != 0) return false;
  if (s_u_ != u_start_ || v_u_ != 0 || still_ticks_ < config_.filter_ticks) return false;
  tap_ = Tap::WaitIndex;
  tap_depth_ = tap_v_ = tap_lag_ = 0;
  tap_locked_ = tap_reverse_ = false;
  tap_revs_ = in.spindle_revs;
  return true;
}

// The spindle's position asks for depth D = pitch · (revolutions since the index); the tap speeds
// up to the spindle's rate, then keeps a constant distance behind D with the acceleration that
// puts it there at the end of each period (within the block's budget, else the sync is lost).
// The distance is kept in depth, not along the path, so the tap stays in its thread both ways.
// (The encoder is read at the start of the period and the command is the position for that
// instant: the servo's velocity feed-forward carries the drive through the period.)
void Interpolator::follow_spindle(const TickInput& in, const MotionBlock& b) noexcept {
  const double tau = config_.period_s, A = b.accel, v = tap_v_, d = tap_depth_;
  const double target = b.feed * tap_dir_ * (in.spindle_revs - tap_rev0_);
  const double v_t = b.feed * tap_dir_ * in.spindle_rev_s;
  double a;
  if (!tap_locked_ && std::fabs(v_t - v) <= A * tau) {
    tap_locked_ = true;
    tap_lag_ = target - (d + 0.5 * (v + v_t) * tau);
  }
  if (tap_locked_) {
    a = 2.0 * (target - tap_lag_ - d - v * tau) / (tau * tau);
    if (std::fabs(a) > A) sync_lost_ = true;
  } else {
    a = (v_t - v) / tau;
  }
  a = std::clamp(a, -A, A);
  tap_depth_ = d + v * tau + 0.5 * a * tau * tau;
  tap_v_ = v + a * tau;
}

// Free of the spindle, back onto the start at the block's speed and acceleration limits, ending at
// rest exactly there.
void Interpolator::place_tap(const MotionBlock& b) noexcept {
  const double tau = config_.period_s, A = b.accel;
  const double dir = tap_depth_ > 0 ? -1.0 : 1.0;  // toward depth 0
  const double dist = std::fabs(tap_depth_), u = dir * tap_v_;
  const double v_end = detail::end_speed_limit(2.0 * A * dist, u, A, tau);  // to rest at depth 0
  if (v_end < 0 || (dist < 1e-12 && std::fabs(u) <= A * tau)) {
    finish_tap();
    return;
  }
  const double a = std::clamp((std::min(b.v_cap, v_end) - u) / tau, -A, A);
  tap_depth_ += dir * (u * tau + 0.5 * a * tau * tau);
  tap_v_ = dir * (u + a * tau);
}

// The tap is back on its start at rest: the path generator goes on after the tap's two blocks
// (the way out ends where the tap started), with the filter's window at rest there.
void Interpolator::finish_tap() noexcept {
  const MotionBlock& in = queue_->peek(index_of(u_seq_));
  const MotionBlock& out = queue_->peek(index_of(u_seq_) + 1);
  u_start_ += in.length + out.length;
  s_u_ = u_start_;
  v_u_ = 0;
  u_seq_ += 2;
  s_f_ = s_u_;
  const double at_rest = s_u_ * config_.period_s;
  for (int i = 0; i < config_.filter_ticks; ++i) history_[static_cast<std::size_t>(i)] = at_rest;
  still_ticks_ = config_.filter_ticks;
  tap_ = Tap::Off;
  tap_depth_ = tap_v_ = 0;
  tap_reverse_ = false;
}

// While the tap runs, the commanded position is the tap's, on its block's line. The block shown
// is the way in until the spindle has reversed, then the way out (its offset measured back up
// from the bottom), each offset within its block.
void Interpolator::show_tap(TickOutput& out) noexcept {
  const MotionBlock& b = queue_->peek(index_of(u_seq_));
  for (int i = 0; i < kAxisCount; ++i) position_[i] = b.base[i] + tap_depth_ * b.lin[i];
  const bool coming_out = tap_ == Tap::Out || tap_ == Tap::Restoring || tap_ == Tap::Placing;
  const MotionBlock& shown = coming_out ? queue_->peek(index_of(u_seq_) + 1) : b;
  const double offset = std::clamp(coming_out ? b.length - tap_depth_ : tap_depth_, 0.0, shown.length);
  shown_ = Shown{shown.seq,  shown.segment, shown.segment_first, shown.segment_last,
                 shown.line, shown.context, offset,              shown.segment_offset};
  write_shown(out);
  out.path_velocity = std::fabs(tap_v_);
  out.spindle_synced = tap_locked_;
  out.tap_reverse = tap_reverse_;
  out.tap_speed_scale = b.tap_scale;
}

}  // namespace opencnc::traj
