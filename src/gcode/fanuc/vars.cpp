// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect's macro variables: computed system variables (modal codes #4001.., positions
// #5001.., tool length offsets #5081..), vacancy, #3000 alarms and #3006 stops with a message.
#include <cmath>

#include "dialect.hpp"
#include "numeric.hpp"
#include "variables.hpp"

namespace opencnc::gcode {

namespace {

// Fanuc numbers axes by their place on the machine: X Y Z on a mill, X Z on a lathe.
constexpr int kMillAxes[kAxisCount] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
constexpr int kLatheAxes[kAxisCount] = {0, 2, 5, 1, 3, 4, 6, 7, 8};

}  // namespace

bool FanucDialect::variable(int index, double& value) {
  switch (fanuc_variable_kind(index)) {
    case FanucVariable::Missing:
      fail(ErrorCode::ParameterOutOfRange,
           "variable #{} does not exist (locals are #1-#33, common variables #100-#999)", index);
    case FanucVariable::Unavailable:
      fail(ErrorCode::FanucVariableUnavailable, "system variable #{} is not available here", index);
    case FanucVariable::Computed:
      value = computed(index);
      return true;
    default:
      return false;
  }
}

// The modal G code of Fanuc's group `group` (#4001 + group - 1), as Fanuc reports it.
double FanucDialect::modal(int group) const {
  const ModalState& m = e_.st_.modal;
  const bool lathe = e_.opt_.machine == MachineKind::Lathe;
  switch (group) {
    case 1:
      return m.motion == -1 || m.motion == 800 || m.motion > 330 ? 80.0 : m.motion / 10.0;
    case 2:
      return m.plane == canon::Plane::XZ ? 18.0 : m.plane == canon::Plane::YZ ? 19.0 : 17.0;
    case 3:
      return m.distance == DistanceMode::Absolute ? 90.0 : 91.0;
    case 5:
      if (m.feed_mode == canon::FeedMode::InverseTime) return 93.0;
      if (lathe) return m.feed_mode == canon::FeedMode::UnitsPerMinute ? 98.0 : 99.0;
      return m.feed_mode == canon::FeedMode::UnitsPerMinute ? 94.0 : 95.0;
    case 6:
      return m.units == canon::Units::Inch ? 20.0 : 21.0;
    case 7:
      return m.cutter_comp == CutterComp::Left ? 41.0 : m.cutter_comp == CutterComp::Right ? 42.0 : 40.0;
    case 8:
      return m.tool_length_mode / 10.0;
    case 9:
      return (m.motion >= 730 && m.motion <= 890 && m.motion != 760) ? m.motion / 10.0 : 80.0;
    case 10:
      return m.retract == RetractMode::OldZ ? 98.0 : 99.0;
    case 11:
      return e_.st_.fanuc.transform.scaling ? 51.0 : 50.0;
    case 12:
      return 67.0;  // no modal macro call (G66)
    case 13:
      return m.spindle_mode == SpindleMode::ConstantSurface ? 96.0 : 97.0;
    case 14:
      return m.coord_system <= 6 ? 53.0 + m.coord_system : 59.0 + (m.coord_system - 6) / 10.0;
    case 15:
      return m.control == canon::MotionControl::Continuous  ? 64.0
             : m.control == canon::MotionControl::ExactPath ? 61.0
                                                            : 61.1;
    case 16:
      return e_.st_.fanuc.transform.rotating ? 68.0 : 69.0;
    case 22:
      return e_.st_.fanuc.transform.mirror_axes != 0 ? 51.1 : 50.1;
    default:
      return 0.0;  // groups this controller has no codes in
  }
}

double FanucDialect::computed(int index) const {
  const PositionState& p = e_.st_.position;
  const bool lathe = e_.opt_.machine == MachineKind::Lathe;
  if (index == 3007) {
    double bits = 0;
    for (int i = 0; i < kAxisCount; ++i) {
      if ((e_.st_.fanuc.transform.mirror_axes >> i) & 1u) bits += std::ldexp(1.0, i);
    }
    return bits;
  }
  if (index >= 4001 && index <= 4330) {
    const int modal = index >= 4201 ? index - 200 : index;
    if (modal <= 4030) return this->modal(modal - 4000);
    if (modal == 4109) return e_.st_.modal.feed_rate;
    if (modal == 4119) return e_.st_.modal.spindle_speed;
    return e_.st_.tool.selected_tool;  // 4120
  }
  if (index >= 5401) return 0.0;  // Haas tool timers: no time passes in the interpreter
  // Positions by Fanuc axis number: block end / work position, machine position, tool length
  // offset, servo lag (none). X reads as a diameter while lathe diameter mode is on.
  const int block = (index - 5001) / 20;
  const int slot = (index - 5001) % 20;
  if (slot >= kAxisCount) return 0.0;  // numbers past the ninth axis of a block
  const int axis = lathe ? kLatheAxes[slot] : kMillAxes[slot];
  double v = 0;
  switch (block) {
    case 0:
    case 2:
      v = p.current[axis];
      break;
    case 1:
      v = p.current[axis] + p.tool_offset[axis] + p.origin_offset[axis] + p.axis_offset[axis];
      break;
    case 4:
      v = p.tool_offset[axis];
      break;
    default:
      return 0.0;
  }
  return axis == 0 && e_.st_.modal.lathe_diameter ? 2.0 * v : v;
}

// The line's assignments with the Fanuc rules: a vacant value makes the variable vacant,
// #3000 = n stops with alarm 3000 + n and the line's comment as the message, #3006 = n stops
// with the comment as a message.
void FanucDialect::assignments() {
  auto& vacant = e_.st_.fanuc.vacant;
  for (const auto& [index, value] : e_.parser_.numbered_assignments) {
    const FanucVariable kind = fanuc_variable_kind(index);
    const std::string text = e_.block_.has_comment ? std::string(e_.block_.comment) : std::string();
    if (kind == FanucVariable::Alarm) {
      // Alarm numbers 3000..3999: #3000 = 0..999 (a value beyond names no alarm, and would
      // overflow the sum).
      const int n = round_to_int(value);
      if (n < 0 || n > 999)
        fail(ErrorCode::FanucAlarm,
             "alarm: #3000 = {} is no alarm number (0 to 999, for alarms 3000 to 3999){}{}", value,
             text.empty() ? "" : ": ", text);
      fail(ErrorCode::FanucAlarm, "alarm {}{}{} (#3000 = {})", 3000 + n, text.empty() ? "" : ": ", text,
           value);
    }
    if (kind == FanucVariable::StopMessage) {
      e_.out_.message(text.empty() ? fmt::format("#3006 = {}", value) : text);
      e_.out_.program_stop();
      e_.request_stop_sync();
    }
    e_.st_.parameters[static_cast<std::size_t>(index)] = value;
    if (index < kFanucVariableCount) vacant.reset(static_cast<std::size_t>(index));
  }
  for (int index : e_.parser_.vacant_assignments) {
    e_.st_.parameters[static_cast<std::size_t>(index)] = 0.0;
    // Only #0..#999 can be vacant (system variables such as #3006 cannot; the fuzzer found the
    // bitset's out_of_range here).
    if (index < kFanucVariableCount) vacant.set(static_cast<std::size_t>(index));
  }
  for (const auto& [name, value] : e_.parser_.named_assignments) e_.params_.store_named(name, value);
}

}  // namespace opencnc::gcode
