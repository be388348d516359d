// SPDX-License-Identifier: GPL-3.0-or-later
// Motion: end points (distance modes, G53, polar), straight moves, arcs and helices with
// LinuxCNC's centre and radius rules and tolerances, inverse-time feeds.
#include <algorithm>
#include <cmath>

#include "engine.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {

constexpr long double kPi = 3.141592653589793238462643383279502884L;
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// Arc tolerances (LinuxCNC's defaults): end radius vs start radius, absolute and relative;
// the smallest radius; the slack allowed for a radius-format semicircle.
constexpr double kSpiralToleranceInch = 2 * 0.001 * 1.41421356237309504880;
constexpr double kSpiralToleranceMm = 2 * 0.01 * 1.41421356237309504880;
constexpr double kSpiralRelativeTolerance = 0.001;
constexpr double kRadiusToleranceInch = 0.00005;
constexpr double kRadiusToleranceMm = 0.00005 * 25.4;
constexpr double kTiny = 1e-12;


// Angle in radians swept from (x1,y1) to (x2,y2) about (cx,cy) with LinuxCNC's turn count.
double find_turn(double x1, double y1, double cx, double cy, int turn, double x2, double y2) {
  if (turn == 0) return 0.0;
  const long double two_pi = 2 * kPi;
  double alpha = std::atan2(y1 - cy, x1 - cx);
  double beta = std::atan2(y2 - cy, x2 - cx);
  if (turn > 0) {
    if (beta <= alpha) beta = static_cast<double>(beta + two_pi);
    return static_cast<double>((beta - alpha) + (turn - 1) * two_pi);
  }
  if (alpha <= beta) alpha = static_cast<double>(alpha + two_pi);
  return static_cast<double>((beta - alpha) + (turn + 1) * two_pi);
}

char plane_letter(canon::Plane p, int which) {
  switch (p) {
    case canon::Plane::XY: return which == 0 ? 'X' : 'Y';
    case canon::Plane::XZ: return which == 0 ? 'Z' : 'X';
    case canon::Plane::YZ: return which == 0 ? 'Y' : 'Z';
    default: return '?';
  }
}

}  // namespace

void Engine::rotate(double& x, double& y, double degrees) const noexcept {
  const double t = degrees * kDegToRad;
  const double xx = x * std::cos(t) - y * std::sin(t);
  const double yy = x * std::sin(t) + y * std::cos(t);
  x = xx;
  y = yy;
}

