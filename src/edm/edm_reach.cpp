// SPDX-License-Identifier: GPL-3.0-or-later
// The EDM's reach: the conditions in force along a program, their orbits and jumps on the moves.
#include "edm_reach.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace opencnc::edm {

namespace {

/// What condition `c` adds to a move while it machines.
Reach reach_of(const machine::EdmCondition& c) {
  Reach r;
  if (c.orbit != machine::OrbitKind::None && c.orbit_radius_mm > 0) {
    r.orbit_mm = c.orbit_radius_mm;
    r.orbit_condition = c.number;
  }
  if (c.jump_period_s > 0 && c.jump_mode == machine::JumpMode::Axis) {
    r.jump_mm = std::max(c.jump_height_mm,
                         c.adaptive ? c.jump_height_max_mm : 0.0);  // adaptive control may lift higher
    r.jump_condition = c.number;
  }
  return r;
}

/// The larger orbit and the larger jump of two.
Reach wider(Reach a, const Reach& b) {
  if (b.orbit_mm > a.orbit_mm) {
    a.orbit_mm = b.orbit_mm;
    a.orbit_condition = b.orbit_condition;
  }
  if (b.jump_mm > a.jump_mm) {
    a.jump_mm = b.jump_mm;
    a.jump_condition = b.jump_condition;
  }
  return a;
}

/// The move's extent widened by an EDM orbit (both orbit axes) and axis jump (the tool axis, away
/// from the work); a jump along the path stays on the path.
void widen_by(const machine::EdmConfig& edm, const Reach& r, controller::Extent& e) {
  for (const std::int8_t a : edm.orbit_axes) {
    e.min[a] -= r.orbit_mm;
    e.max[a] += r.orbit_mm;
  }
  (edm.lift_direction > 0 ? e.max : e.min)[edm.tool_axis] += edm.lift_direction * r.jump_mm;
}

/// "with EDM condition 2's orbit (0.08 mm) and jump (0.4 mm) ": what widened the move, for the message.
std::string reason(const Reach& r) {
  const bool orbit = r.orbit_condition != 0, jump = r.jump_condition != 0;
  if (!orbit && !jump) return "";
  std::string s = "with EDM ";
  if (orbit) s += fmt::format("condition {}'s orbit ({} mm)", r.orbit_condition, r.orbit_mm);
  if (orbit && jump) s += " and ";
  if (jump && orbit && r.jump_condition == r.orbit_condition) {
    s += fmt::format("jump ({} mm)", r.jump_mm);
  } else if (jump) {
    s += fmt::format("condition {}'s jump ({} mm)", r.jump_condition, r.jump_mm);
  }
  return s + " ";
}

/// The shortest time move `id` can take: its widest axis' travel at that axis' max_velocity.
double shortest_time_s(const canon::Program& program, canon::SegmentId id,
                       const control::ServoConfig& config) {
  const controller::Extent e = controller::move_extent(program, id);
  double t = 0;
  for (int j = 0; j < config.joint_count; ++j) {
    const control::JointConfig& jc = config.joints[static_cast<std::size_t>(j)];
    if (jc.max_velocity > 0) t = std::max(t, (e.max[jc.axis] - e.min[jc.axis]) / jc.max_velocity);
  }
  return t;
}

}  // namespace

std::string ReachCheck::widen(const canon::Program& program, canon::SegmentId move,
                              controller::Extent& extent) {
  if (!config_.edm.enabled) return "";
  const Reach r = reach_at(program, move);
  widen_by(config_.edm, r, extent);
  return reason(r);
}

// How long condition n's offsets may stay out once it is off: the orbit spirals in at the rate it
// grew (a step per quarter turn), a jump under way goes up and comes back at half the tool axis'
// acceleration (GapServo).
void ReachCheck::start_tail(int n) {
  const machine::EdmCondition* c = config_.edm.find(n);
  if (c == nullptr) return;
  double t = 0;
  if (c->orbit != machine::OrbitKind::None && c->orbit_period_s > 0 && c->orbit_radius_mm > 0) {
    const double step = c->orbit_step_mm > 0 ? c->orbit_step_mm : c->orbit_radius_mm;
    t = 0.25 * c->orbit_period_s * c->orbit_radius_mm / step;
  }
  if (c->jump_period_s > 0 && c->jump_speed_mm_s > 0) {
    double a = 0;
    for (int j = 0; j < config_.joint_count; ++j) {
      if (config_.joints[static_cast<std::size_t>(j)].axis == config_.edm.tool_axis)
        a = 0.5 * config_.joints[static_cast<std::size_t>(j)].max_acceleration;
    }
    const double h = std::max(c->jump_height_mm, c->adaptive ? c->jump_height_max_mm : 0.0);
    t = std::max(t, 2 * (h / c->jump_speed_mm_s + (a > 0 ? c->jump_speed_mm_s / a : 0)));
  }
  const double left = tail_s_ - since_s_;
  tail_ = left > 0 || tail_first_ ? wider(tail_, reach_of(*c)) : reach_of(*c);
  tail_s_ = std::max(left, t);
  since_s_ = 0;
  tail_first_ = true;
}

// The moves are checked in order; the codes before each are read once (a new program, or a move
// before the last one, starts afresh). Actions already released were seen before (the scan
// releases only what it has checked). Each move checked adds its shortest time to the time
// since the last code; one not checked adds nothing, which only widens more moves.
Reach ReachCheck::reach_at(const canon::Program& program, std::size_t move) {
  if (&program != program_ || move < last_move_) {
    program_ = &program;
    next_action_ = 0;
    on_ = 0;
    tail_ = {};
    tail_s_ = since_s_ = 0;
    tail_first_ = false;
    timed_move_ = move;
  } else if (move == last_move_ && timed_move_ > move) {
    return last_reach_;  // the same move checked again
  }
  last_move_ = move;
  next_action_ = std::max(next_action_, program.first_held_action());
  for (; next_action_ < program.action_count(); ++next_action_) {
    const canon::Action& a = program.action(next_action_);
    if (a.before_move > move) break;
    if (a.kind != canon::ActionKind::ProcessCode) continue;
    if (a.index == machine::kEdmConditionCode) {
      const int n = static_cast<int>(std::lround(a.value));
      if (on_ != 0 && on_ != n) start_tail(on_);
      on_ = n;
    } else if (a.index == machine::kEdmOffCode) {
      if (on_ != 0) start_tail(on_);
      on_ = 0;
    }
  }
  Reach r;
  if (on_ != 0) {
    if (const machine::EdmCondition* c = config_.edm.find(on_)) r = reach_of(*c);
  }
  if (tail_first_ || since_s_ < tail_s_) r = wider(r, tail_);
  since_s_ += shortest_time_s(program, move, config_);
  tail_first_ = false;
  timed_move_ = move + 1;
  last_reach_ = r;
  return r;
}

}  // namespace opencnc::edm
