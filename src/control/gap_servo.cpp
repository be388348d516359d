// SPDX-License-Identifier: GPL-3.0-or-later
// GapServo: the path memory, the gap servo's law, the jump and the orbit (docs/edm.md).
#include "opencnc/control/gap_servo.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::control {

namespace {

constexpr double kTwoPi = 6.283185307179586;
/// The finishing cycle's orbit counts as full within this of its radius: the lateral servo draws
/// it in by a fraction of a micrometre whenever the noisy gap voltage dips below the reference, and
/// a turn that counted only to the nanometre went on by a tenth for it (the floor burning on).
constexpr double kFullWithin_mm = 0.0005;

double distance(const Pose& a, const Pose& b) noexcept {
  double d2 = 0;
  for (std::size_t i = 0; i < a.v.size(); ++i) d2 += (a.v[i] - b.v[i]) * (a.v[i] - b.v[i]);
  return std::sqrt(d2);
}

Pose lerp(const Pose& a, const Pose& b, double f) noexcept {
  Pose p;
  for (std::size_t i = 0; i < a.v.size(); ++i) p.v[i] = a.v[i] + f * (b.v[i] - a.v[i]);
  return p;
}

double smoothstep(double f) noexcept {
  return f * f * (3 - 2 * f);
}

}  // namespace

// --- the path memory --------------------------------------------------------------------------

void PathMemory::reset(const Pose& at) noexcept {
  first_ = 0;
  count_ = 1;
  points_[0] = at;
  s_[0] = 0;
  head_ = at;
  head_s_ = 0;
}

void PathMemory::advance(const Pose& head, double spacing, bool corner) noexcept {
  if (count_ == 0) reset(head);
  const std::size_t last = slot(count_ - 1);
  const double d = distance(points_[last], head);
  head_ = head;
  head_s_ = s_[last] + d;
  if (d <= 0 || (d < spacing && !corner)) return;
  if (count_ == kPoints) {  // the oldest point goes: the memory is a ring
    first_ = (first_ + 1) % kPoints;
    --count_;
  }
  const std::size_t k = slot(count_);
  points_[k] = head;
  s_[k] = head_s_;
  ++count_;
}

double PathMemory::tail_s() const noexcept {
  return count_ > 0 ? s_[slot(0)] : 0.0;
}

// Between the last kept point and the live head the chord to the head; elsewhere the chord
// between the two kept points around s (at most `spacing` apart or a block's own chord).
Pose PathMemory::at(double s) const noexcept {
  if (count_ == 0) return head_;
  const std::size_t last = slot(count_ - 1);
  if (s >= head_s_) return head_;
  if (s >= s_[last]) {
    const double len = head_s_ - s_[last];
    return len > 0 ? lerp(points_[last], head_, (s - s_[last]) / len) : head_;
  }
  if (s <= s_[slot(0)]) return points_[slot(0)];
  int lo = 0, hi = count_ - 1;  // s_[lo] ≤ s < s_[hi]
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    (s_[slot(mid)] <= s ? lo : hi) = mid;
  }
  const std::size_t a = slot(lo), b = slot(hi);
  return lerp(points_[a], points_[b], (s - s_[a]) / (s_[b] - s_[a]));
}

// --- the orbit's shapes -----------------------------------------------------------------------

