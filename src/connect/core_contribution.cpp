// SPDX-License-Identifier: GPL-3.0-or-later
// The machine's core in MTConnect: its axes, the controller with its path, the spindle, and the
// faults and process alarms as conditions. What each status field becomes is in docs/connectivity.md.
#include "core_contribution.hpp"

#include <fmt/format.h>

#include <cmath>

namespace opencnc::connect {

namespace {

constexpr int kMm = 4;    // 0.1 µm, the resolution of the status
constexpr int kDeg = 4;   // 0.0001°
constexpr int kFeed = 3;  // mm/s

std::string lower(char c) {
  return std::string(1, static_cast<char>(c - 'A' + 'a'));
}

const char* execution(const controller::ControllerStatus& s) {
  using control::State;
  const auto& v = s.servo;
  switch (v.state) {
    case State::Running:
      if (v.wait != control::Wait::None && v.wait != control::Wait::Starved) return "WAIT";
      return "ACTIVE";
    case State::Held:
      return "FEED_HOLD";
    case State::Stopped:
      switch (v.stop_reason) {
        case control::StopReason::ProgramStop:
          return "PROGRAM_STOPPED";
        case control::StopReason::OptionalStop:
          return "OPTIONAL_STOP";
        default:
          return "INTERRUPTED";  // single block: waits for cycle start between blocks
      }
    case State::Idle:
      return "READY";
    case State::EStopped:
    case State::Off:
    case State::Faulted:
      return "STOPPED";
  }
  return "UNAVAILABLE";
}

const char* controller_mode(control::Mode m) {
  switch (m) {
    case control::Mode::Manual:
      return "MANUAL";
    case control::Mode::Mdi:
      return "MANUAL_DATA_INPUT";
    case control::Mode::Auto:
      return "AUTOMATIC";
  }
  return "UNAVAILABLE";
}

/// Faults that belong to one axis, and whether it is its travel (POSITION) or its drive (ACTUATOR).
enum class AxisFault { None, Travel, Actuator };
AxisFault axis_fault(control::FaultKind k) {
  using control::FaultKind;
  switch (k) {
    case FaultKind::LimitSwitch:
    case FaultKind::SoftLimit:
    case FaultKind::Homing:
    case FaultKind::SeekNoSwitch:
      return AxisFault::Travel;
    case FaultKind::AmpFault:
    case FaultKind::FollowingError:
    case FaultKind::Stall:
    case FaultKind::CouplingPosition:
      return AxisFault::Actuator;
    default:
      return AxisFault::None;
  }
}

}  // namespace

CoreContribution::CoreContribution(const config::MachineProfile& profile) : profile_(profile) {}

void CoreContribution::describe(DeviceModel& model) {
  auto item = [&](int component, std::string id, Category category, std::string type, std::string element,
                  std::string sub_type = {}, std::string units = {}) {
    return model.add_item(DataItem{std::move(id), category, std::move(type), std::move(sub_type),
                                   std::move(units), std::move(element), component});
  };
  const int axes = model.add_component(0, "Axes", "axes");
  for (const auto& a : profile_.axes) {
    const char l = letter(a.axis);
    const std::string p = lower(l);
    AxisItems ai;
    ai.axis = static_cast<int>(a.axis);
    ai.joint = a.joint;
    ai.rotary = a.rotary;
    ai.peak_effort = a.sim.peak_effort;
    const int c = model.add_component(axes, a.rotary ? "Rotary" : "Linear", p, std::string(1, l));
    const std::string type = a.rotary ? "ANGLE" : "POSITION";
    const std::string element = a.rotary ? "Angle" : "Position";
    const std::string units = a.rotary ? "DEGREE" : "MILLIMETER";
    ai.actual = item(c, p + "_act", Category::Sample, type, element, "ACTUAL", units);
    ai.commanded = item(c, p + "_cmd", Category::Sample, type, element, "COMMANDED", units);
    ai.load = item(c, p + "_load", Category::Sample, "LOAD", "Load", {}, "PERCENT");
    ai.travel = item(c, p + "_travel", Category::Condition, "POSITION", {});
    ai.actuator = item(c, p + "_actuator", Category::Condition, "ACTUATOR", {});
    axes_.push_back(ai);
  }
  if (profile_.spindle.present) {
    const int c = model.add_component(axes, "Rotary", "s", "S");
    spindle_ = SpindleItems{};
    spindle_->speed = item(c, "s_speed", Category::Sample, "ROTARY_VELOCITY", "RotaryVelocity", "ACTUAL",
                           "REVOLUTION/MINUTE");
    spindle_->commanded = item(c, "s_speed_cmd", Category::Sample, "ROTARY_VELOCITY", "RotaryVelocity",
                               "COMMANDED", "REVOLUTION/MINUTE");
    spindle_->override_ =
        item(c, "s_ovr", Category::Event, "ROTARY_VELOCITY_OVERRIDE", "RotaryVelocityOverride");
    spindle_->mode = item(c, "s_mode", Category::Event, "ROTARY_MODE", "RotaryMode");
    spindle_->load = item(c, "s_load", Category::Sample, "LOAD", "Load", {}, "PERCENT");
    spindle_->torque = item(c, "s_torque", Category::Sample, "TORQUE", "Torque", {}, "NEWTON_METER");
    spindle_->rated_torque = profile_.spindle.rated_torque_nm;
  }
  const int controller = model.add_component(0, "Controller", "controller");
  estop_ = item(controller, "estop", Category::Event, "EMERGENCY_STOP", "EmergencyStop");
  system_ = item(controller, "system", Category::Condition, "SYSTEM", {});
  const int path = model.add_component(controller, "Path", "path");
  execution_ = item(path, "execution", Category::Event, "EXECUTION", "Execution");
  mode_ = item(path, "mode", Category::Event, "CONTROLLER_MODE", "ControllerMode");
  program_ = item(path, "program", Category::Event, "PROGRAM", "Program");
  line_ = item(path, "line", Category::Event, "LINE_NUMBER", "LineNumber", "ABSOLUTE");
  tool_ = item(path, "tool", Category::Event, "TOOL_NUMBER", "ToolNumber");
  part_count_ = item(path, "part_count", Category::Event, "PART_COUNT", "PartCount", "ALL");
  feed_ =
      item(path, "feed", Category::Sample, "PATH_FEEDRATE", "PathFeedrate", "ACTUAL", "MILLIMETER/SECOND");
  feed_override_ =
      item(path, "feed_ovr", Category::Event, "PATH_FEEDRATE_OVERRIDE", "PathFeedrateOverride", "PROGRAMMED");
  rapid_override_ =
      item(path, "rapid_ovr", Category::Event, "PATH_FEEDRATE_OVERRIDE", "PathFeedrateOverride", "RAPID");
  position_ =
      item(path, "path_pos", Category::Sample, "PATH_POSITION", "PathPosition", "ACTUAL", "MILLIMETER_3D");
}

void CoreContribution::observe(const controller::ControllerStatus& s, ValueSink& out) const {
  const auto& v = s.servo;
  for (const auto& a : axes_) {
    const auto i = static_cast<std::size_t>(a.axis);
    const int decimals = a.rotary ? kDeg : kMm;
    out.set(a.actual, v.actual[i], decimals);
    out.set(a.commanded, v.commanded[i], decimals);
    // LOAD: the drive's effort as a share of its peak, where the drive reports it (the simulated
    // machine's servo drives do; in HAL, the `joint.N.effort` pins when the component is loaded
    // with effort=1).
    const auto& joint = v.joints[static_cast<std::size_t>(a.joint)];
    if (joint.effort_valid && a.peak_effort > 0)
      out.set(a.load, 100.0 * std::abs(joint.effort) / a.peak_effort, 1);
    else
      out.set(a.load, "UNAVAILABLE");
  }
  if (spindle_) {
    out.set(spindle_->speed, v.spindle_rpm_actual, 1);
    out.set(spindle_->commanded, v.spindle_rpm, 1);
    out.set(spindle_->override_, v.spindle_override * 100.0, 0);
    out.set(spindle_->mode, "SPINDLE");
    // LOAD: the drive's torque as a share of its rating, where the drive reports it and the
    // profile states the rating ([spindle] rated_torque_nm).
    if (v.spindle_torque_valid) {
      out.set(spindle_->torque, v.spindle_torque_nm, 2);
      if (spindle_->rated_torque > 0)
        out.set(spindle_->load, 100.0 * std::abs(v.spindle_torque_nm) / spindle_->rated_torque, 1);
      else
        out.set(spindle_->load, "UNAVAILABLE");
    } else {
      out.set(spindle_->torque, "UNAVAILABLE");
      out.set(spindle_->load, "UNAVAILABLE");
    }
  }
  out.set(estop_, v.state == control::State::EStopped || !v.estop_input_ok ? "TRIGGERED" : "ARMED");
  out.set(execution_, execution(s));
  out.set(mode_, controller_mode(v.mode));
  out.set(program_, s.program_name.empty() ? "UNAVAILABLE" : s.program_name);
  out.set(line_, v.run_active ? fmt::format("{}", v.line) : std::string("UNAVAILABLE"));
  out.set(tool_, fmt::format("{}", v.tool));
  out.set(part_count_, fmt::format("{}", s.runs_finished));
  out.set(feed_, v.path_velocity, kFeed);
  out.set(feed_override_, v.feed_override * 100.0, 0);
  out.set(rapid_override_, v.rapid_override * 100.0, 0);
  out.set(position_,
          fmt::format("{:.{}f} {:.{}f} {:.{}f}", v.actual[0], kMm, v.actual[1], kMm, v.actual[2], kMm));

  // A fault of one axis goes to that axis; every other fault, and the process alarms, to the system.
  const auto& f = v.fault;
  if (f.kind != control::FaultKind::None) {
    const std::string code = control::fault_code(f.kind);
    const AxisFault where = axis_fault(f.kind);
    const AxisItems* axis = nullptr;
    for (const auto& a : axes_)
      if (a.axis == f.axis) axis = &a;
    if (where != AxisFault::None && axis != nullptr)
      out.condition(where == AxisFault::Travel ? axis->travel : axis->actuator, Level::Fault, code,
                    s.fault_text);
    else
      out.condition(system_, Level::Fault, code, s.fault_text);
  }
  const auto& alarms = profile_.alarms;
  for (int i = 0; i < alarms.alarms.count; ++i) {
    if (((v.alarms_active >> i) & 1u) == 0) continue;
    const auto& alarm = alarms.alarms.alarms[static_cast<std::size_t>(i)];
    const std::string& name = alarms.names[static_cast<std::size_t>(i)];
    const std::string& unit = alarms.units[static_cast<std::size_t>(i)];
    const double value = v.alarm_values[static_cast<std::size_t>(i)];
    std::string bounds;
    if (alarm.has_low) bounds += fmt::format(" below {:g}", alarm.low);
    if (alarm.has_high) bounds += fmt::format("{} above {:g}", bounds.empty() ? "" : " or", alarm.high);
    out.condition(system_, alarm.reaction == machine::AlarmReaction::Message ? Level::Warning : Level::Fault,
                  "alarm." + name,
                  fmt::format("process alarm {}: {:g}{}{} is out of range (alarm{})", name, value,
                              unit.empty() ? "" : " ", unit, bounds));
  }
}

}  // namespace opencnc::connect
