// SPDX-License-Identifier: GPL-3.0-or-later
// The coupling pass: slave coordinates by the law as the builder appends moves, and the checks
// of the slave's limits through the law (docs/broaching.md, "The planner and the preflight").
#include "opencnc/broaching/coupling_pass.hpp"

#include <fmt/format.h>

#include <cmath>

#include "opencnc/controller/servo_setup.hpp"

namespace opencnc::broaching {

namespace {

/// Share of the slave's acceleration the law's curvature may take on top of what the planner
/// plans along the chord (the planner does not see it).
constexpr double kCurvatureShare = 0.05;
/// Velocity slack: the planner's own rounding.
constexpr double kVelocitySlack = 1e-6;

std::string file_name(const canon::Program& p, std::uint32_t context) {
  const std::uint32_t f =
      context != 0 && context < p.sources().context_count() ? p.sources().context_info(context).body_file : 0;
  return f < p.sources().file_count() ? p.sources().file(f) : std::string();
}

}  // namespace

CoupledAxes coupled_axes(const config::MachineProfile& profile) {
  CoupledAxes c;
  c.config = control::coupling_config(profile.coupling);
  if (!c.config.enabled) return c;
  const plan::MachineLimits limits = controller::machine_limits(profile);
  const auto master = static_cast<std::size_t>(c.config.master_axis);
  const auto slave = static_cast<std::size_t>(c.config.slave_axis);
  c.master_velocity = limits.axis[master].max_velocity;
  c.slave_velocity = limits.axis[slave].max_velocity;
  c.slave_acceleration = limits.axis[slave].max_acceleration;
  if (const config::AxisProfile* a = profile.find(profile.coupling.slave)) {
    c.slave_wrapped = a->wrapped;
    c.slave_min = a->min_limit;
    c.slave_max = a->max_limit;
  }
  return c;
}

void CouplingPass::process(canon::Program& program) {
  if (!axes_.any()) return;
  if (!started_) {
    started_ = true;
    next_ = 0;
    next_action_ = program.first_held_action();
    programmed_slave_ = program.start()[axes_.config.slave_axis];
  }
  for (; next_ < program.size(); ++next_) {
    take_actions(program, next_);
    process_move(program, static_cast<canon::SegmentId>(next_));
  }
}

// The coupling actions that stand before move `before_move`, in order.
void CouplingPass::take_actions(canon::Program& program, std::size_t before_move) {
  for (; next_action_ < program.action_count() && program.action(next_action_).before_move <= before_move;
       ++next_action_) {
    const canon::Action& a = program.action(next_action_);
    if (a.kind == canon::ActionKind::AxisCoupling) engage(program, a);
  }
}

// Engaged where the path stands (the end of the move before), as the tick does at the marker.
void CouplingPass::engage(const canon::Program& program, const canon::Action& a) {
  const Pose at = program.start_of(a.before_move);
  const int slave = axes_.config.slave_axis;
  const auto kind = static_cast<motion::CouplingKind>(a.index);
  if (kind == motion::CouplingKind::Off) {
    if (law_.active()) slave_shift_ = at[slave] - programmed_slave_;
    law_ = motion::CouplingLaw{};
    return;
  }
  law_ = motion::law_for(axes_.config, kind, a.value, program.action_pose(a.pose)[0], a.index2);
  if (!law_.active()) {  // only a table can be missing: the codes give the pitch laws their pitch
    fail(program, a.context, a.line,
         fmt::format("this machine has no {} table {} (its profile's [[coupling.table]] entries)",
                     kind == motion::CouplingKind::Cam ? "cam" : "pitch", a.index2));
    return;
  }
  // A resumed program's law engages with the origin its code had; the slave coordinate the
  // program asked for last is the one it had there (it cannot ask for another while coupled).
  const Pose& origin = a.origin != 0 ? program.action_pose(a.origin - 1) : at;
  if (a.origin != 0) programmed_slave_ = origin[slave];
  master_origin_ = origin[axes_.config.master_axis];
  slave_origin_ = origin[slave];
}

void CouplingPass::process_move(canon::Program& program, canon::SegmentId id) {
  const Axis slave = static_cast<Axis>(axes_.config.slave_axis);
  const canon::Move& m = program.move(id);
  const double asked = program.end_coord(id, slave);
  const bool slave_word = asked != programmed_slave_;
  programmed_slave_ = asked;
  if (!law_.active()) {
    if (slave_word) slave_shift_ = 0;  // the program places the slave again
    if (slave_shift_ != 0) program.set_end_coord(id, slave, asked + slave_shift_);
    return;
  }
  const char axis_letter = letter(slave);
  if (slave_word) {
    fail(program, m.context, m.line,
         fmt::format("{} is coupled to {} (M171-M174): the program cannot move it until M175", axis_letter,
                     letter(static_cast<Axis>(axes_.config.master_axis))));
    return;
  }
  if (m.kind == canon::MoveKind::Probe || m.kind == canon::MoveKind::RigidTap ||
      (m.flags & canon::kSpindleSynced)) {
    fail(program, m.context, m.line,
         fmt::format(
             "a probe, rigid tap or spindle-synchronised move cannot run while {} is coupled (M175 first)",
             axis_letter));
    return;
  }
  const int master = axes_.config.master_axis;
  const double d0 = program.start_of(id)[master] - master_origin_;
  const double d1 = program.end_coord(id, static_cast<Axis>(master)) - master_origin_;
  program.set_end_coord(id, slave, slave_origin_ + law_.slave(d1));
  check_move(program, id, d0, d1);
}

// The fastest the planner may run the master on this move: its own limit, the slave's through
// the chord, and the programmed feed's share along the master (feed per minute only).
double CouplingPass::master_speed_bound(const canon::Program& program, canon::SegmentId id,
                                        double chord_slope) const {
  double v = axes_.master_velocity;
  if (std::fabs(chord_slope) > 0) v = std::min(v, axes_.slave_velocity / std::fabs(chord_slope));
  const canon::Move& m = program.move(id);
  const bool per_minute = !(m.flags & (canon::kInverseTime | canon::kPerRevolution));
  if (m.kind == canon::MoveKind::Traverse || !per_minute) return v;
  const double feed = program.feed(id) / 60.0;
  if (m.kind != canon::MoveKind::Feed) return std::min(v, feed);
  const Pose a = program.start_of(id), b = program.end(id);
  const auto diff = [&](int i) { return b[i] - a[i]; };
  const double xyz = std::sqrt(diff(0) * diff(0) + diff(1) * diff(1) + diff(2) * diff(2));
  const double along = std::fabs(diff(axes_.config.master_axis));
  return xyz > 0 ? std::min(v, feed * along / xyz) : v;
}

void CouplingPass::check_move(const canon::Program& program, canon::SegmentId id, double d0, double d1) {
  const canon::Move& m = program.move(id);
  const char s = letter(static_cast<Axis>(axes_.config.slave_axis));
  if (law_.kind() == motion::CouplingKind::LinearPitch &&
      (law_.pitch_at(d0) > 0) != (law_.pitch_at(d1) > 0)) {
    fail(program, m.context, m.line,
         fmt::format("the pitch of M172 reaches 0 on this move (at {:.3f} mm from where it was engaged)",
                     -law_.pitch_mm() / law_.pitch_rate()));
    return;
  }
  if (!axes_.slave_wrapped) {
    const auto [lo, hi] = law_.slave_extent(d0, d1);
    if (slave_origin_ + lo < axes_.slave_min - 1e-9 || slave_origin_ + hi > axes_.slave_max + 1e-9) {
      fail(program, m.context, m.line,
           fmt::format("the coupled {} would reach {:.3f} on this move, beyond its soft limits [{}, {}]", s,
                       slave_origin_ + (slave_origin_ + lo < axes_.slave_min ? lo : hi), axes_.slave_min,
                       axes_.slave_max));
      return;
    }
  }
  if (d1 == d0) return;
  const double chord = (law_.slave(d1) - law_.slave(d0)) / (d1 - d0);
  const double v = master_speed_bound(program, id, chord);
  const double peak = v * law_.max_slope(d0, d1);
  if (peak > axes_.slave_velocity * (1 + kVelocitySlack)) {
    fail(program, m.context, m.line,
         fmt::format("the coupled {} would turn at {:.1f} deg/s on this move (its limit {:.1f}): the law is "
                     "steeper inside the move than its chord; split the move or lower the feed",
                     s, peak, axes_.slave_velocity));
    return;
  }
  const double curvature_accel = v * v * law_.max_curvature(d0, d1);
  if (curvature_accel > kCurvatureShare * axes_.slave_acceleration) {
    fail(
        program, m.context, m.line,
        fmt::format("the law's curvature alone would accelerate the coupled {} at {:.1f} deg/s² on this move "
                    "(more than {:.0f} % of its {:.1f}): lower the feed",
                    s, curvature_accel, kCurvatureShare * 100, axes_.slave_acceleration));
  }
}

void CouplingPass::fail(const canon::Program& program, std::uint32_t context, std::uint32_t line,
                        std::string message) {
  failures_.error(file_name(program, context), line, 0, std::move(message), "control.coupling");
}

}  // namespace opencnc::broaching
