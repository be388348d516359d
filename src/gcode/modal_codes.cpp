// SPDX-License-Identifier: GPL-3.0-or-later
// The modal settings of a block's G and G-like codes: spindle and feed modes, plane, lathe
// diameter mode, cutter compensation off, path control, distance modes, canned cycle return.
#include <cmath>

#include "engine.hpp"

namespace opencnc::gcode {

void ModalCodes::set_spindle_mode() {
  if (e_.block_.g[kGroupSpindleMode] == 970) {
    e_.st_.modal.spindle_mode = SpindleMode::Rpm;
    e_.out_.set_spindle_mode(0, 0);
  } else {
    e_.st_.modal.spindle_mode = SpindleMode::ConstantSurface;
    e_.out_.set_spindle_mode(0, e_.block_.has('d') ? std::fabs(e_.block_.get('d')) : 1e30);
  }
}

void ModalCodes::set_feed_mode(int code) {
  if (code == 930) {
    e_.out_.comment("interpreter: feed mode set to inverse time");
    e_.st_.modal.feed_mode = canon::FeedMode::InverseTime;
    e_.out_.set_feed_mode(0, canon::FeedMode::InverseTime);
    return;
  }
  if (code == 940) {
    e_.out_.comment("interpreter: feed mode set to units per minute");
    e_.st_.modal.feed_mode = canon::FeedMode::UnitsPerMinute;
    e_.out_.set_feed_mode(0, canon::FeedMode::UnitsPerMinute);
  } else {
    e_.out_.comment("interpreter: feed mode set to units per revolution");
    e_.st_.modal.feed_mode = canon::FeedMode::UnitsPerRevolution;
    e_.out_.set_feed_mode(0, canon::FeedMode::UnitsPerRevolution);
  }
  e_.st_.modal.feed_rate = 0;
  e_.out_.set_feed_rate(0);
}

void ModalCodes::set_plane(int code) {
  const bool comp = e_.st_.modal.cutter_comp != CutterComp::Off;
  const canon::Plane p = e_.st_.modal.plane;
  const int at = e_.block_.g_position(kGroupPlane);
  if (comp && ((code == 170 && p != canon::Plane::XY) || (code == 180 && p != canon::Plane::XZ) ||
               (code == 190 && p != canon::Plane::YZ)))
    fail_at(at, ErrorCode::CompPlaneChange,
            "{} cannot change the plane while cutter compensation is on: G40 first", g_name(code));
  if (comp && code == 190)
    fail_at(at, ErrorCode::CompYzPlane,
            "cutter compensation works in the XY and XZ planes only, not in G19 (YZ)");
  canon::Plane plane = canon::Plane::XY;
  switch (code) {
    case 170:
      plane = canon::Plane::XY;
      break;
    case 180:
      plane = canon::Plane::XZ;
      break;
    case 190:
      plane = canon::Plane::YZ;
      break;
    case 171:
      plane = canon::Plane::UV;
      break;
    case 181:
      plane = canon::Plane::UW;
      break;
    case 191:
      plane = canon::Plane::VW;
      break;
    default:
      break;
  }
  e_.out_.select_plane(plane);
  e_.st_.modal.plane = plane;
}

void ModalCodes::set_lathe_mode(int code) {
  if (code == 70 && !e_.st_.modal.lathe_diameter) {
    // The X word was read as a radius: apply the diameter mode from this block on.
    if (e_.block_.has('x')) e_.block_.value['x' - 'a'] /= 2.0;
    e_.out_.comment("interpreter: Lathe diameter mode changed to diameter");
    e_.st_.modal.lathe_diameter = true;
  } else if (code == 80 && e_.st_.modal.lathe_diameter) {
    if (e_.block_.has('x')) e_.block_.value['x' - 'a'] *= 2.0;
    e_.out_.comment("interpreter: Lathe diameter mode changed to radius");
    e_.st_.modal.lathe_diameter = false;
  }
}

void ModalCodes::set_cutter_comp(int code) {
  if (code == 400) {
    if (e_.run_extension_g(code)) return;  // the compensation module ends its own moves
    e_.out_.comment("interpreter: cutter radius compensation off");
    if (e_.st_.modal.cutter_comp != CutterComp::Off && e_.ext_ != nullptr && e_.ext_->compensator) {
      const Engine::ExtensionSite site(e_, e_.block_.g_position(kGroupCutterComp));
      e_.ext_->compensator->finish(e_.ctx_);
    }
    e_.st_.modal.cutter_comp = CutterComp::Off;
    e_.st_.modal.comp_first_move = true;
    return;
  }
  if (!e_.run_extension_g(code)) e_.unsupported_g(code, e_.block_.g_position(kGroupCutterComp));
}

void ModalCodes::set_control_mode(int code) {
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(e_.block_.g_position(kGroupControl), ErrorCode::CompControlMode,
            "{} cannot change the path control mode while cutter compensation is on: G40 first",
            g_name(code));
  if (code == 610) {
    e_.out_.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
    e_.st_.modal.control = canon::MotionControl::ExactPath;
  } else if (code == 611) {
    e_.out_.set_motion_control_mode(canon::MotionControl::ExactStop, 0);
    e_.st_.modal.control = canon::MotionControl::ExactStop;
  } else {
    const double tolerance = e_.block_.p_or(-1.0);
    const double naive = e_.block_.q_or(-1.0);
    e_.out_.set_motion_control_mode(canon::MotionControl::Continuous, tolerance >= 0 ? tolerance : 0);
    const double naive_used = naive >= 0 ? naive : (tolerance >= 0 ? tolerance : 0);
    e_.out_.set_naivecam_tolerance(naive_used);
    e_.st_.modal.control = canon::MotionControl::Continuous;
    e_.st_.modal.path_tolerance = tolerance >= 0 ? tolerance : 0;
    e_.st_.modal.naivecam_tolerance = naive_used;
  }
}

void ModalCodes::set_distance_mode(int code) {
  const DistanceMode want = code == 900 ? DistanceMode::Absolute : DistanceMode::Incremental;
  if (e_.st_.modal.distance == want) return;
  e_.out_.comment(want == DistanceMode::Absolute ? "interpreter: distance mode changed to absolute"
                                                 : "interpreter: distance mode changed to incremental");
  e_.st_.modal.distance = want;
}

void ModalCodes::set_ijk_mode(int code) {
  const DistanceMode want = code == 901 ? DistanceMode::Absolute : DistanceMode::Incremental;
  if (e_.st_.modal.ijk_distance == want) return;
  e_.out_.comment(want == DistanceMode::Absolute ? "interpreter: IJK distance mode changed to absolute"
                                                 : "interpreter: IJK distance mode changed to incremental");
  e_.st_.modal.ijk_distance = want;
}

void ModalCodes::set_retract_mode(int code) {
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(e_.block_.g_position(kGroupRetract), ErrorCode::CompRetractMode,
            "{} cannot change the canned cycle return mode while cutter compensation is on: G40 first",
            g_name(code));
  if (code == 980) {
    e_.out_.comment("interpreter: retract mode set to old_z");
    e_.st_.modal.retract = RetractMode::OldZ;
  } else {
    e_.out_.comment("interpreter: retract mode set to r_plane");
    e_.st_.modal.retract = RetractMode::RPlane;
  }
}

}  // namespace opencnc::gcode