Pose Engine::find_ends(const Block& b) {
  const PositionState& s = st_.position;
  const bool comp = st_.modal.cutter_comp != CutterComp::Off;
  const bool middle = !st_.modal.comp_first_move;
  Pose end = s.current;
  if (b.g[kGroupNonModal] == 530) {
    // Machine coordinates: remove every offset from the words given.
    if (b.radius_flag || b.theta_flag) fail(ErrorCode::PolarCoordinates, "polar coordinates cannot be used with G53");
    double cx = s.current[0] + s.axis_offset[0];
    double cy = s.current[1] + s.axis_offset[1];
    rotate(cx, cy, s.rotation_xy_deg);
    double x = b.has('x') ? b.get('x') - s.origin_offset[0] - s.tool_offset[0] : cx;
    double y = b.has('y') ? b.get('y') - s.origin_offset[1] - s.tool_offset[1] : cy;
    rotate(x, y, -s.rotation_xy_deg);
    end[0] = x - s.axis_offset[0];
    end[1] = y - s.axis_offset[1];
    if (b.has('z')) end[2] = b.get('z') - s.origin_offset[2] - s.axis_offset[2] - s.tool_offset[2];
    for (int i = 3; i < 6; ++i) {   // LinuxCNC leaves the tool offset out on A, B, C here
      if (b.has(kAxisWordLetters[i])) end[i] = b.get(kAxisWordLetters[i]) - s.origin_offset[i] - s.axis_offset[i];
    }
    for (int i = 6; i < 9; ++i) {
      if (b.has(kAxisWordLetters[i]))
        end[i] = b.get(kAxisWordLetters[i]) - s.origin_offset[i] - s.axis_offset[i] - s.tool_offset[i];
    }
    return end;
  }
  const bool xy_plane = st_.modal.plane == canon::Plane::XY;
  const bool xz_plane = st_.modal.plane == canon::Plane::XZ;
  // While compensation runs, unspecified in-plane coordinates continue from the programmed
  // point, not from the compensated tool position.
  const double from_x = comp && middle ? s.programmed[0] : s.current[0];
  const double from_y = comp && middle && xy_plane ? s.programmed[1] : s.current[1];
  const double from_z = comp && middle && xz_plane ? s.programmed[2] : s.current[2];
  if (st_.modal.distance == DistanceMode::Absolute) {
    double x = b.has('x') ? b.get('x') : from_x;
    double y = b.has('y') ? b.get('y') : from_y;
    if (b.radius_flag || b.theta_flag) {
      if (b.has('x') || b.has('y')) fail(ErrorCode::PolarCoordinates, "X or Y word beside a polar coordinate");
      if (b.radius_flag && b.theta_flag) {
        x = b.radius * std::cos(b.theta * kDegToRad);
        y = b.radius * std::sin(b.theta * kDegToRad);
      } else if (b.radius_flag) {
        if (x == 0 && y == 0) fail(ErrorCode::PolarCoordinates, "a polar radius alone needs an angle when at the origin");
        const double t = std::atan2(y, x);
        x = b.radius * std::cos(t);
        y = b.radius * std::sin(t);
      } else {
        const double r = std::hypot(y, x);
        x = r * std::cos(b.theta * kDegToRad);
        y = r * std::sin(b.theta * kDegToRad);
      }
    }
    end[0] = x;
    end[1] = y;
    end[2] = b.has('z') ? b.get('z') : from_z;
    for (int i = 3; i < kAxisCount; ++i) {
      if (b.has(kAxisWordLetters[i])) end[i] = b.get(kAxisWordLetters[i]);
    }
    return end;
  }
  double x = from_x + (b.has('x') ? b.get('x') : 0.0);
  double y = from_y + (b.has('y') ? b.get('y') : 0.0);
  if (b.radius_flag) {
    if (b.has('x') || b.has('y')) fail(ErrorCode::PolarCoordinates, "X or Y word beside a polar coordinate");
    if (x == 0 && y == 0) fail(ErrorCode::PolarCoordinates, "incremental polar motion is undefined at the origin");
    const double t = std::atan2(y, x);
    const double r = std::hypot(y, x) + b.radius;
    x = r * std::cos(t);
    y = r * std::sin(t);
  }
  if (b.theta_flag) {
    if (b.has('x') || b.has('y')) fail(ErrorCode::PolarCoordinates, "X or Y word beside a polar coordinate");
    if (x == 0 && y == 0) fail(ErrorCode::PolarCoordinates, "incremental polar motion is undefined at the origin");
    const double t = std::atan2(y, x) + b.theta * kDegToRad;
    const double r = std::hypot(y, x);
    x = r * std::cos(t);
    y = r * std::sin(t);
  }
  end[0] = x;
  end[1] = y;
  end[2] = from_z + (b.has('z') ? b.get('z') : 0.0);
  for (int i = 3; i < kAxisCount; ++i) {
    if (b.has(kAxisWordLetters[i])) end[i] += b.get(kAxisWordLetters[i]);
  }
  return end;
}

void Engine::convert_motion(int motion) {
  switch (motion) {
    case 0:
    case 10:
      convert_straight(motion);
      return;
    case 20:
    case 30:
      convert_arc(motion);
      return;
    case 800:
      out_.comment("interpreter: motion mode set to none");
      st_.modal.motion = 800;
      return;
    default:
      if (!run_extension_g(motion)) unsupported_g(motion);
  }
}

void Engine::emit_straight(bool rapid, const Pose& end) {
  if (st_.modal.cutter_comp != CutterComp::Off && st_.modal.comp_radius > 0.0 && ext_ != nullptr && ext_->compensator) {
    ext_->compensator->straight(*this, rapid, end);
    return;
  }
  if (rapid) out_.straight_traverse(0, end);
  else out_.straight_feed(0, end);
  st_.position.current = end;
}

