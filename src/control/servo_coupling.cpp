// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, the coupling stage: axes → joints, the slave axis computed from its master by the law a
// program engaged (broaching helices, cams), from the master's command or its feedback.
#include <algorithm>
#include <cmath>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

// While a law is engaged the slave's command is the law's, whatever the interpolator said: the
// program's own slave coordinates (the controller's coupling pass writes the law's value at every
// move's end) agree with it at the ends of moves, so engaging and releasing moves nothing.
void Servo::couple_axes() noexcept {
  if (law_.active()) {
    const double d = coupling_master() - coupling_.master_origin;
    commanded_[coupling_.slave_axis] = coupling_.slave_origin + law_.slave(d);
  }
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    joint_cmd_[uj] = commanded_[config_.joints[uj].axis] - offset_[uj];
  }
}

double Servo::coupling_master() const noexcept {
  if (config_.coupling.source == motion::CouplingSource::Actual && master_joint_ >= 0) {
    const auto mj = static_cast<std::size_t>(master_joint_);
    return position_[mj] + offset_[mj];
  }
  return commanded_[coupling_.master_axis];
}

// The helix error: where the slave is against where the law puts it for where the master is.
double Servo::coupling_error() const noexcept {
  if (!law_.active() || master_joint_ < 0 || slave_joint_ < 0) return 0;
  const auto mj = static_cast<std::size_t>(master_joint_), sj = static_cast<std::size_t>(slave_joint_);
  const double master = position_[mj] + offset_[mj];
  const double slave = position_[sj] + offset_[sj];
  return slave - (coupling_.slave_origin + law_.slave(master - coupling_.master_origin));
}

// A program's coupling record (an exact stop of the path: the commanded position is the corner).
// The origin is the master's commanded position there, so that the law meets the program's slave
// coordinates; a record the machine cannot honour (no coupling configured, no such table)
// releases the coupling — the preflight refuses such programs before they run.
void Servo::engage_coupling(const MachineAction& a) noexcept {
  const motion::CouplingConfig& cc = config_.coupling;
  const auto kind = static_cast<motion::CouplingKind>(a.index);
  master_joint_ = joint_of(cc.master_axis);
  slave_joint_ = joint_of(cc.slave_axis);
  if (!cc.enabled || kind == motion::CouplingKind::Off || master_joint_ < 0 || slave_joint_ < 0) {
    release_coupling();
    return;
  }
  law_ = motion::law_for(cc, kind, a.value, a.value2, a.index2);
  if (!law_.active()) {  // a kind or table the machine does not have
    release_coupling();
    return;
  }
  coupling_.kind = kind;
  coupling_.master_axis = cc.master_axis;
  coupling_.slave_axis = cc.slave_axis;
  coupling_.table = a.index2;
  coupling_.pitch_mm = a.value;
  coupling_.pitch_rate = a.value2;
  coupling_.master_origin = a.has_origin ? a.master_origin : commanded_[cc.master_axis];
  coupling_.slave_origin = a.has_origin ? a.slave_origin : commanded_[cc.slave_axis];
}

// A coupling code's marker waits here until master and slave stand within the tolerance of
// their commands for kInPositionPeriods in a row (a drive swinging through its target is not in
// position). Every period, so that the count is current when the marker is reached.
bool Servo::coupling_in_position() noexcept {
  constexpr int kInPositionPeriods = 5;
  const motion::CouplingConfig& cc = config_.coupling;
  const int m = joint_of(cc.master_axis), s = joint_of(cc.slave_axis);
  if (m < 0 || s < 0 || (cc.engage_tolerance_master <= 0 && cc.engage_tolerance_slave <= 0)) return true;
  const bool in = std::fabs(following_error_[static_cast<std::size_t>(m)]) <= cc.engage_tolerance_master &&
                  std::fabs(following_error_[static_cast<std::size_t>(s)]) <= cc.engage_tolerance_slave;
  in_position_periods_ = in ? std::min(in_position_periods_ + 1, kInPositionPeriods) : 0;
  return in_position_periods_ >= kInPositionPeriods;
}

// Bounded: a drive that does not settle in engage_timeout_s stops the run with a fault naming
// the axis furthest out (relative to its tolerance) and its error.
void Servo::check_engage_wait() noexcept {
  if (!tick_out_.waiting_in_position) {
    engage_wait_periods_ = 0;
    return;
  }
  const motion::CouplingConfig& cc = config_.coupling;
  if (static_cast<double>(++engage_wait_periods_) * config_.period_s <= cc.engage_timeout_s) return;
  const int m = joint_of(cc.master_axis), s = joint_of(cc.slave_axis);
  const double em = following_error_[static_cast<std::size_t>(m)];
  const double es = following_error_[static_cast<std::size_t>(s)];
  const bool master_worse =
      std::fabs(em) * cc.engage_tolerance_slave > std::fabs(es) * cc.engage_tolerance_master;
  engage_wait_periods_ = 0;
  enter_fault({FaultKind::CouplingPosition, master_worse ? cc.master_axis : cc.slave_axis,
               std::fabs(master_worse ? em : es),
               master_worse ? cc.engage_tolerance_master : cc.engage_tolerance_slave, tick_});
}

void Servo::release_coupling() noexcept {
  law_ = motion::CouplingLaw{};
  coupling_ = CouplingStatus{};
}

}  // namespace opencnc::control
