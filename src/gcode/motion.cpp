// SPDX-License-Identifier: GPL-3.0-or-later
// Motion: end points (distance modes, G53, polar), straight moves, arcs and helices with
// LinuxCNC's centre and radius rules and tolerances, inverse-time feeds.
#include <algorithm>
#include <cmath>

#include "arc_math.hpp"
#include "engine.hpp"
#include "numeric.hpp"
#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::gcode {

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// Arc tolerances (LinuxCNC's defaults): end radius vs start radius, relative (the absolute
// ones are in arc_math.hpp); the smallest radius; the slack allowed for a radius-format
// semicircle.
constexpr double kSpiralRelativeTolerance = 0.001;
constexpr double kRadiusToleranceInch = 0.00005;
constexpr double kRadiusToleranceMm = 0.00005 * 25.4;
constexpr double kTiny = 1e-12;
// A B C U V W: most blocks have none of them, and find_ends then skips their loop.
constexpr std::uint32_t kOtherAxisWordBits =
    Block::kAxisWordBits & ~((1u << ('x' - 'a')) | (1u << ('y' - 'a')) | (1u << ('z' - 'a')));


// The first centre offset word (I, J or K) of an arc, -1 if none.
int first_offset_position(const Block& b) noexcept {
  int first = -1;
  for (char c : {'i', 'j', 'k'}) {
    const int p = b.word_position(c);
    if (p != -1 && (first == -1 || p < first)) first = p;
  }
  return first;
}

char plane_letter(canon::Plane p, int which) {
  if (canon::plane_base(p) != 0) return '?';
  const canon::PlaneAxes axes = canon::plane_axes(p);
  return kAxisLetters[static_cast<std::size_t>(which == 0 ? axes.first : axes.second)];
}

}  // namespace

void rotate_xy(double& x, double& y, double degrees) noexcept {
  const double t = degrees * kDegToRad;
  const double xx = x * std::cos(t) - y * std::sin(t);
  const double yy = x * std::sin(t) + y * std::cos(t);
  x = xx;
  y = yy;
}

// Habits of a program that LinuxCNC accepts but a preflight should point out (once each).
// Called on every move until nothing is left to be told (habits_settled_).
void MotionCodes::check_habits(bool feed) {
  const bool units_settled = warned_units_ || e_.offsets_.units_programmed();
  // Both only ever become true: once they are, no move can be warned about again.
  habits_settled_ = units_settled && (warned_spindle_ || !e_.opt_.spindle);
  const bool units = !units_settled;
  const bool spindle =
      feed && !warned_spindle_ && e_.opt_.spindle && e_.st_.modal.spindle == canon::SpindleDirection::Stopped;
  if (!units && !spindle) return;
  if (e_.mdi_.active) return;
  if (units)
    e_.warn_once(warned_units_, ErrorCode::UnitsNotProgrammed,
                 "motion before any G20/G21: the program relies on the machine's default units");
  if (spindle)
    e_.warn_once(warned_spindle_, ErrorCode::FeedWithSpindleStopped,
                 "feed move while the spindle is stopped");
}

void MotionCodes::polar_with_xy(const Block& b) {
  const char letter = b.has('x') ? 'x' : 'y';
  fail_at(b.word_position(letter), ErrorCode::PolarWithXy,
          "{} word beside a polar coordinate: give the point either as @ and ^ or as X and Y",
          letter == 'x' ? 'X' : 'Y');
}

void MotionCodes::polar_at_origin(const Block& b) {
  fail_at(
      b.polar_position(), ErrorCode::PolarAtOrigin,
      "incremental polar motion (G91) from the origin: the direction is undefined there, move off it first");
}