void Engine::emit_arc(const canon::ArcFeed& arc) {
  out_.arc_feed(0, arc);
  st_.position.current = arc.end;
}

void Engine::convert_straight(int motion) {
  const Block& b = block_;
  st_.modal.arc_not_allowed = false;
  if (motion == 10) {
    switch (st_.modal.feed_mode) {
      case canon::FeedMode::UnitsPerMinute:
        if (st_.modal.feed_rate == 0.0) fail(ErrorCode::ZeroFeedRate, "G1 with zero feed rate (program an F word)");
        break;
      case canon::FeedMode::UnitsPerRevolution:
        if (st_.modal.feed_rate == 0.0) fail(ErrorCode::ZeroFeedRate, "G1 with zero feed rate (program an F word)");
        if (st_.modal.spindle_speed == 0.0)
          fail(ErrorCode::ZeroSpindleSpeed, "feed per revolution (G95) with zero spindle speed");
        break;
      case canon::FeedMode::InverseTime:
        if (!b.has('f')) fail(ErrorCode::InverseTimeFeedMissing, "G1 in inverse time mode (G93) needs an F word");
        break;
    }
  }
  st_.modal.motion = motion;
  const Pose end = find_ends(b);
  check_motion_habits(motion == 10);
  if (motion == 10) inverse_time_straight(end);
  if (st_.modal.cutter_comp != CutterComp::Off && st_.modal.comp_radius > 0.0 && b.g[kGroupNonModal] == 530)
    fail(ErrorCode::G53Usage, "G53 cannot be used while cutter compensation is on");
  emit_straight(motion == 0, end);
}

void Engine::inverse_time_straight(const Pose& end) {
  if (st_.modal.feed_mode != canon::FeedMode::InverseTime) return;
  const Pose& c = st_.position.current;
  constexpr double tiny = 1e-7;
  auto moved = [&](int a, int b2, int d) {
    return std::fabs(c[a] - end[a]) > tiny || std::fabs(c[b2] - end[b2]) > tiny || std::fabs(c[d] - end[d]) > tiny;
  };
  auto dist = [&](int a, int b2, int d) {
    return std::sqrt(std::pow(end[a] - c[a], 2) + std::pow(end[b2] - c[b2], 2) + std::pow(end[d] - c[d], 2));
  };
  const double length = moved(0, 1, 2) ? dist(0, 1, 2) : moved(6, 7, 8) ? dist(6, 7, 8) : dist(3, 4, 5);
  const double rate = std::max(0.1, length * block_.get('f'));
  out_.set_feed_rate(rate);
  st_.modal.feed_rate = rate;
}

void Engine::inverse_time_arc(double x1, double y1, double z1, double cx, double cy, int turn, double x2, double y2,
                              double z2) {
  if (st_.modal.feed_mode != canon::FeedMode::InverseTime) return;
  const double radius = std::hypot(cx - x1, cy - y1);
  const double theta = find_turn(x1, y1, cx, cy, turn, x2, y2);
  const double length = z2 == z1 ? radius * std::fabs(theta) : std::hypot(radius * theta, z2 - z1);
  const double rate = std::max(0.1, length * block_.get('f'));
  out_.set_feed_rate(rate);
  st_.modal.feed_rate = rate;
}

