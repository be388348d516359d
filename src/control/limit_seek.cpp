// SPDX-License-Identifier: GPL-3.0-or-later
// LimitSeek: a joint's seek of a limit switch, phase by phase (search, release, latch, clear).
#include "opencnc/control/limit_seek.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::control {

const char* to_string(SeekPhase p) noexcept {
  switch (p) {
    case SeekPhase::Idle:
      return "idle";
    case SeekPhase::Search:
      return "search";
    case SeekPhase::Release:
      return "release";
    case SeekPhase::Latch:
      return "latch";
    case SeekPhase::Clear:
      return "clear";
    case SeekPhase::Done:
      return "done";
    case SeekPhase::Failed:
      return "failed";
  }
  return "?";
}

void LimitSeek::start(const LimitSeekConfig&, int direction, double feedback, double search_end,
                      double free_end, AxisMover&) noexcept {
  phase_ = SeekPhase::Search;
  stopping_ = moving_ = backing_ = false;
  direction_ = direction > 0 ? 1 : -1;
  search_end_ = search_end;
  free_end_ = free_end;
  previous_feedback_ = feedback;
  tripped_at_ = released_at_ = feedback;
}

void LimitSeek::cancel(AxisMover& mover) noexcept {
  if (active()) mover.stop();
  phase_ = SeekPhase::Idle;
  stopping_ = moving_ = backing_ = false;
}

void LimitSeek::tick(const LimitSeekConfig& c, double feedback, bool switch_on, AxisMover& mover) noexcept {
  if (active()) step(c, feedback, switch_on, mover);
  previous_feedback_ = feedback;
}

// The edge happened between the last sample and this one: their middle halves the error the
// sampling adds (speed × period).
void LimitSeek::step(const LimitSeekConfig& c, double feedback, bool switch_on, AxisMover& m) noexcept {
  if (stopping_) {
    if (!m.settled()) return;
    stopping_ = moving_ = false;
  }
  const double dir = direction_;
  const double edge = 0.5 * (previous_feedback_ + feedback);
  auto next = [&](SeekPhase p) {
    m.stop();
    stopping_ = true;
    phase_ = p;
  };
  switch (phase_) {
    case SeekPhase::Search:
      if (!moving_) {
        if (std::isfinite(search_end_)) {
          m.move_to(search_end_, c.velocity);
        } else {
          m.run_at(dir * c.velocity);
        }
        moving_ = true;
      }
      if (switch_on) {
        next(SeekPhase::Release);
      } else if (m.settled()) {
        phase_ = SeekPhase::Failed;  // at the end of the search and no switch
      }
      return;
    case SeekPhase::Release:
      if (!moving_) m.run_at(-dir * c.latch_velocity);
      moving_ = true;
      if (!switch_on) {
        released_at_ = edge;
        next(SeekPhase::Latch);
      }
      return;
    case SeekPhase::Latch:
      if (!moving_) m.run_at(dir * c.latch_velocity);
      moving_ = true;
      if (switch_on) {
        tripped_at_ = edge;
        next(SeekPhase::Clear);
      }
      return;
    case SeekPhase::Clear:
      if (!moving_) m.run_at(-dir * c.latch_velocity);
      moving_ = true;
      if (!backing_ && !switch_on) {
        released_at_ = edge;
        const double target = released_at_ - dir * c.back_off;
        m.move_to(dir > 0 ? std::min(target, free_end_) : std::max(target, free_end_), c.velocity);
        backing_ = true;
      } else if (backing_ && m.settled()) {
        phase_ = SeekPhase::Done;
      }
      return;
    case SeekPhase::Idle:
    case SeekPhase::Done:
    case SeekPhase::Failed:
      return;
  }
}

}  // namespace opencnc::control
