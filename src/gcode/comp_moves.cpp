// SPDX-License-Identifier: GPL-3.0-or-later
// Cutter compensation of one programmed move, by LinuxCNC 2.9's rules: the entry move, then
// each line or arc against the corner it makes with the held move before it (convex corners
// get an arc around the programmed corner point; concave corners move the held move's end to
// where the two offset paths meet).
#include <cmath>

#include "arc_math.hpp"
#include "comp_path.hpp"
#include "gcode_error.hpp"

namespace opencnc::gcode::comp {

namespace {

constexpr long double kHalfPiL = kPiL / 2;
// LinuxCNC's "equal" tolerance: an entry arc whose chord is this close to perpendicular to
// the centre line cannot be re-centred.
constexpr double kEqualTolerance = 0.0001;

bool clockwise(int motion) noexcept {
  return motion == 20;
}

// The tool cuts on the inside of the programmed arc (G3 on the left, G2 on the right).
bool inside_by_motion(bool left, int motion) noexcept {
  return left != clockwise(motion);
}

[[noreturn]] void arc_too_small(double arc_radius, double tool_radius) {
  fail(ErrorCode::CompArcTooSmall, "the tool (radius {:.4f}) does not fit inside this arc (radius {:.4f})",
       tool_radius, arc_radius);
}

// The point of the held move's circle where the tool, offset from a following line, meets
// it (an arc into a concave corner with a line).
PlanePoint arc_line_corner(const CompPath& path, const CompQueuedMove& prev, double op1, double op2,
                           double p1, double p2) {
  const double r = path.radius();
  const double held_radius = std::hypot(prev.center2 - prev.end2, prev.center1 - prev.end1);
  const double base_dir = std::atan2(p2 - op2, p1 - op1);
  const double theta = add_long(base_dir, prev.turn > 0 ? kHalfPiL : -kHalfPiL);
  const double phi = std::atan2(prev.center2 - op2, prev.center1 - op1);
  const bool inside = tool_inside_arc(path.left(), prev.turn);
  const double programmed_radius = inside ? held_radius + r : held_radius - r;
  // Distance from the arc centre to the offset line, in units of the held radius.
  const double d = programmed_radius * std::cos(theta - phi);
  const double l = (inside ? d - r : d + r) / held_radius;
  if (l > 1.0 || l < -1.0)
    fail(ErrorCode::CompGouge, "the tool cannot fit in the corner between this arc and line without gouging");
  const bool plus = inside ? prev.turn <= 0 : prev.turn > 0;
  const double angle = add_long((plus ? std::acos(l) : -std::acos(l)) + theta, kPiL);
  return {prev.center1 + held_radius * std::cos(angle), prev.center2 + held_radius * std::sin(angle)};
}

// Where a line's offset meets the offset of a following arc (centre c, radius arc_radius)
// in a concave corner; theta is the normal of the held line towards the tool.
PlanePoint line_arc_corner(const CompPath& path, double theta, double beta, double c1, double c2,
                           double arc_radius, int turn) {
  const double r = path.radius();
  const double cy = static_cast<double>(arc_radius * std::sin(static_cast<long double>(beta) - kHalfPiL));
  const bool inside = tool_inside_arc(path.left(), turn);
  const double dist = inside ? arc_radius - r : arc_radius + r;
  const double l = (inside ? cy + r : cy - r) / dist;
  if (l > 1.0 || l < -1.0)
    fail(ErrorCode::CompGouge, "the tool cannot reach the inside corner before this arc without gouging");
  double angle;
  if (inside)
    angle = turn > 0 ? theta + std::asin(l) : theta - std::asin(l);
  else
    angle = static_cast<double>(static_cast<long double>(theta) + kPiL +
                                (turn > 0 ? -std::asin(l) : std::asin(l)));
  return {c1 + dist * std::cos(angle), c2 + dist * std::sin(angle)};
}

// Where the offsets of two arcs meet in a concave corner: on the held arc's offset circle at
// the distance of the new arc's offset radius from the new centre (law of cosines).
PlanePoint arc_arc_corner(const CompPath& path, const CompQueuedMove& prev, double c1, double c2,
                          double arc_radius, int turn) {
  const double held_radius = std::hypot(prev.center2 - prev.end2, prev.center1 - prev.end1);
  const double new_radius =
      tool_inside_arc(path.left(), turn) ? arc_radius - path.radius() : arc_radius + path.radius();
  const double centres = std::hypot(prev.center2 - c2, prev.center1 - c1);
  if (held_radius == 0 || centres == 0)
    fail(ErrorCode::CompConcentricArcs, "cutter compensation cannot join two arcs with the same centre");
  const double a =
      (held_radius * held_radius + centres * centres - new_radius * new_radius) / (2 * held_radius * centres);
  if (a > 1.0 || a < -1.0)
    fail(ErrorCode::CompGouge, "the tool cannot fit in the corner between these two arcs without gouging");
  const double pullback = std::acos(a);
  const double cc_dir = std::atan2(c2 - prev.center2, c1 - prev.center1);
  const bool plus = tool_inside_arc(path.left(), prev.turn) == (turn > 0);
  const double dir = plus ? cc_dir + pullback : cc_dir - pullback;
  return {prev.center1 + held_radius * std::cos(dir), prev.center2 + held_radius * std::sin(dir)};
}

}  // namespace

// The entry move: a line from the tool's position tangent to the tool circle at the end.
void straight_first(CompPath& path, bool rapid, const Pose& end) {
  double c1, c2, c3, p1, p2, p3;
  path.current(c1, c2, c3);
  path.split(end, p1, p2, p3);
  const double r = path.radius();
  const double distance = std::hypot(p1 - c1, p2 - c2);
  if (distance <= r)
    fail(ErrorCode::CompEntryTooShort,
         "the move that starts cutter compensation ({:.4f}) must be longer than the tool radius ({:.4f})",
         distance, r);
  const double alpha = add_long(std::atan2(p2 - c2, p1 - c1), path.left() ? kHalfPiL : -kHalfPiL);
  const double e1 = p1 + r * std::cos(alpha);
  const double e2 = p2 + r * std::sin(alpha);
  path.set_start(c1, c2);
  path.queue_line(rapid, std::cos(alpha), std::sin(alpha), e1, e2, p3, end);
  path.first_move_done();
  path.moved_to(e1, e2, p3, end);
  path.set_programmed(p1, p2, p3);
}

void straight_next(CompPath& path, bool rapid, const Pose& end) {
  double c1, c2, c3, op1, op2, op3, p1, p2, p3;
  path.current(c1, c2, c3);
  path.programmed(op1, op2, op3);
  path.split(end, p1, p2, p3);
  double e1 = c1, e2 = c2;
  if (p1 == op1 && p2 == op2) {
    // No motion in the plane: the tool stays where it is (the corner is still open).
    path.queue_line(rapid, 0, 0, c1, c2, p3, end);
  } else {
    const bool left = path.left();
    const double r = path.radius();
    // theta: from the programmed point to the tool (normal of the last move); alpha: this
    // move's direction; beta: the turn between them, > 0 convex, < 0 or > π concave.
    double theta = std::atan2(c2 - op2, c1 - op1);
    double alpha = std::atan2(p2 - op2, p1 - op1);
    double beta, gamma;
    if (left) {
      if (theta < alpha) theta = add_long(theta, 2 * kPiL);
      beta = add_long(theta - alpha, -kHalfPiL);
      gamma = static_cast<double>(kHalfPiL);
    } else {
      if (alpha < theta) alpha = add_long(alpha, 2 * kPiL);
      beta = add_long(alpha - theta, -kHalfPiL);
      gamma = static_cast<double>(-kHalfPiL);
    }
    e1 = p1 + r * std::cos(alpha + gamma);
    e2 = p2 + r * std::sin(alpha + gamma);
    const long double b = beta;
    bool concave = b < -kCornerTolerance || b > kPiL + kCornerTolerance;
    // Over the top of a convex arc into a line that doubles back ("h" shape): stay outside.
    const CompQueuedMove* held = path.held_front();
    if (!concave && b > kPiL - kCornerTolerance && held != nullptr &&
        held->kind == CompQueuedMove::Kind::Arc) {
      concave = (!left && held->turn > 0) || (left && held->turn < 0);
    }
    if (!concave && beta > kCornerTolerance) {
      // Convex corner: round it with an arc about the programmed corner point.
      const double m1 = op1 + r * std::cos(alpha + gamma);
      const double m2 = op2 + r * std::sin(alpha + gamma);
      path.settle(c1, c2);
      if (rapid)
        path.queue_line(true, 0, 0, m1, m2, c3, end);  // no arc at rapid rate
      else
        path.queue_arc(0.0, m1, m2, op1, op2, left ? -1 : 1, c3, end);
      path.release();
      path.set_start(m1, m2);
    } else if (concave && path.front().kind != CompQueuedMove::Kind::Arc) {
      // Line into line: back the held line's end up to where the offsets cross. (beta is at
      // least -π/2 here, so half the inside corner is never zero.)
      const double half_corner = static_cast<double>((b + kPiL) / 2.0);
      const double retreat = r / std::tan(half_corner);
      path.settle(c1 + retreat * std::cos(theta + gamma), c2 + retreat * std::sin(theta + gamma));
    } else if (concave) {
      const PlanePoint m = arc_line_corner(path, path.front(), op1, op2, p1, p2);
      path.settle(m.first, m.second);
    } else {
      // Straight on (or tangent out of an arc): the held move is final as it is.
      path.release();
      path.set_start(c1, c2);
    }
    path.queue_line(rapid, p1 - op1, p2 - op2, e1, e2, p3, end);
  }
  path.moved_to(e1, e2, p3, end);
  path.set_programmed(p1, p2, p3);
}

// The entry arc: from the tool's position, an arc tangent to the programmed arc's offset at
// its end (a new centre on the line from the compensated end to the programmed centre).
void arc_first(CompPath& path, ExecContext& ctx, const Block& block, int motion, const Pose& end) {
  double c1, c2, c3, e1, e2, e3;
  path.current(c1, c2, c3);
  path.split(end, e1, e2, e3);
  const bool left = path.left();
  const double r = path.radius();
  const InterpState& st = ctx.state();
  if (std::hypot(e1 - c1, e2 - c2) <= r)
    fail(ErrorCode::CompEntryTooShort,
         "the arc that starts cutter compensation must end more than the tool radius ({:.4f}) away", r);
  if (block.has('r') && std::fabs(block.get('r')) <= r && inside_by_motion(left, motion))
    arc_too_small(std::fabs(block.get('r')), r);
  const ArcCentre centre = ctx.arc_centre(block, motion, st.position.current, end);
  const double arc_radius = std::hypot(centre.first - c1, centre.second - c2);
  if (!block.has('r') && arc_radius <= r && inside_by_motion(left, motion)) arc_too_small(arc_radius, r);
  const double gamma = tool_inside_arc(left, centre.turn) ? std::atan2(centre.second - e2, centre.first - e1)
                                                          : std::atan2(e2 - centre.second, e1 - centre.first);
  path.first_move_done();
  path.set_programmed(e1, e2, e3);
  const double n1 = e1 + r * std::cos(gamma);
  const double n2 = e2 + r * std::sin(gamma);
  // Triangle: compensated end A, new centre B, midpoint of the chord C; AB along the old
  // centre's direction, the chord from A to the tool.
  const double half_chord = std::hypot(c2 - n2, c1 - n1) / 2.0;
  const double ab_angle = std::atan2(centre.second - n2, centre.first - n1);
  const double a_angle = std::atan2(c2 - n2, c1 - n1) - ab_angle;
  if (std::fabs(std::cos(a_angle)) < kEqualTolerance) arc_too_small(arc_radius, r);
  const double to_centre = half_chord / std::cos(a_angle);
  const double k1 = n1 + to_centre * std::cos(ab_angle);
  const double k2 = n2 + to_centre * std::sin(ab_angle);
  const double spiral = st.modal.units == canon::Units::Inch ? kSpiralToleranceInch : kSpiralToleranceMm;
  if (std::fabs(std::hypot(k1 - n1, k2 - n2) - std::hypot(k1 - c1, k2 - c2)) > spiral)
    fail(ErrorCode::CompInternal, "cutter compensation could not find an entry arc through both ends");
  // A lathe tool's origin must first move to where its nose centre starts the arc.
  if (st.modal.comp_orientation != 0 && st.modal.comp_orientation != 9) {
    path.queue_line(false, 0, 0, c1, c2, c3, end);
    path.set_start(c1, c2);
  }
  path.queue_arc(find_turn(c1, c2, k1, k2, centre.turn, n1, n2), n1, n2, k1, k2, centre.turn, e3, end);
  path.moved_to(n1, n2, e3, end);
}

void arc_next(CompPath& path, ExecContext& ctx, const Block& block, int motion, const Pose& end) {
  double c1, c2, c3, op1, op2, op3, e1, e2, e3;
  path.current(c1, c2, c3);
  path.programmed(op1, op2, op3);
  path.split(end, e1, e2, e3);
  Pose start = ctx.state().position.current;
  path.place(start, op1, op2, op3);
  const ArcCentre centre = ctx.arc_centre(block, motion, start, end);
  const double k1 = centre.first, k2 = centre.second;
  const int turn = centre.turn;
  const bool left = path.left();
  const double r = path.radius();
  const double arc_radius = std::hypot(k1 - e1, k2 - e2);
  // theta: direction of the last move at the corner; alpha: this arc's starting tangent.
  const double theta = add_long(std::atan2(c2 - op2, c1 - op1), left ? -kHalfPiL : kHalfPiL);
  double delta = std::atan2(k2 - op2, k1 - op1);
  const double alpha = add_long(delta, clockwise(motion) ? kHalfPiL : -kHalfPiL);
  double beta = left ? theta - alpha : alpha - theta;
  if (beta > 1.5 * kPiL)
    beta = add_long(beta, -2 * kPiL);
  else if (beta < -kHalfPiL)
    beta = add_long(beta, 2 * kPiL);
  double gamma;
  if (inside_by_motion(left, motion)) {
    gamma = std::atan2(k2 - e2, k1 - e1);
    if (arc_radius <= r) arc_too_small(arc_radius, r);
  } else {
    gamma = std::atan2(e2 - k2, e1 - k1);
    delta = add_long(delta, kPiL);
  }
  const double n1 = e1 + r * std::cos(gamma);
  const double n2 = e2 + r * std::sin(gamma);
  const long double b = beta;
  const double sweep = find_turn(op1, op2, k1, k2, turn, e1, e2);
  // Concave, or tangent into the top of an arc the tool is outside of ("m" and "h" shapes).
  const bool concave = b < -kCornerTolerance || b > kPiL + kCornerTolerance ||
                       (std::fabs(b - kPiL) < kCornerTolerance && !tool_inside_arc(left, turn));
  if (concave) {
    const PlanePoint m = path.front().kind == CompQueuedMove::Kind::Arc
                             ? arc_arc_corner(path, path.front(), k1, k2, arc_radius, turn)
                             : line_arc_corner(path, theta, beta, k1, k2, arc_radius, turn);
    path.settle(m.first, m.second);
  } else if (beta > kCornerTolerance) {
    // Convex: an arc about the programmed corner point first.
    const double m1 = op1 + r * std::cos(delta);
    const double m2 = op2 + r * std::sin(delta);
    path.release();
    path.queue_arc(0.0, m1, m2, op1, op2, left ? -1 : 1, c3, end);
    path.release();
    path.set_start(m1, m2);
  } else {
    path.release();
    path.set_start(c1, c2);
  }
  path.queue_arc(sweep, n1, n2, k1, k2, turn, e3, end);
  path.set_programmed(e1, e2, e3);
  path.moved_to(n1, n2, e3, end);
}

}  // namespace opencnc::gcode::comp
