// SPDX-License-Identifier: GPL-3.0-or-later
// The order of execution within a block (LinuxCNC's): comment, spindle and feed modes, F,
// S, T, M codes, G codes by modal group, motion, then stops.

#include "comments.hpp"
#include "engine.hpp"

namespace opencnc::gcode {

void Engine::apply_assignments() {
  // Assignments take effect after the whole line has been read, in line order.
  for (const auto& [index, value] : parser_.numbered_assignments) st_.parameters[static_cast<std::size_t>(index)] = value;
  for (const auto& [name, value] : parser_.named_assignments) params_.store_named(name, value);
}

void Engine::execute_block() {
  const Block& b = block_;
  if (b.has_comment && !b.comment.empty()) convert_comment(b.comment, st_, params_, out_);
  if (b.dollar_flag && (b.g[kGroupSpindleMode] != -1 || b.g[kGroupFeedMode] != -1))
    check_spindle_number(false);
  if (b.g[kGroupSpindleMode] != -1) modes_.set_spindle_mode();
  if (b.g[kGroupFeedMode] != -1) modes_.set_feed_mode(b.g[kGroupFeedMode]);
  if (b.has('f') && st_.modal.feed_mode != canon::FeedMode::InverseTime) {
    st_.modal.feed_rate = b.get('f');
    out_.set_feed_rate(b.get('f'));
  }
  if (b.has('s')) {
    if (b.dollar_flag) check_spindle_number(true);
    out_.set_spindle_speed(0, b.get('s'));
    st_.modal.spindle_speed = b.get('s');
  }
  if (b.has('t')) mcodes_.select_tool(static_cast<int>(b.get('t')));
  if (b.m_count != 0) mcodes_.convert_m();  // tested here: most blocks have none, and a call costs more
  convert_g();
  if (b.m[kGroupStop] != -1) mcodes_.convert_stop();
}

// This machine has spindle 0; $-1 means every spindle where a code can address them all.
void Engine::check_spindle_number(bool all_allowed) const {
  const double d = block_.dollar;
  if (d >= 1 || d < (all_allowed ? -1 : 0))
    fail_at(block_.dollar_at, ErrorCode::SpindleNumber, "${}: this machine has spindle $0 only{}", d,
            all_allowed ? " ($-1 addresses every spindle)" : "");
}

void Engine::convert_g() {
  const Block& b = block_;
  if (b.g[kGroupNonModal] == 40) out_.dwell(b.get('p'));
  if (b.g[kGroupPlane] != -1) modes_.set_plane(b.g[kGroupPlane]);
  if (b.g[kGroupUnits] != -1) offsets_.set_units(b.g[kGroupUnits]);
  if (b.g[kGroupLatheDiameter] != -1) modes_.set_lathe_mode(b.g[kGroupLatheDiameter]);
  if (b.g[kGroupCutterComp] != -1) modes_.set_cutter_comp(b.g[kGroupCutterComp]);
  if (b.g[kGroupToolLength] != -1) offsets_.tool_length_offset(b.g[kGroupToolLength]);
  if (b.g[kGroupCoordSystem] != -1) offsets_.set_coordinate_system(b.g[kGroupCoordSystem]);
  if (b.g[kGroupControl] != -1) modes_.set_control_mode(b.g[kGroupControl]);
  if (b.g[kGroupDistance] != -1) modes_.set_distance_mode(b.g[kGroupDistance]);
  if (b.g[kGroupIjkDistance] != -1) modes_.set_ijk_mode(b.g[kGroupIjkDistance]);
  if (b.g[kGroupRetract] != -1) modes_.set_retract_mode(b.g[kGroupRetract]);
  if (b.extension_groups) convert_extension_groups();
  if (b.g[kGroupNonModal] != -1) offsets_.convert_modal_0(b.g[kGroupNonModal]);
  if (b.motion != -1) motion_.convert_motion(b.motion);
}

// --- extensions ---------------------------------------------------------------------------

// An extension's errors point at its code's word (or, for a modal motion, the first axis word).
bool Engine::run_extension_g(int code) {
  if (ext_ == nullptr || code < 0 || code >= 1000 || !ext_->g[static_cast<std::size_t>(code)]) return false;
  const int group = g_group(code);
  const ExtensionSite site(*this, group >= 0 && block_.g[static_cast<std::size_t>(group)] == code
                                      ? block_.g_position(group)
                                      : block_.first_axis_position());
  ext_->g[static_cast<std::size_t>(code)]->execute(ctx_, block_, code);
  return true;
}

bool Engine::run_extension_m(int code) {
  if (ext_ == nullptr || code < 0 || code >= 200 || !ext_->m[static_cast<std::size_t>(code)]) return false;
  const int group = m_group(code);
  const ExtensionSite site(*this, group >= 0 ? block_.m_position(group) : -1);
  ext_->m[static_cast<std::size_t>(code)]->execute(ctx_, block_, code);
  return true;
}

// Codes of the groups only extensions know (Fanuc mirroring, scaling, rotation), in Fanuc's
// order.
void Engine::convert_extension_groups() {
  for (const int group : {kGroupMirror, kGroupScaling, kGroupRotation}) {
    const int code = block_.g[static_cast<std::size_t>(group)];
    if (code != -1 && !run_extension_g(code)) unsupported_g(code, block_.g_position(group));
  }
}

void Engine::unsupported_g(int code, int at) {
  const char* what = "this G code";
  if (code == 410 || code == 420 || code == 411 || code == 421) what = "cutter radius compensation";
  else if (code == 730 || code == 740 || (code >= 810 && code <= 890)) what = "canned cycles";
  else if (code == 330 || code == 331 || code == 760) what = "spindle-synchronised motion (threading)";
  else if (code >= 382 && code <= 385) what = "probing";
  else if (code >= 50 && code <= 53) what = "splines";
  else if (code >= 700 && code <= 722) what = "lathe cycles";
  fail_at(at, ErrorCode::Unsupported, "{} ({}) is not supported yet", g_name(code), what);
}

}  // namespace opencnc::gcode