// Each shape starts and ends a turn at the same point and has no step of velocity: the square's
// edges and the star's rays are run with a smooth start and stop (the drives see no corner).
void orbit_offset(OrbitKind kind, double phase, double r, double out[2]) noexcept {
  phase -= std::floor(phase);
  switch (kind) {
    case OrbitKind::Circle:
      out[0] = r * std::cos(kTwoPi * phase);
      out[1] = r * std::sin(kTwoPi * phase);
      return;
    case OrbitKind::Square: {
      static constexpr double kCorner[5][2] = {{1, 0}, {1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
      // Five legs: half an edge up to the first corner, three edges, then to the start (by length).
      const double u = phase * 8;  // perimeter in units of r
      const double ends[6] = {0, 1, 3, 5, 7, 8};
      int k = 0;
      while (k < 4 && u >= ends[k + 1]) ++k;
      const double f = smoothstep((u - ends[k]) / (ends[k + 1] - ends[k]));
      const double* a = kCorner[k];
      const double* b = k == 4 ? kCorner[0] : kCorner[k + 1];
      out[0] = r * (a[0] + f * (b[0] - a[0]));
      out[1] = r * (a[1] + f * (b[1] - a[1]));
      return;
    }
    case OrbitKind::Star: {
      const double u = phase * 8;
      const double k = std::floor(u), f = u - k;
      const double rho = r * 0.5 * (1 - std::cos(kTwoPi * f));  // out and back, smooth at both ends
      out[0] = rho * std::cos(k * kTwoPi / 8);
      out[1] = rho * std::sin(k * kTwoPi / 8);
      return;
    }
    case OrbitKind::None:
      break;
  }
  out[0] = out[1] = 0;
}

// --- the stage ------------------------------------------------------------------------------

void GapServo::configure(const EdmConfig& config, double period_s, double jump_accel_mm_s2) noexcept {
  config_ = config;
  period_s_ = period_s;
  accel_ = jump_accel_mm_s2 > 0 ? jump_accel_mm_s2 : 1000;
}

void GapServo::begin_run(const Pose& at) noexcept {
  memory_.reset(at);
  s_ = v_ = 0;
  feed_scale_ = 1;
  status_.on = status_.generator = false;
  status_.condition = 0;
  cond_ = EdmCondition{};
  jump_ = Jump::Idle;
  lift_ = lift_v_ = 0;
  machining_s_ = 0;
  status_.short_s = 0;
  status_.retract_limit = reached_retract_limit_ = pressing_limit_ = false;
  phase_ = radius_ = 0;
  orbit_rate_ = 1;
  turns_ = 0;
  orbit_[0] = orbit_[1] = 0;
  shape_ = OrbitKind::None;
  finishing_ = status_.finishing = false;
  lateral_v_ = full_turn_ = finish_elapsed_s_ = 0;
  base_ = EdmCondition{};
  adaptive_.reset();
}

// Under a condition with the finishing cycle the burn's end waits: the code is kept until the
// orbit is full at the path's end and has turned there (run_finish), the interpolator waiting.
bool GapServo::apply_code(int code, double p, double q) noexcept {
  if (finishing_ || (status_.on && cond_.orbit_finish && cond_.orbit != OrbitKind::None)) {
    if (!finishing_) {
      finishing_ = true;
      full_turn_ = 0;  // the radius goes on at the speed it has (no step of velocity)
      finish_elapsed_s_ = 0;
      // Where the burn's path ended (the head may already have begun the next block this period).
      finish_s_ = std::min(s_, memory_.head_s());
    }
    pending_code_ = code;
    pending_p_ = p;
    pending_q_ = q;
    return code == machine::kEdmOffCode ||
           (code == machine::kEdmConditionCode && config_.find(static_cast<int>(std::lround(p))) != nullptr);
  }
  return select(code, p, q);
}

bool GapServo::select(int code, double p, double q) noexcept {
  const EdmCondition* c =
      code == machine::kEdmConditionCode ? config_.find(static_cast<int>(std::lround(p))) : nullptr;
  if (c == nullptr) {
    status_.on = false;
    status_.condition = 0;
    return code == machine::kEdmOffCode;
  }
  cond_ = base_ = *c;
  // M180 P<n> Q<r>: this burn's orbit grows to r (the interpreter let through at most the
  // condition's radius, the reach the preflight checked).
  if (q > 0 && cond_.orbit != OrbitKind::None)
    cond_.orbit_radius_mm = base_.orbit_radius_mm = std::min(q, c->orbit_radius_mm);
  adaptive_.reset();
  status_.on = true;
  status_.condition = c->number;
  turns_ = 0;  // the orbit grows again, a step per turn, from where its radius stands
  return true;
}

machine::GeneratorOutputs GapServo::generator() const noexcept {
  machine::GeneratorOutputs g;
  if (!status_.on) return g;
  g.on_time_us = cond_.on_time_us;
  g.off_time_us = cond_.off_time_us;
  g.peak_current_a = cond_.peak_current_a;
  g.voltage_v = cond_.voltage_v;
  g.polarity = cond_.polarity;
  g.condition = cond_.number;
  return g;
}

// The period: the servo's speed moves the electrode on the memory (or lets the interpolator's
// head go on), then the jump and the orbit add their offsets. Off (no condition, a rapid, a hold)
// the generator is off, a jump under way comes back, the orbit shrinks to its centre and an
// electrode left behind the head walks up to it before the interpolator goes on.
Pose GapServo::step(const GapInputs& in) noexcept {
  // An electrode at the head goes with it (the interpolator moved at the speed the servo asked).
  const bool at_head = s_ >= memory_.head_s() - 1e-12;
  memory_.advance(in.head, config_.path_spacing_mm, in.new_block);
  if (at_head && !finishing_) s_ = memory_.head_s();  // finishing: the burn's end, not the head, is its end
  status_.gap_voltage_v = in.gap_voltage_v;
  status_.gap_state = in.gap_state;
  // The finishing cycle machines on at the path's end while the head waits in the next block.
  const bool machining = config_.enabled && status_.on && !in.hold && (finishing_ || !in.rapid);
  // A short is timed while machining; a hold leaves the count where it stands (the gap is still
  // shorted when the program goes on), anything else (a rapid, M181) ends it.
  if (machining && in.gap_state == machine::GapState::Short)
    status_.short_s += period_s_;
  else if (!in.hold)
    status_.short_s = 0;
  if (!machining) {
    v_ = 0;
    run_jump(false);
    if (in.hold || jump_ != Jump::Idle) {
      feed_scale_ = 0;
    } else {
      catch_up();
    }
    return_offsets();
    status_.generator = false;
  } else if (finishing_) {
    run_finish(in, jump_due());
  } else {
    // A jump that is due waits until the servo has braked to rest (no step of velocity).
    const bool due = jump_due();
    law_mm_s_ = 0;
    if (jump_ == Jump::Idle) move_electrode(servo_speed(in, due), in);
    run_jump(due && v_ == 0 && in.gap_state != machine::GapState::Short);
    if (jump_ != Jump::Idle) feed_scale_ = 0;
    run_orbit(in);
    status_.generator = jump_ == Jump::Idle;
    if (status_.generator) machining_s_ += period_s_;
    adapt(in);
  }
  Pose p = memory_.at(s_);
  p[config_.tool_axis] += config_.lift_direction * lift_;
  p[config_.orbit_axes[0]] += orbit_[0];
  p[config_.orbit_axes[1]] += orbit_[1];
  status_.path_speed_mm_s = v_;
  status_.backlog_mm = memory_.head_s() - s_;
  status_.retract_limit = s_ <= memory_.tail_s() && v_ <= 0 && status_.backlog_mm > 0;
  // Reached: the servo still drives back (a short, an arc) and the memory has no more path. Told
  // once until the electrode has moved off the end again.
  reached_retract_limit_ = machining && status_.retract_limit && v_ < 0 && !pressing_limit_;
  if (reached_retract_limit_) pressing_limit_ = true;
  if (!status_.retract_limit) pressing_limit_ = false;
  status_.jumping = jump_ != Jump::Idle;
  status_.jump_lift_mm = cond_.jump_mode == JumpMode::Axis || jump_ == Jump::Idle ? lift_ : jump_from_s_ - s_;
  status_.orbit_radius_mm = radius_;
  status_.orbit_offset[0] = orbit_[0];
  status_.orbit_offset[1] = orbit_[1];
  status_.finishing = finishing_;
  status_.servo_reference_v = cond_.servo_reference_v;
  status_.gain_mm_s_per_v = cond_.gain_mm_s_per_v;
  status_.jump_period_s = cond_.jump_period_s;
  status_.jump_height_mm = cond_.jump_height_mm;
  return p;
}

// The finishing cycle, a period: the path rests at its end (the interpolator waits), the electrode
// comes back to it along the path after a short; the lateral servo drives the orbit's radius
// instead (out at the condition's forward limit while the gap voltage is at the reference or above,
// in at the law's speed below it, in at once on a short), up to the condition's radius. Once a
// whole turn has burnt at that radius, the code the burn's end brought is applied.
void GapServo::run_finish(const GapInputs& in, bool due) noexcept {
  const bool shorted = in.gap_state == machine::GapState::Short;
  double lateral = 0;
  law_mm_s_ = 0;
  finish_elapsed_s_ += period_s_;
  if (jump_ == Jump::Idle) {
    const double v = servo_speed(in, due);
    if (shorted || s_ < finish_s_ - 1e-12) {
      v_ = v;
      s_ = std::clamp(s_ + v * period_s_, memory_.tail_s(), finish_s_);
    } else {
      v_ = 0;  // at the path's end: the radius takes the law
    }
    feed_scale_ = 0;
    if (!due) {
      // Out at the forward limit while the gap is at the reference or wider: at the final depth
      // the floor, still sparking, is what the voltage says, and it opens as it burns; the radius
      // that waited for the law's speed there left the floor burning for seconds (docs/edm.md).
      const double law = cond_.gain_mm_s_per_v * (status_.filtered_voltage_v - cond_.servo_reference_v);
      lateral = shorted ? -cond_.max_retract_mm_s : law < 0 ? law : cond_.max_forward_mm_s;
    }
  }
  // Under the lateral servo a jump waits until the orbit has stopped turning too, and the orbit
  // waits while the electrode is lifted: it comes back to the walls where it left them, not a
  // stretch further on (where they were burnt at a smaller radius: a side short, or seconds of side
  // discharges, on its return).
  const bool turning = cond_.lateral_servo && orbit_rate_ != 0;
  run_jump(due && v_ == 0 && lateral_v_ == 0 && !turning && !shorted);
  feed_scale_ = 0;
  run_lateral(in, lateral);
  status_.generator = jump_ == Jump::Idle;
  if (status_.generator) machining_s_ += period_s_;
  adapt(in);
  if (full_turn_ >= 1) {
    finishing_ = false;
    lateral_v_ = 0;
    select(pending_code_, pending_p_, pending_q_);
  }
}

// The orbit's radius at the lateral servo's speed (out at most at the condition's forward speed,
// in at the growth's rate, at the retract speed on a short) within the tool axis' acceleration,
// between the centre and the condition's radius; it turns as the lateral servo lets it, and comes
// to a stop (within its acceleration) for a jump due or under way. A shape still spiralling in
// from another condition goes on doing so first. The finishing cycle's own.
void GapServo::run_lateral(const GapInputs& in, double target) noexcept {
  if (shape_ != cond_.orbit || cond_.orbit_period_s <= 0) {
    run_orbit(in);
    return;
  }
  draw_period_s_ = cond_.orbit_period_s;
  const double step = cond_.orbit_step_mm > 0 ? cond_.orbit_step_mm : cond_.orbit_radius_mm;
  draw_rate_ = step / (0.25 * cond_.orbit_period_s);
  const double dv = accel_ * period_s_;
  const double limited = std::clamp(target, in.gap_state == machine::GapState::Short ? target : -draw_rate_,
                                    cond_.max_forward_mm_s);
  lateral_v_ = std::clamp(limited, lateral_v_ - dv, lateral_v_ + dv);
  const bool stop = jump_due() || jump_ != Jump::Idle;
  if (cond_.lateral_servo) follow_gap(in.gap_state == machine::GapState::Short || stop);
  turn();
  const double r = std::clamp(radius_ + lateral_v_ * period_s_, 0.0, cond_.orbit_radius_mm);
  if (r != radius_ + lateral_v_ * period_s_) lateral_v_ = 0;  // at the centre or the full size
  radius_ = r;
  orbit_offset(shape_, phase_, radius_, orbit_);
  // The turn at full size counts where it burns: sparking, with the electrode at the burn's end
  // (not lifted, not backed off up the path after a short: there it burns nothing).
  const bool sparking = in.gap_state == machine::GapState::Normal || in.gap_state == machine::GapState::Arc;
  if (radius_ >= cond_.orbit_radius_mm - kFullWithin_mm && jump_ == Jump::Idle && sparking &&
      s_ >= finish_s_ - 1e-9)
    full_turn_ += orbit_rate_ * period_s_ / draw_period_s_;
}

// Adaptive control: every machining period in which the gap sparks (or shorts) feeds the window;
// at its end the settings in force move within the condition's bounds (edm_adaptive.hpp).
void GapServo::adapt(const GapInputs& in) noexcept {
  if (!cond_.adaptive || !status_.generator || in.gap_state == machine::GapState::Open) return;
  if (adaptive_.sample(in.gap_state, in.gap_voltage_v, base_, cond_)) ++status_.adaptations;
  status_.abnormal_share = static_cast<float>(adaptive_.abnormal_share());
  status_.voltage_spread = static_cast<float>(adaptive_.voltage_spread());
}

// Behind the head with nothing to machine: forward to it at the larger of the last condition's
// forward limit and 1 mm/s while the interpolator waits; at the head it goes with it.
void GapServo::catch_up() noexcept {
  const double head = memory_.head_s();
  if (s_ >= head - 1e-12) {
    s_ = head;
    feed_scale_ = 1;
    catch_v_ = 0;
    return;
  }
  feed_scale_ = 0;
  s_ = approach(s_, head, catch_v_, std::max(cond_.max_forward_mm_s, 1.0), 0.5 * accel_, period_s_);
}

// The law: a short backs off at the retract limit at once; otherwise the filtered gap voltage's
// excess over the reference times the gain (an open gap saturates forward, an arc's low voltage
// backs off), limited in speed and in acceleration (the tool axis' limit).
double GapServo::servo_speed(const GapInputs& in, bool brake) noexcept {
  const double alpha = cond_.filter_s > 0 ? std::min(1.0, period_s_ / cond_.filter_s) : 1.0;
  status_.filtered_voltage_v += alpha * (in.gap_voltage_v - status_.filtered_voltage_v);
  double target = cond_.gain_mm_s_per_v * (status_.filtered_voltage_v - cond_.servo_reference_v);
  if (in.gap_state == machine::GapState::Short) target = -cond_.max_retract_mm_s;
  target = std::clamp(target, -cond_.max_retract_mm_s, cond_.max_forward_mm_s);
  if (brake && in.gap_state != machine::GapState::Short) target = 0;
  law_mm_s_ = target;
  const double dv = accel_ * period_s_;
  return std::clamp(target, v_ - dv, v_ + dv);
}

// Forward at the head: the interpolator runs at the servo's speed (its override scaled by the
// block's feed), the electrode with it. Otherwise the interpolator waits and the electrode moves
// on the memory, back down the path or forward to the head again.
void GapServo::move_electrode(double v, const GapInputs& in) noexcept {
  v_ = v;
  const double head = memory_.head_s();
  const bool at_head = s_ >= head - 1e-12;
  if (at_head && v > 0) {
    feed_scale_ = in.head_feed > 0 ? std::min(1.0, v / in.head_feed) : 1.0;  // a marker: pass it
    s_ = head;
    return;
  }
  feed_scale_ = 0;
  s_ = std::clamp(s_ + v * period_s_, memory_.tail_s(), head);
}

// Every T_on of machining the electrode lifts by H at the jump speed and comes back (the
// generator off meanwhile). Along the tool axis: an offset; along the path: the electrode walks
// back on the memory and forward again to where it left it.
bool GapServo::jump_due() const noexcept {
  return jump_ == Jump::Idle && cond_.jump_period_s > 0 && cond_.jump_height_mm > 0 &&
         cond_.jump_speed_mm_s > 0 && machining_s_ >= cond_.jump_period_s;
}

void GapServo::run_jump(bool may_start) noexcept {
  const double h = cond_.jump_height_mm, vj = cond_.jump_speed_mm_s;
  if (jump_ == Jump::Idle) {
    if (!may_start) return;
    jump_ = Jump::Up;
    machining_s_ = 0;
    ++status_.jumps;
    jump_from_s_ = s_;
    v_ = lift_v_ = 0;
  }
  const bool up = jump_ == Jump::Up;
  if (cond_.jump_mode == JumpMode::Axis) {
    lift_ = approach(lift_, up ? h : 0.0, lift_v_, vj, 0.5 * accel_, period_s_);
    if (up && lift_ >= h) jump_ = Jump::Down;
    if (!up && lift_ <= 0) jump_ = Jump::Idle;
    return;
  }
  const double target = up ? std::max(memory_.tail_s(), jump_from_s_ - h) : jump_from_s_;
  s_ = approach(s_, target, lift_v_, vj, 0.5 * accel_, period_s_);
  if (s_ == target) {
    jump_ = up ? Jump::Down : Jump::Idle;
    lift_v_ = 0;
  }
}

// A 1-D move toward `target`: speed up at a_max to v_max, brake so as to stop on it. The braking
// speed is that of whole periods: slowing by a·T each period from n·a·T covers a·T²·n(n+1)/2, so
// the move arrives at a·T. A move that turns (the jump's top) changes its step by up to 2·a·T²
// there: the callers give half the axis' acceleration.
double GapServo::approach(double x, double target, double& v, double v_max, double a_max,
                          double dt) noexcept {
  const double rest = std::fabs(target - x);
  const double dir = target >= x ? 1.0 : -1.0;
  const double at = a_max * dt;
  const double brake = at * (std::sqrt(0.25 + 2 * rest / (at * dt)) - 0.5);
  const double speed = std::min({std::fabs(v) + at, v_max, std::max(brake, at)});
  if (speed * dt >= rest) {
    v = 0;
    return target;
  }
  v = dir * speed;
  return x + v * dt;
}

// The orbit turns at its period while the condition machines (through jumps and shorts too:
// stopping it would be a step of velocity); its radius grows by a step per turn toward the final
// radius, at a step per quarter turn, so that the shape spirals out and never jumps.
void GapServo::run_orbit(const GapInputs& in) noexcept {
  // Another shape (or none): the one drawn spirals in to the centre first, the new one grows from it.
  if (shape_ != cond_.orbit || cond_.orbit_period_s <= 0) {
    return_offsets();
    if (radius_ == 0) shape_ = cond_.orbit_period_s > 0 ? cond_.orbit : OrbitKind::None;
    if (shape_ == OrbitKind::None || radius_ > 0) return;
  }
  draw_period_s_ = cond_.orbit_period_s;
  const double step = cond_.orbit_step_mm > 0 ? cond_.orbit_step_mm : cond_.orbit_radius_mm;
  draw_rate_ = step / (0.25 * cond_.orbit_period_s);
  const double goal = std::min(cond_.orbit_radius_mm, step * (turns_ + 1));
  if (cond_.lateral_servo) {
    // A short draws the orbit in at the retract speed (within the acceleration), as the path
    // backs off: the short may be at a side wall.
    const bool shorted = in.gap_state == machine::GapState::Short;
    follow_gap(shorted);
    turn();
    const double grow = std::clamp((goal - radius_) / period_s_, -draw_rate_, draw_rate_);
    const double dv = accel_ * period_s_;
    // Below the reference the orbit draws in at the law's speed as the path backs off at it (the
    // narrowest gap may be at a side wall): the servo acts along both.
    const double target = law_mm_s_ < 0 ? law_mm_s_ : grow;
    lateral_v_ = std::clamp(shorted ? -cond_.max_retract_mm_s : target, lateral_v_ - dv, lateral_v_ + dv);
    radius_ = std::max(0.0, radius_ + lateral_v_ * period_s_);
    if (radius_ == 0) lateral_v_ = 0;
  } else {
    turn();
    radius_ += std::clamp(goal - radius_, -draw_rate_ * period_s_, draw_rate_ * period_s_);
  }
  orbit_offset(shape_, phase_, radius_, orbit_);
}

// The lateral servo's share of the orbit: it turns at its period while the filtered gap voltage is
// at the reference or above and slows to a stop as it falls to half the reference (`shorted`: a
// short, or in the finishing cycle a jump due or under way — at once), the orbit's speed changing
// within a quarter of the tool axis' acceleration, so that the electrode does not run into a side
// wall faster than the side discharges burn it back.
void GapServo::follow_gap(bool shorted) noexcept {
  const double ref = cond_.servo_reference_v;
  // In the finishing cycle at the full radius the last turn goes twice as fast while the gap is at
  // the reference or wider (slower as it closes, as above): the floor burns on at the final depth
  // and opens the gap, and the walls follow it there, so the sooner the turn ends the nearer to
  // size they stay (docs/edm.md, "The turbine channel without dwell").
  const double fastest = finishing_ && radius_ >= cond_.orbit_radius_mm - kFullWithin_mm ? 2.0 : 1.0;
  const double target =
      shorted || ref <= 0
          ? 0.0
          : fastest * std::clamp((status_.filtered_voltage_v - 0.5 * ref) / (0.5 * ref), 0.0, 1.0);
  const double r = std::max(radius_, 1e-6);
  const double per_turn = cond_.orbit == OrbitKind::Circle   ? 6.283185307179586 * r
                          : cond_.orbit == OrbitKind::Square ? 12 * r
                                                             : 8 * 3.141592653589793 * r;
  const double peak_mm_s = per_turn / draw_period_s_;
  const double dk = 0.25 * accel_ * period_s_ / peak_mm_s;
  orbit_rate_ += std::clamp(target - orbit_rate_, -dk, dk);
}

void GapServo::turn() noexcept {
  phase_ += orbit_rate_ * period_s_ / draw_period_s_;
  if (phase_ >= 1) {
    phase_ -= 1;
    ++turns_;
  }
}

// The shape drawn spirals in: it keeps turning at its period while its radius shrinks at the rate
// it grew (the generator off, another condition, none).
void GapServo::return_offsets() noexcept {
  if (shape_ == OrbitKind::None || radius_ <= 0) {
    radius_ = orbit_[0] = orbit_[1] = phase_ = 0;
    turns_ = 0;
    shape_ = OrbitKind::None;
    orbit_rate_ = 1;  // at the centre the orbit stands still: its speed starts afresh
    return;
  }
  turn();
  radius_ = std::max(0.0, radius_ - draw_rate_ * period_s_);
  orbit_offset(shape_, phase_, radius_, orbit_);
  if (radius_ == 0) shape_ = OrbitKind::None;
}

}  // namespace opencnc::control