Pose MotionCodes::find_ends(const Block& b) {
  const PositionState& s = e_.st_.position;
  const bool comp = e_.st_.modal.cutter_comp != CutterComp::Off;
  const bool middle = !e_.st_.modal.comp_first_move;
  Pose end = s.current;
  if (b.g[kGroupNonModal] == 530) {
    // Machine coordinates: remove every offset from the words given.
    if (b.radius_flag || b.theta_flag)
      fail_at(b.polar_position(), ErrorCode::PolarWithG53,
              "polar coordinates (@ ^) cannot be used with G53: give X and Y");
    double cx = s.current[0] + s.axis_offset[0];
    double cy = s.current[1] + s.axis_offset[1];
    rotate_xy(cx, cy, s.rotation_xy_deg);
    double x = b.has('x') ? b.get('x') - s.origin_offset[0] - s.tool_offset[0] : cx;
    double y = b.has('y') ? b.get('y') - s.origin_offset[1] - s.tool_offset[1] : cy;
    rotate_xy(x, y, -s.rotation_xy_deg);
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
  const bool xy_plane = e_.st_.modal.plane == canon::Plane::XY;
  const bool xz_plane = e_.st_.modal.plane == canon::Plane::XZ;
  // While compensation runs, unspecified in-plane coordinates continue from the programmed
  // point, not from the compensated tool position.
  const double from_x = comp && middle ? s.programmed[0] : s.current[0];
  const double from_y = comp && middle && xy_plane ? s.programmed[1] : s.current[1];
  const double from_z = comp && middle && xz_plane ? s.programmed[2] : s.current[2];
  if (e_.st_.modal.distance == DistanceMode::Absolute) {
    double x = b.has('x') ? b.get('x') : from_x;
    double y = b.has('y') ? b.get('y') : from_y;
    if (b.radius_flag || b.theta_flag) {
      if (b.has('x') || b.has('y')) polar_with_xy(b);
      if (b.radius_flag && b.theta_flag) {
        x = b.radius * std::cos(b.theta * kDegToRad);
        y = b.radius * std::sin(b.theta * kDegToRad);
      } else if (b.radius_flag) {
        if (x == 0 && y == 0)
          fail_at(b.radius_at, ErrorCode::PolarAtOrigin,
                  "a polar radius @ without an angle ^ at the origin: the direction is undefined");
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
    if ((b.words & kOtherAxisWordBits) == 0) return end;
    for (int i = 3; i < kAxisCount; ++i) {
      if (b.has(kAxisWordLetters[i])) end[i] = b.get(kAxisWordLetters[i]);
    }
    return end;
  }
  double x = from_x + (b.has('x') ? b.get('x') : 0.0);
  double y = from_y + (b.has('y') ? b.get('y') : 0.0);
  if (b.radius_flag) {
    if (b.has('x') || b.has('y')) polar_with_xy(b);
    if (x == 0 && y == 0) polar_at_origin(b);
    const double t = std::atan2(y, x);
    const double r = std::hypot(y, x) + b.radius;
    x = r * std::cos(t);
    y = r * std::sin(t);
  }
  if (b.theta_flag) {
    if (b.has('x') || b.has('y')) polar_with_xy(b);
    if (x == 0 && y == 0) polar_at_origin(b);
    const double t = std::atan2(y, x) + b.theta * kDegToRad;
    const double r = std::hypot(y, x);
    x = r * std::cos(t);
    y = r * std::sin(t);
  }
  end[0] = x;
  end[1] = y;
  end[2] = from_z + (b.has('z') ? b.get('z') : 0.0);
  if ((b.words & kOtherAxisWordBits) == 0) return end;
  for (int i = 3; i < kAxisCount; ++i) {
    if (b.has(kAxisWordLetters[i])) end[i] += b.get(kAxisWordLetters[i]);
  }
  return end;
}

void MotionCodes::convert_motion(int motion) {
  // A run of canned-cycle blocks keeps its initial level until a block moves otherwise.
  const bool cycle = motion == 730 || motion == 740 || (motion >= 810 && motion <= 890);
  if (!cycle) e_.st_.cycle.initial_level_valid = false;
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
      e_.out_.comment("interpreter: motion mode set to none");
      e_.st_.modal.motion = 800;
      return;
    default:
      if (!e_.run_extension_g(motion)) e_.unsupported_g(motion, e_.block_.motion_position());
  }
}

void MotionCodes::emit_straight(bool rapid, const Pose& end) {
  if (e_.st_.modal.cutter_comp != CutterComp::Off && e_.st_.modal.comp_radius > 0.0 && e_.ext_ != nullptr &&
      e_.ext_->compensator) {
    const Engine::ExtensionSite site(e_, e_.block_.motion_position());
    e_.ext_->compensator->straight(e_.ctx_, rapid, end);
    return;
  }
  if (rapid) e_.out_.straight_traverse(0, end);
  else e_.out_.straight_feed(0, end);
  e_.st_.position.current = end;
}

void MotionCodes::emit_arc(const canon::ArcFeed& arc) {
  e_.out_.arc_feed(0, arc);
  e_.st_.position.current = arc.end;
}

void MotionCodes::convert_straight(int motion) {
  const Block& b = e_.block_;
  e_.st_.modal.arc_not_allowed = false;
  if (motion == 10) check_feed("G1");
  e_.st_.modal.motion = motion;
  const Pose end = find_ends(b);
  if (!habits_settled_) check_habits(motion == 10);
  if (motion == 10 && e_.st_.modal.feed_mode == canon::FeedMode::InverseTime) inverse_time_straight(end);
  if (e_.st_.modal.cutter_comp != CutterComp::Off && e_.st_.modal.comp_radius > 0.0 &&
      b.g[kGroupNonModal] == 530)
    fail_at(b.g_position(kGroupNonModal), ErrorCode::CompG53,
            "G53 cannot be used while cutter compensation is on: G40 first");
  emit_straight(motion == 0, end);
}

// A feed move needs a feed rate in its feed mode (and a turning spindle per revolution).
void MotionCodes::check_feed(std::string_view what) const {
  const int at = e_.block_.motion_position();
  switch (e_.st_.modal.feed_mode) {
    case canon::FeedMode::UnitsPerMinute:
      if (e_.st_.modal.feed_rate == 0.0)
        fail_at(at, ErrorCode::FeedZero, "{} needs a feed rate, and none is set: program an F word", what);
      break;
    case canon::FeedMode::UnitsPerRevolution:
      if (e_.st_.modal.feed_rate == 0.0)
        fail_at(at, ErrorCode::FeedZero,
                "{} in feed per revolution (G95) needs a feed rate, and none is set: program an F word",
                what);
      if (e_.st_.modal.spindle_speed == 0.0)
        fail_at(at, ErrorCode::SpindleSpeedZero,
                "{} in feed per revolution (G95) with the spindle speed at 0: program an S word", what);
      // rs274 only checks the speed; on the machine LinuxCNC's motion then waits for the
      // revolutions for ever, without a word. A preflight must say so.
      if (e_.st_.modal.spindle == canon::SpindleDirection::Stopped)
        fail_at(at, ErrorCode::SpindleStopped,
                "{} in feed per revolution (G95) with the spindle stopped: start it with M3 or M4 first "
                "(the move would wait for revolutions for ever)",
                what);
      break;
    case canon::FeedMode::InverseTime:
      if (!e_.block_.has('f'))
        fail_at(at, ErrorCode::InverseTimeFeedMissing,
                "{} in inverse time mode (G93) needs its own F word on this line", what);
      break;
  }
}

// G93 only (the caller tests the mode).
void MotionCodes::inverse_time_straight(const Pose& end) {
  // While compensation runs, the length is the programmed one (LinuxCNC's rule).
  Pose c = e_.st_.position.current;
  if (e_.st_.modal.cutter_comp != CutterComp::Off && e_.st_.modal.comp_radius > 0.0 &&
      !e_.st_.modal.comp_first_move) {
    for (int i = 0; i < 3; ++i) c[i] = e_.st_.position.programmed[static_cast<std::size_t>(i)];
  }
  constexpr double tiny = 1e-7;
  auto moved = [&](int a, int b2, int d) {
    return std::fabs(c[a] - end[a]) > tiny || std::fabs(c[b2] - end[b2]) > tiny || std::fabs(c[d] - end[d]) > tiny;
  };
  auto dist = [&](int a, int b2, int d) {
    return std::sqrt(std::pow(end[a] - c[a], 2) + std::pow(end[b2] - c[b2], 2) + std::pow(end[d] - c[d], 2));
  };
  const double length = moved(0, 1, 2) ? dist(0, 1, 2) : moved(6, 7, 8) ? dist(6, 7, 8) : dist(3, 4, 5);
  const double rate = std::max(0.1, length * e_.block_.get('f'));
  e_.out_.set_feed_rate(rate);
  e_.st_.modal.feed_rate = rate;
}

void MotionCodes::inverse_time_arc(double x1, double y1, double z1, double cx, double cy, int turn, double x2,
                                   double y2, double z2) {
  if (e_.st_.modal.feed_mode != canon::FeedMode::InverseTime) return;
  const double radius = std::hypot(cx - x1, cy - y1);
  const double theta = find_turn(x1, y1, cx, cy, turn, x2, y2);
  const double length = z2 == z1 ? radius * std::fabs(theta) : std::hypot(radius * theta, z2 - z1);
  const double rate = std::max(0.1, length * e_.block_.get('f'));
  e_.out_.set_feed_rate(rate);
  e_.st_.modal.feed_rate = rate;
}

void MotionCodes::convert_arc(int motion) {
  Block& b = e_.block_;
  const ModalState& m = e_.st_.modal;
  const int at = b.motion_position();
  const std::string name = g_name(motion);
  if (m.arc_not_allowed)
    fail_at(at, ErrorCode::CompExitArc,
            "the move right after G40 must be a straight line, not an arc: add a G1 move first");
  const bool ijk = b.has('i') || b.has('j') || b.has('k');
  if (m.plane == canon::Plane::UV || m.plane == canon::Plane::VW || m.plane == canon::Plane::UW)
    fail_at(at, ErrorCode::ArcUvwPlane,
            "{} in the {} plane: arcs are possible only in the XY, XZ and YZ planes (G17, G18, G19)", name,
            canon::plane_name(m.plane));
  if (!b.has('r') && !ijk)
    fail_at(at, ErrorCode::ArcCentreMissing, "{} needs either R (the radius) or I/J/K (the centre offsets)",
            name);
  if (b.has('r') && ijk)
    fail_at(b.word_position('r'), ErrorCode::ArcMixedFormat,
            "R together with I/J/K: give an arc either its radius or its centre, not both");
  check_feed(name);
  const bool absolute_ijk = m.ijk_distance == DistanceMode::Absolute;
  // Letters of the plane's first and second axis offsets, and the one not allowed.
  char l1 = 'i', l2 = 'j', bad = 'k';
  if (m.plane == canon::Plane::YZ) l1 = 'j', l2 = 'k', bad = 'i';
  if (m.plane == canon::Plane::XZ) l1 = 'i', l2 = 'k', bad = 'j';
  if (ijk) {
    if (b.has(bad))
      fail_at(b.word_position(bad), ErrorCode::ArcOffsetWrongPlane,
              "{} word in an arc of the {} plane: its centre offsets are {} and {}",
              static_cast<char>(bad - 32), canon::plane_name(m.plane), static_cast<char>(l1 - 32),
              static_cast<char>(l2 - 32));
    for (char need : {l1, l2}) {
      if (b.has(need)) continue;
      if (absolute_ijk)
        fail_at(at, ErrorCode::ArcCentreIncomplete,
                "{} without {}: with absolute arc centres (G90.1) both {} and {} are needed", name,
                static_cast<char>(need - 32), static_cast<char>(l1 - 32), static_cast<char>(l2 - 32));
      b.value[static_cast<std::size_t>(need - 'a')] = 0.0;
      break;   // LinuxCNC defaults only the first missing offset
    }
  } else {
    const bool missing = m.plane == canon::Plane::XY   ? !b.has('x') && !b.has('y') && !b.radius_flag && !b.theta_flag
                         : m.plane == canon::Plane::YZ ? !b.has('y') && !b.has('z')
                                                       : !b.has('x') && !b.has('z');
    if (missing)
      fail_at(at, ErrorCode::ArcEndpointMissing,
              "{} with R but no end point in the {} plane: give the end point (a full circle needs I/J/K)",
              name, canon::plane_name(m.plane));
  }
  const Pose end = find_ends(b);
  if (!habits_settled_) check_habits(true);
  e_.st_.modal.motion = motion;
  // Plane axes: first, second, normal.
  int a1 = 0, a2 = 1, a3 = 2;
  if (m.plane == canon::Plane::XZ) a1 = 2, a2 = 0, a3 = 1;
  if (m.plane == canon::Plane::YZ) a1 = 1, a2 = 2, a3 = 0;
  if (e_.st_.modal.cutter_comp != CutterComp::Off && e_.st_.modal.comp_radius > 0.0 &&
      m.plane != canon::Plane::YZ && e_.ext_ != nullptr && e_.ext_->compensator) {
    const Engine::ExtensionSite site(e_, at);
    e_.ext_->compensator->arc(e_.ctx_, b, motion, end);
    return;
  }
  const ArcCentre c = e_.ctx_.arc_centre(b, motion, e_.st_.position.current, end);
  canon::ArcFeed arc;
  arc.plane = m.plane;
  arc.first_end = end[a1];
  arc.second_end = end[a2];
  arc.first_center = c.first;
  arc.second_center = c.second;
  arc.rotation = c.turn;
  arc.axis_end = end[a3];
  arc.end = end;
  emit_arc(arc);
}

ArcCentre ExtensionContext::arc_centre(const Block& b, int motion, const Pose& start, const Pose& end) {
  const canon::Plane p = e_.st_.modal.plane;
  // Plane axes (first, second, normal) and the centre offsets in that order (XZ: K then I).
  int a1 = 0, a2 = 1, a3 = 2;
  double off1 = b.get('i'), off2 = b.get('j');
  if (p == canon::Plane::XZ) a1 = 2, a2 = 0, a3 = 1, off1 = b.get('k'), off2 = b.get('i');
  if (p == canon::Plane::YZ) a1 = 1, a2 = 2, a3 = 0, off1 = b.get('j'), off2 = b.get('k');
  const int turns = b.has('p') ? round_to_int(b.get('p')) : 1;
  ArcCentre c;
  if (b.has('r'))
    e_.motion_.arc_center_r(motion, start[a1], start[a2], end[a1], end[a2], b.get('r'), turns, c.first,
                            c.second, c.turn);
  else
    e_.motion_.arc_center_ijk(motion, start[a1], start[a2], end[a1], end[a2], off1, off2, turns, c.first,
                              c.second, c.turn);
  e_.motion_.inverse_time_arc(start[a1], start[a2], start[a3], c.first, c.second, c.turn, end[a1], end[a2],
                              end[a3]);
  return c;
}

void MotionCodes::arc_center_ijk(int motion, double cur1, double cur2, double end1, double end2, double off1,
                                 double off2, int turns, double& c1, double& c2, int& turn) const {
  const bool inch = e_.st_.modal.units == canon::Units::Inch;
  const double radius_tol = inch ? kRadiusToleranceInch : kRadiusToleranceMm;
  const double spiral_tol = inch ? kSpiralToleranceInch : kSpiralToleranceMm;
  if (e_.st_.modal.ijk_distance == DistanceMode::Absolute) {
    c1 = off1;
    c2 = off2;
  } else {
    c1 = cur1 + off1;
    c2 = cur2 + off2;
  }
  const double r1 = std::hypot(c1 - cur1, c2 - cur2);
  const double r2 = std::hypot(c1 - end1, c2 - end2);
  const canon::Plane p = e_.st_.modal.plane;
  const char a = plane_letter(p, 0), b = plane_letter(p, 1);
  const int at = first_offset_position(e_.block_);
  if (r1 < radius_tol)
    fail_at(at, ErrorCode::ArcZeroRadius,
            "zero-radius arc: its centre ({}{:.4f}, {}{:.4f}) is the start point", a, c1, b, c2);
  if (r2 < radius_tol)
    fail_at(at, ErrorCode::ArcZeroRadius, "zero-radius arc: its centre ({}{:.4f}, {}{:.4f}) is the end point",
            a, c1, b, c2);
  const double abs_err = std::fabs(r1 - r2);
  const double rel_err = abs_err / std::max(r1, r2);
  // LinuxCNC: within the absolute tolerance, or within the relative one up to 100 times the
  // absolute one (large radii); the planner runs the accepted difference as a spiral.
  if (abs_err > 100.0 * spiral_tol || (abs_err > spiral_tol && rel_err > kSpiralRelativeTolerance))
    fail_at(at, ErrorCode::ArcEndOffCircle,
            "the arc's end ({}{:.4f}, {}{:.4f}) is not on its circle: around the centre ({}{:.4f}, {}{:.4f}) "
            "the start is "
            "{:.4f} away and the end {:.4f}; correct the end point or the centre",
            a, end1, b, end2, a, c1, b, c2, r1, r2);
  turn = motion == 20 ? -turns : turns;
}

void MotionCodes::arc_center_r(int motion, double cur1, double cur2, double end1, double end2, double radius,
                               int turns, double& c1, double& c2, int& turn) const {
  const double tolerance =
      e_.st_.modal.units == canon::Units::Inch ? kRadiusToleranceInch : kRadiusToleranceMm;
  const int at = e_.block_.word_position('r');
  if (end1 == cur1 && end2 == cur2)
    fail_at(at, ErrorCode::ArcRadiusFullCircle,
            "an R arc that ends where it starts: R cannot give a full circle, give the centre with I/J/K "
            "instead");
  const double abs_radius = std::fabs(radius);
  const double mid1 = (end1 + cur1) / 2.0;
  const double mid2 = (end2 + cur2) / 2.0;
  double half_length = std::hypot(mid1 - end1, mid2 - end2);
  if (half_length - abs_radius > tolerance)
    fail_at(at, ErrorCode::ArcRadiusTooSmall,
            "arc radius {:.4f} is smaller than half the chord {:.4f} between start and end", abs_radius,
            half_length);
  if (half_length / abs_radius > 1 - kTiny) half_length = abs_radius;   // allow a semicircle's rounding
  // The direction is a double; ±π/2 is added in long double and the sum rounded (LinuxCNC's
  // arithmetic, kept so that centres on a coordinate axis come out with the same sign).
  const double dir = std::atan2(end2 - cur2, end1 - cur1);
  const double theta = static_cast<double>(((motion == 20 && radius > 0) || (motion == 30 && radius < 0)) ? dir - kPiL / 2
                                                                                                           : dir + kPiL / 2);
  const double turn2 = std::asin(half_length / abs_radius);
  const double offset = abs_radius * std::cos(turn2);
  c1 = mid1 + offset * std::cos(theta);
  c2 = mid2 + offset * std::sin(theta);
  turn = motion == 20 ? -turns : turns;
}

}  // namespace opencnc::gcode
