// SPDX-License-Identifier: GPL-3.0-or-later
// Named parameters: locals per call level, globals (#<_name>), and LinuxCNC's read-only
// system parameters (#<_x>, #<_feed>, #<_line>, ...); the current-position parameters.
#include <algorithm>
#include <array>

#include "engine.hpp"

namespace opencnc::gcode {

namespace {

enum class Sys {
  AbsoluteMode, AdaptiveFeed, A, B, C, CallLevel, Ccomp, CoordSystem, CurrentPocket, CurrentTool, Feed, FeedHold,
  FeedOverride, Flood, IjkAbsolute, Imperial, Incremental, InverseTime, LatheDiameter, LatheRadius, Line, Metric, Mist,
  MotionMode, Plane, RemapLevel, RetractOldZ, RetractRPlane, Rpm, SelectedPocket, SelectedTool, SpeedOverride,
  SpindleCss, SpindleCw, SpindleOn, SpindleRpm, ToolOffset, U, UnitsPerMinute, UnitsPerRev, V, Value, ValueReturned,
  Vmajor, Vminor, W, X, Y, Z
};

struct SysName {
  std::string_view name;
  Sys id;
};

// Sorted by name for binary search.
constexpr std::array<SysName, 49> kSystem = {{
    {"_a", Sys::A}, {"_absolute", Sys::AbsoluteMode}, {"_adaptive_feed", Sys::AdaptiveFeed}, {"_b", Sys::B},
    {"_c", Sys::C}, {"_call_level", Sys::CallLevel}, {"_ccomp", Sys::Ccomp}, {"_coord_system", Sys::CoordSystem},
    {"_current_pocket", Sys::CurrentPocket}, {"_current_tool", Sys::CurrentTool}, {"_feed", Sys::Feed},
    {"_feed_hold", Sys::FeedHold}, {"_feed_override", Sys::FeedOverride}, {"_flood", Sys::Flood},
    {"_ijk_absolute_mode", Sys::IjkAbsolute}, {"_imperial", Sys::Imperial}, {"_incremental", Sys::Incremental},
    {"_inverse_time", Sys::InverseTime}, {"_lathe_diameter_mode", Sys::LatheDiameter},
    {"_lathe_radius_mode", Sys::LatheRadius}, {"_line", Sys::Line}, {"_metric", Sys::Metric}, {"_mist", Sys::Mist},
    {"_motion_mode", Sys::MotionMode}, {"_plane", Sys::Plane}, {"_remap_level", Sys::RemapLevel},
    {"_retract_old_z", Sys::RetractOldZ}, {"_retract_r_plane", Sys::RetractRPlane}, {"_rpm", Sys::Rpm},
    {"_selected_pocket", Sys::SelectedPocket}, {"_selected_tool", Sys::SelectedTool},
    {"_speed_override", Sys::SpeedOverride}, {"_spindle_css_mode", Sys::SpindleCss}, {"_spindle_cw", Sys::SpindleCw},
    {"_spindle_on", Sys::SpindleOn}, {"_spindle_rpm_mode", Sys::SpindleRpm}, {"_tool_offset", Sys::ToolOffset},
    {"_u", Sys::U}, {"_units_per_minute", Sys::UnitsPerMinute}, {"_units_per_rev", Sys::UnitsPerRev}, {"_v", Sys::V},
    {"_value", Sys::Value}, {"_value_returned", Sys::ValueReturned}, {"_vmajor", Sys::Vmajor},
    {"_vminor", Sys::Vminor}, {"_w", Sys::W}, {"_x", Sys::X}, {"_y", Sys::Y}, {"_z", Sys::Z},
}};

const SysName* find_system(std::string_view name) noexcept {
  auto it = std::lower_bound(kSystem.begin(), kSystem.end(), name,
                             [](const SysName& s, std::string_view n) { return s.name < n; });
  return (it != kSystem.end() && it->name == name) ? &*it : nullptr;
}

bool is_predefined(std::string_view name) noexcept {
  return find_system(name) != nullptr;
}

}  // namespace

bool ParameterHost::predefined_value(std::string_view name, double& v) const {
  const SysName* s = find_system(name);
  if (s == nullptr) return false;
  const ModalState& m = e_.st_.modal;
  const PositionState& p = e_.st_.position;
  auto b = [](bool x) { return x ? 1.0 : 0.0; };
  switch (s->id) {
    case Sys::Vmajor: v = 2.9; break;
    case Sys::Vminor: v = 0.0; break;
    case Sys::Line:
      v = e_.line_.number;
      break;
    case Sys::MotionMode: v = m.motion; break;
    case Sys::Plane: {
      static constexpr int kCodes[] = {170, 190, 180, 171, 191, 181};
      v = kCodes[static_cast<int>(m.plane)];
      break;
    }
    case Sys::Ccomp: v = m.cutter_comp == CutterComp::Right ? 420 : m.cutter_comp == CutterComp::Left ? 410 : 400; break;
    case Sys::Metric: v = b(m.units == canon::Units::Mm); break;
    case Sys::Imperial: v = b(m.units == canon::Units::Inch); break;
    case Sys::AbsoluteMode: v = b(m.distance == DistanceMode::Absolute); break;
    case Sys::Incremental: v = b(m.distance == DistanceMode::Incremental); break;
    case Sys::InverseTime: v = b(m.feed_mode == canon::FeedMode::InverseTime); break;
    case Sys::UnitsPerMinute: v = b(m.feed_mode == canon::FeedMode::UnitsPerMinute); break;
    case Sys::UnitsPerRev: v = b(m.feed_mode == canon::FeedMode::UnitsPerRevolution); break;
    case Sys::CoordSystem: v = m.coord_system < 7 ? 530 + 10 * m.coord_system : 584 + m.coord_system; break;
    case Sys::ToolOffset: {
      bool any = false;
      for (int i = 0; i < kAxisCount; ++i) any = any || p.tool_offset[i] != 0.0;
      v = b(any);
      break;
    }
    case Sys::RetractRPlane: v = b(m.retract == RetractMode::RPlane); break;
    case Sys::RetractOldZ: v = b(m.retract == RetractMode::OldZ); break;
    case Sys::SpindleRpm: v = b(m.spindle_mode == SpindleMode::Rpm); break;
    case Sys::SpindleCss: v = b(m.spindle_mode == SpindleMode::ConstantSurface); break;
    case Sys::IjkAbsolute: v = b(m.ijk_distance == DistanceMode::Absolute); break;
    case Sys::LatheDiameter: v = b(m.lathe_diameter); break;
    case Sys::LatheRadius: v = b(!m.lathe_diameter); break;
    case Sys::SpindleOn: v = b(m.spindle != canon::SpindleDirection::Stopped); break;
    case Sys::SpindleCw: v = b(m.spindle == canon::SpindleDirection::Clockwise); break;
    case Sys::Mist: v = b(m.mist); break;
    case Sys::Flood: v = b(m.flood); break;
    case Sys::SpeedOverride: v = b(m.speed_override); break;
    case Sys::FeedOverride: v = b(m.feed_override); break;
    case Sys::AdaptiveFeed: v = b(m.adaptive_feed); break;
    case Sys::FeedHold: v = b(m.feed_hold); break;
    case Sys::Feed: v = m.feed_rate; break;
    case Sys::Rpm: v = std::abs(m.spindle_speed); break;
    case Sys::CurrentTool:
      v = e_.st_.tool.table[0].tool;
      break;
    case Sys::CurrentPocket:
      v = e_.mcodes_.pocket_of(e_.st_.tool.current_index);
      break;
    case Sys::SelectedPocket:
      v = e_.mcodes_.pocket_of(e_.st_.tool.selected_index);
      break;
    case Sys::SelectedTool:
      v = e_.st_.tool.selected_tool;
      break;
    case Sys::X: v = p.current[0]; break;
    case Sys::Y: v = p.current[1]; break;
    case Sys::Z: v = p.current[2]; break;
    case Sys::A: v = p.current[3]; break;
    case Sys::B: v = p.current[4]; break;
    case Sys::C: v = p.current[5]; break;
    case Sys::U: v = p.current[6]; break;
    case Sys::V: v = p.current[7]; break;
    case Sys::W: v = p.current[8]; break;
    case Sys::Value:
      v = e_.st_.control.return_value;
      break;
    case Sys::ValueReturned:
      v = b(e_.st_.control.value_returned);
      break;
    case Sys::CallLevel:
      v = static_cast<double>(e_.st_.frames.size() - 1);
      break;
    case Sys::RemapLevel: v = 0; break;
  }
  return true;
}

bool ParameterHost::named_value(std::string_view name, double& value) {
  if (!name.empty() && name.front() == '_') {
    if (predefined_value(name, value)) return true;
    auto it = e_.st_.globals.find(name);
    if (it == e_.st_.globals.end()) return false;
    value = it->second.value;
    return true;
  }
  const auto& locals = e_.st_.frames.back().locals;
  auto it = locals.find(name);
  if (it == locals.end()) return false;
  value = it->second.value;
  return true;
}

void ParameterHost::declare_named(std::string_view name) {
  if (!name.empty() && name.front() == '_') {
    if (is_predefined(name) || e_.st_.globals.find(name) != e_.st_.globals.end()) return;
    e_.st_.globals.emplace(std::string(name), NamedValue{});
    return;
  }
  auto& locals = e_.st_.frames.back().locals;
  if (locals.find(name) == locals.end()) locals.emplace(std::string(name), NamedValue{});
}

void ParameterHost::store_named(const std::string& name, double value) {
  if (is_predefined(name))
    fail(ErrorCode::ParameterReadOnly, "#<{}> is read-only: the interpreter sets it (choose another name)",
         name);
  NamedParameters& scope =
      (!name.empty() && name.front() == '_') ? e_.st_.globals : e_.st_.frames.back().locals;
  NamedValue& v = scope[name];
  v.value = value;
  v.set = true;
}

// Variables the dialect computes (DialectHooks::computed_variable).
bool ParameterHost::computed_variable(int index, double& value) {
  return e_.dialect_.computed_variable != nullptr && e_.dialect_.computed_variable(e_, index, value);
}

void Engine::update_position_parameters() {
  for (int i = 0; i < kAxisCount; ++i) st_.parameters[static_cast<std::size_t>(5420 + i)] = st_.position.current[i];
}

}  // namespace opencnc::gcode