void Engine::convert_arc(int motion) {
  Block& b = block_;
  const ModalState& m = st_.modal;
  if (m.arc_not_allowed) fail(ErrorCode::ModalContext, "the move right after G40 must be straight, not an arc");
  const bool ijk = b.has('i') || b.has('j') || b.has('k');
  if (m.plane == canon::Plane::UV || m.plane == canon::Plane::VW || m.plane == canon::Plane::UW)
    fail(ErrorCode::ArcPlane, "arcs are not possible in the G17.1, G18.1 and G19.1 planes");
  if (!b.has('r') && !ijk) fail(ErrorCode::ArcFormat, "arc needs an R word or centre offsets (I, J, K)");
  if (b.has('r') && ijk) fail(ErrorCode::ArcFormat, "arc has both R and I/J/K (use one format)");
  switch (m.feed_mode) {
    case canon::FeedMode::UnitsPerMinute:
      if (m.feed_rate == 0.0) fail(ErrorCode::ZeroFeedRate, "arc with zero feed rate (program an F word)");
      break;
    case canon::FeedMode::UnitsPerRevolution:
      if (m.feed_rate == 0.0) fail(ErrorCode::ZeroFeedRate, "arc with zero feed rate (program an F word)");
      if (m.spindle_speed == 0.0) fail(ErrorCode::ZeroSpindleSpeed, "feed per revolution (G95) with zero spindle speed");
      break;
    case canon::FeedMode::InverseTime:
      if (!b.has('f')) fail(ErrorCode::InverseTimeFeedMissing, "arc in inverse time mode (G93) needs an F word");
      break;
  }
  const bool absolute_ijk = m.ijk_distance == DistanceMode::Absolute;
  // Letters of the plane's first and second axis offsets, and the one not allowed.
  char l1 = 'i', l2 = 'j', bad = 'k';
  if (m.plane == canon::Plane::YZ) l1 = 'j', l2 = 'k', bad = 'i';
  if (m.plane == canon::Plane::XZ) l1 = 'i', l2 = 'k', bad = 'j';
  if (ijk) {
    if (b.has(bad))
      fail(ErrorCode::ArcFormat, "{} word in an arc in the {} plane", static_cast<char>(bad - 32),
           m.plane == canon::Plane::XY ? "XY" : m.plane == canon::Plane::YZ ? "YZ" : "XZ");
    for (char need : {l1, l2}) {
      if (b.has(need)) continue;
      if (absolute_ijk) fail(ErrorCode::ArcFormat, "{} word missing in an absolute-centre arc (G90.1)", static_cast<char>(need - 32));
      b.value[static_cast<std::size_t>(need - 'a')] = 0.0;
      break;   // LinuxCNC defaults only the first missing offset
    }
  } else {
    const bool missing = m.plane == canon::Plane::XY   ? !b.has('x') && !b.has('y') && !b.radius_flag && !b.theta_flag
                         : m.plane == canon::Plane::YZ ? !b.has('y') && !b.has('z')
                                                       : !b.has('x') && !b.has('z');
    if (missing) fail(ErrorCode::ArcEndpointMissing, "radius-format arc needs an end point in the plane (full circles need I/J/K)");
  }
  const Pose end = find_ends(b);
  check_motion_habits(true);
  st_.modal.motion = motion;
  // Plane axes: first, second, normal.
  int a1 = 0, a2 = 1, a3 = 2;
  if (m.plane == canon::Plane::XZ) a1 = 2, a2 = 0, a3 = 1;
  if (m.plane == canon::Plane::YZ) a1 = 1, a2 = 2, a3 = 0;
  // Offsets in the plane's axis order (XZ: K then I).
  const double off1 = m.plane == canon::Plane::XZ ? b.get('k') : b.get(l1);
  const double off2 = m.plane == canon::Plane::XZ ? b.get('i') : b.get(l2);
  const Pose& cur = st_.position.current;
  if (st_.modal.cutter_comp != CutterComp::Off && st_.modal.comp_radius > 0.0 && m.plane != canon::Plane::YZ &&
      ext_ != nullptr && ext_->compensator) {
    ext_->compensator->arc(*this, b, motion, end);
    return;
  }
  const int turns = b.has('p') ? round_to_int(b.get('p')) : 1;
  double c1, c2;
  int turn;
  if (b.has('r')) arc_center_r(motion, cur[a1], cur[a2], end[a1], end[a2], b.get('r'), turns, c1, c2, turn);
  else arc_center_ijk(motion, cur[a1], cur[a2], end[a1], end[a2], off1, off2, turns, c1, c2, turn);
  inverse_time_arc(cur[a1], cur[a2], cur[a3], c1, c2, turn, end[a1], end[a2], end[a3]);
  canon::ArcFeed arc;
  arc.plane = m.plane;
  arc.first_end = end[a1];
  arc.second_end = end[a2];
  arc.first_center = c1;
  arc.second_center = c2;
  arc.rotation = turn;
  arc.axis_end = end[a3];
  arc.end = end;
  emit_arc(arc);
}

