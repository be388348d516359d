// SPDX-License-Identifier: GPL-3.0-or-later
// The order of execution within a block (LinuxCNC's): comment, spindle and feed modes, F,
// S, T, M codes, G codes by modal group, motion, then stops.
#include <cmath>

#include "engine.hpp"

namespace opencnc::gcode {

void Engine::apply_assignments() {
  // Assignments take effect after the whole line has been read, in line order.
  for (const auto& [index, value] : parser_.numbered_assignments) st_.parameters[static_cast<std::size_t>(index)] = value;
  for (const auto& [name, value] : parser_.named_assignments) store_named(name, value);
}

void Engine::execute_block() {
  const Block& b = block_;
  if (b.has_comment && !b.comment.empty()) convert_comment(b.comment);
  if (b.dollar_flag && (b.g[kGroupSpindleMode] != -1 || b.g[kGroupFeedMode] != -1) &&
      (b.dollar < 0 || b.dollar >= 1))
    fail(ErrorCode::SpindleUsage, "spindle ${} does not exist (this machine has spindle 0)", b.dollar);
  if (b.g[kGroupSpindleMode] != -1) set_spindle_mode();
  if (b.g[kGroupFeedMode] != -1) set_feed_mode(b.g[kGroupFeedMode]);
  if (b.has('f') && st_.modal.feed_mode != canon::FeedMode::InverseTime) {
    st_.modal.feed_rate = b.get('f');
    out_.set_feed_rate(b.get('f'));
  }
  if (b.has('s')) {
    if (b.dollar_flag && (b.dollar < -1 || b.dollar >= 1))
      fail(ErrorCode::SpindleUsage, "spindle ${} does not exist (this machine has spindle 0)", b.dollar);
    out_.set_spindle_speed(0, b.get('s'));
    st_.modal.spindle_speed = b.get('s');
  }
  if (b.has('t')) select_tool(static_cast<int>(b.get('t')));
  convert_m();
  convert_g();
  if (b.m[kGroupStop] != -1) convert_stop();
}

void Engine::convert_m() {
  if (block_.m_count == 0) return;
  convert_io();
  convert_tool_change_group();
  convert_spindle_group();
  convert_coolant();
  convert_overrides();
  if (const int m = block_.m[kGroupUser]; m != -1 && !run_extension_m(m))
    fail(ErrorCode::UnknownMCode, "M{} is not defined (no user M code of that number)", m);
}

void Engine::convert_g() {
  const Block& b = block_;
  if (b.g[kGroupNonModal] == 40) out_.dwell(b.get('p'));
  if (b.g[kGroupPlane] != -1) set_plane(b.g[kGroupPlane]);
  if (b.g[kGroupUnits] != -1) set_units(b.g[kGroupUnits]);
  if (b.g[kGroupLatheDiameter] != -1) set_lathe_mode(b.g[kGroupLatheDiameter]);
  if (b.g[kGroupCutterComp] != -1) set_cutter_comp(b.g[kGroupCutterComp]);
  if (b.g[kGroupToolLength] != -1) tool_length_offset(b.g[kGroupToolLength]);
  if (b.g[kGroupCoordSystem] != -1) set_coordinate_system(b.g[kGroupCoordSystem]);
  if (b.g[kGroupControl] != -1) set_control_mode(b.g[kGroupControl]);
  if (b.g[kGroupDistance] != -1) set_distance_mode(b.g[kGroupDistance]);
  if (b.g[kGroupIjkDistance] != -1) set_ijk_mode(b.g[kGroupIjkDistance]);
  if (b.g[kGroupRetract] != -1) set_retract_mode(b.g[kGroupRetract]);
  if (b.g[kGroupNonModal] != -1) convert_modal_0(b.g[kGroupNonModal]);
  if (b.motion != -1) convert_motion(b.motion);
}

// --- modal settings ---------------------------------------------------------------------

void Engine::set_spindle_mode() {
  if (block_.g[kGroupSpindleMode] == 970) {
    st_.modal.spindle_mode = SpindleMode::Rpm;
    out_.set_spindle_mode(0, 0);
  } else {
    st_.modal.spindle_mode = SpindleMode::ConstantSurface;
    out_.set_spindle_mode(0, block_.has('d') ? std::fabs(block_.get('d')) : 1e30);
  }
}

void Engine::set_feed_mode(int code) {
  if (code == 930) {
    out_.comment("interpreter: feed mode set to inverse time");
    st_.modal.feed_mode = canon::FeedMode::InverseTime;
    out_.set_feed_mode(0, canon::FeedMode::InverseTime);
    return;
  }
  if (code == 940) {
    out_.comment("interpreter: feed mode set to units per minute");
    st_.modal.feed_mode = canon::FeedMode::UnitsPerMinute;
    out_.set_feed_mode(0, canon::FeedMode::UnitsPerMinute);
  } else {
    out_.comment("interpreter: feed mode set to units per revolution");
    st_.modal.feed_mode = canon::FeedMode::UnitsPerRevolution;
    out_.set_feed_mode(0, canon::FeedMode::UnitsPerRevolution);
  }
  st_.modal.feed_rate = 0;
  out_.set_feed_rate(0);
}

void Engine::set_plane(int code) {
  const bool comp = st_.modal.cutter_comp != CutterComp::Off;
  const canon::Plane p = st_.modal.plane;
  if (comp && ((code == 170 && p != canon::Plane::XY) || (code == 180 && p != canon::Plane::XZ) ||
               (code == 190 && p != canon::Plane::YZ)))
    fail(ErrorCode::ModalContext, "the plane cannot change while cutter compensation is on");
  if (comp && code == 190) fail(ErrorCode::ModalContext, "cutter compensation works only in the XY and XZ planes");
  canon::Plane plane = canon::Plane::XY;
  switch (code) {
    case 170: plane = canon::Plane::XY; break;
    case 180: plane = canon::Plane::XZ; break;
    case 190: plane = canon::Plane::YZ; break;
    case 171: plane = canon::Plane::UV; break;
    case 181: plane = canon::Plane::UW; break;
    case 191: plane = canon::Plane::VW; break;
    default: break;
  }
  out_.select_plane(plane);
  st_.modal.plane = plane;
}

void Engine::set_lathe_mode(int code) {
  if (code == 70 && !st_.modal.lathe_diameter) {
    // The X word was read as a radius: apply the diameter mode from this block on.
    if (block_.has('x')) block_.value['x' - 'a'] /= 2.0;
    out_.comment("interpreter: Lathe diameter mode changed to diameter");
    st_.modal.lathe_diameter = true;
  } else if (code == 80 && st_.modal.lathe_diameter) {
    if (block_.has('x')) block_.value['x' - 'a'] *= 2.0;
    out_.comment("interpreter: Lathe diameter mode changed to radius");
    st_.modal.lathe_diameter = false;
  }
}

void Engine::set_cutter_comp(int code) {
  if (code == 400) {
    out_.comment("interpreter: cutter radius compensation off");
    if (st_.modal.cutter_comp != CutterComp::Off && ext_ != nullptr && ext_->compensator) {
      ext_->compensator->finish(*this);
    }
    st_.modal.cutter_comp = CutterComp::Off;
    st_.modal.comp_first_move = true;
    return;
  }
  if (!run_extension_g(code)) unsupported_g(code);
}

void Engine::set_control_mode(int code) {
  if (st_.modal.cutter_comp != CutterComp::Off)
    fail(ErrorCode::ModalContext, "the path control mode cannot change while cutter compensation is on");
  if (code == 610) {
    out_.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
    st_.modal.control = canon::MotionControl::ExactPath;
  } else if (code == 611) {
    out_.set_motion_control_mode(canon::MotionControl::ExactStop, 0);
    st_.modal.control = canon::MotionControl::ExactStop;
  } else {
    const double tolerance = block_.p_or(-1.0);
    const double naive = block_.q_or(-1.0);
    out_.set_motion_control_mode(canon::MotionControl::Continuous, tolerance >= 0 ? tolerance : 0);
    const double naive_used = naive >= 0 ? naive : (tolerance >= 0 ? tolerance : 0);
    out_.set_naivecam_tolerance(naive_used);
    st_.modal.control = canon::MotionControl::Continuous;
    st_.modal.path_tolerance = tolerance >= 0 ? tolerance : 0;
    st_.modal.naivecam_tolerance = naive_used;
  }
}

void Engine::set_distance_mode(int code) {
  const DistanceMode want = code == 900 ? DistanceMode::Absolute : DistanceMode::Incremental;
  if (st_.modal.distance == want) return;
  out_.comment(want == DistanceMode::Absolute ? "interpreter: distance mode changed to absolute"
                                              : "interpreter: distance mode changed to incremental");
  st_.modal.distance = want;
}

void Engine::set_ijk_mode(int code) {
  const DistanceMode want = code == 901 ? DistanceMode::Absolute : DistanceMode::Incremental;
  if (st_.modal.ijk_distance == want) return;
  out_.comment(want == DistanceMode::Absolute ? "interpreter: IJK distance mode changed to absolute"
                                              : "interpreter: IJK distance mode changed to incremental");
  st_.modal.ijk_distance = want;
}

void Engine::set_retract_mode(int code) {
  if (st_.modal.cutter_comp != CutterComp::Off)
    fail(ErrorCode::ModalContext, "the retract mode cannot change while cutter compensation is on");
  if (code == 980) {
    out_.comment("interpreter: retract mode set to old_z");
    st_.modal.retract = RetractMode::OldZ;
  } else {
    out_.comment("interpreter: retract mode set to r_plane");
    st_.modal.retract = RetractMode::RPlane;
  }
}

// --- extensions ---------------------------------------------------------------------------

bool Engine::run_extension_g(int code) {
  if (ext_ == nullptr || code < 0 || code >= 1000 || !ext_->g[static_cast<std::size_t>(code)]) return false;
  ext_->g[static_cast<std::size_t>(code)]->execute(*this, block_, code);
  return true;
}

bool Engine::run_extension_m(int code) {
  if (ext_ == nullptr || code < 0 || code >= 200 || !ext_->m[static_cast<std::size_t>(code)]) return false;
  ext_->m[static_cast<std::size_t>(code)]->execute(*this, block_, code);
  return true;
}

void Engine::unsupported_g(int code) {
  const char* what = "this G code";
  if (code == 410 || code == 420 || code == 411 || code == 421) what = "cutter radius compensation";
  else if (code == 730 || code == 740 || (code >= 810 && code <= 890)) what = "canned cycles";
  else if (code == 330 || code == 331 || code == 760) what = "spindle-synchronised motion (threading)";
  else if (code >= 382 && code <= 385) what = "probing";
  else if (code >= 50 && code <= 53) what = "splines";
  else if (code >= 700 && code <= 722) what = "lathe cycles";
  if (code % 10) fail(ErrorCode::Unsupported, "G{}.{} ({}) is not supported yet", code / 10, code % 10, what);
  fail(ErrorCode::Unsupported, "G{} ({}) is not supported yet", code / 10, what);
}

}  // namespace opencnc::gcode