void Engine::arc_center_ijk(int motion, double cur1, double cur2, double end1, double end2, double off1, double off2,
                            int turns, double& c1, double& c2, int& turn) const {
  const bool inch = st_.modal.units == canon::Units::Inch;
  const double radius_tol = inch ? kRadiusToleranceInch : kRadiusToleranceMm;
  const double spiral_tol = inch ? kSpiralToleranceInch : kSpiralToleranceMm;
  if (st_.modal.ijk_distance == DistanceMode::Absolute) {
    c1 = off1;
    c2 = off2;
  } else {
    c1 = cur1 + off1;
    c2 = cur2 + off2;
  }
  const double r1 = std::hypot(c1 - cur1, c2 - cur2);
  const double r2 = std::hypot(c1 - end1, c2 - end2);
  const canon::Plane p = st_.modal.plane;
  const char a = plane_letter(p, 0), b = plane_letter(p, 1);
  if (r1 < radius_tol || r2 < radius_tol)
    fail(ErrorCode::ArcZeroRadius, "zero-radius arc: start ({}{:.4f}, {}{:.4f}), centre ({}{:.4f}, {}{:.4f})", a, cur1, b,
         cur2, a, c1, b, c2);
  const double abs_err = std::fabs(r1 - r2);
  const double rel_err = abs_err / std::max(r1, r2);
  if (abs_err > spiral_tol && rel_err > kSpiralRelativeTolerance)
    fail(ErrorCode::ArcRadiusMismatch,
         "arc end is not on the circle: start ({}{:.4f}, {}{:.4f}), centre ({}{:.4f}, {}{:.4f}), end ({}{:.4f}, {}{:.4f}); "
         "radius {:.4f} at the start, {:.4f} at the end",
         a, cur1, b, cur2, a, c1, b, c2, a, end1, b, end2, r1, r2);
  turn = motion == 20 ? -turns : turns;
}

void Engine::arc_center_r(int motion, double cur1, double cur2, double end1, double end2, double radius, int turns,
                          double& c1, double& c2, int& turn) const {
  const double tolerance = st_.modal.units == canon::Units::Inch ? kRadiusToleranceInch : kRadiusToleranceMm;
  if (end1 == cur1 && end2 == cur2)
    fail(ErrorCode::ArcSameEndpoint, "radius-format arc ends where it starts (use I/J/K for a full circle)");
  const double abs_radius = std::fabs(radius);
  const double mid1 = (end1 + cur1) / 2.0;
  const double mid2 = (end2 + cur2) / 2.0;
  double half_length = std::hypot(mid1 - end1, mid2 - end2);
  if (half_length - abs_radius > tolerance)
    fail(ErrorCode::ArcRadiusTooSmall, "arc radius {:.4f} is too small to reach the end point (half chord {:.4f})",
         abs_radius, half_length);
  if (half_length / abs_radius > 1 - kTiny) half_length = abs_radius;   // allow a semicircle's rounding
  // The direction is a double; ±π/2 is added in long double and the sum rounded (LinuxCNC's
  // arithmetic, kept so that centres on a coordinate axis come out with the same sign).
  const double dir = std::atan2(end2 - cur2, end1 - cur1);
  const double theta = static_cast<double>(((motion == 20 && radius > 0) || (motion == 30 && radius < 0)) ? dir - kPi / 2
                                                                                                           : dir + kPi / 2);
  const double turn2 = std::asin(half_length / abs_radius);
  const double offset = abs_radius * std::cos(turn2);
  c1 = mid1 + offset * std::cos(theta);
  c2 = mid2 + offset * std::sin(theta);
  turn = motion == 20 ? -turns : turns;
}

}  // namespace opencnc::gcode
