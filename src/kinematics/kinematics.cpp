// SPDX-License-Identifier: GPL-3.0-or-later
// Five-axis kinematics: the chain of two rotary axes as rotations about lines (Rodrigues), the
// inverse by Paden–Kahan's subproblems, the Jacobian from the axes' current lines.
#include "opencnc/kinematics/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace opencnc::kinematics {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
/// Below this length (of a unit vector's part across an axis) the vector lies along the axis and
/// its angle about it is free: 1e-9 rad of tool tilt, 1 nm at a metre.
constexpr double kAlong = 1e-9;

constexpr Vec3 kToolAxis{0, 0, 1};

Vec3 scaled(const Vec3& a, double k) noexcept {
  return k * a;
}

/// A rotary axis turned by its angle: the rotation about the line through `q` along `u`.
struct Turn {
  Vec3 u{0, 0, 1};
  Vec3 q{};
  double c = 1;
  double s = 0;

  Turn(const RotaryAxis& a, double degrees) noexcept
      : u(a.direction), q(a.pivot_mm), c(std::cos(degrees * kDegree)), s(std::sin(degrees * kDegree)) {}

  /// Rodrigues: x cosθ + (u × x) sinθ + u (u·x)(1 − cosθ); `sign` −1 turns back.
  Vec3 rotate(const Vec3& x, double sign = 1) const noexcept {
    return scaled(x, c) + scaled(cross(u, x), sign * s) + scaled(u, dot(u, x) * (1 - c));
  }
  Vec3 move(const Vec3& x) const noexcept { return q + rotate(x - q); }
  Vec3 move_back(const Vec3& y) const noexcept { return q + rotate(y - q, -1); }
};

/// The angle (radians) that turns `a` onto `b` about the unit vector `w`, taking only their parts
/// across `w`; `free` is set when `a`'s part is too short for an angle to mean anything.
double turn_angle(const Vec3& w, const Vec3& a, const Vec3& b, bool& free) noexcept {
  const Vec3 a_across = a - scaled(w, dot(w, a));
  const Vec3 b_across = b - scaled(w, dot(w, b));
  free = norm(a_across) < kAlong || norm(b_across) < kAlong;
  if (free) return 0;
  return std::atan2(dot(w, cross(a_across, b_across)), dot(a_across, b_across));
}

/// `degrees` moved by whole turns to lie nearest `near`.
double nearest_turn(double degrees, double near) noexcept {
  return degrees + 360.0 * std::round((near - degrees) / 360.0);
}

/// The rotary problem of every structure, in one form: angles t1, t2 (radians) with
/// R(w1, t1) · R(w2, t2) · p = q for unit vectors (Paden–Kahan's second subproblem). How each
/// structure maps onto it is in `inverse_all`.
struct TwoTurns {
  Vec3 w1, w2, p, q;
};

struct AngleSet {
  int count = 0;
  bool singular = false;
  std::array<std::array<double, 2>, 2> t{};  // radians, [solution][t1, t2]
};

/// `previous`: t1 and t2 (radians) to keep where one is free.
AngleSet solve_two_turns(const TwoTurns& k, std::array<double, 2> previous) noexcept {
  AngleSet out;
  const double w = dot(k.w1, k.w2);
  const double p2 = dot(k.w2, k.p);
  const double q1 = dot(k.w1, k.q);
  const Vec3 w12 = cross(k.w1, k.w2);
  const double across2 = dot(w12, w12);  // 1 − w², > 0 for axes that are not parallel
  // The intermediate vector c = R(w2, t2) p = R(w1, −t1) q keeps p's part along w2 and q's
  // along w1, and the unit length: c = α w1 + β w2 + γ (w1 × w2).
  const double alpha = (q1 - w * p2) / across2;
  const double beta = (p2 - w * q1) / across2;
  double gamma2 = (1.0 - alpha * alpha - beta * beta - 2 * alpha * beta * w) / across2;
  if (gamma2 < -1e-12) return out;  // the cones of the two turns do not meet
  gamma2 = std::max(gamma2, 0.0);
  const double gamma = std::sqrt(gamma2);
  const int candidates = gamma > kAlong ? 2 : 1;
  for (int n = 0; n < candidates; ++n) {
    const Vec3 c = scaled(k.w1, alpha) + scaled(k.w2, beta) + scaled(w12, n == 0 ? gamma : -gamma);
    bool free2 = false;
    bool free1 = false;
    double t2 = turn_angle(k.w2, k.p, c, free2);
    double t1 = turn_angle(k.w1, c, k.q, free1);
    if (free2) {  // p along w2: t2 free, kept; t1 turns R(w2, t2) p onto q
      t2 = previous[1];
      const Turn keep{RotaryAxis{Axis::C, k.w2, {}}, t2 / kDegree};
      t1 = turn_angle(k.w1, keep.rotate(k.p), k.q, free1);
      if (free1) t1 = previous[0];
    } else if (free1) {  // q along w1: t1 free, kept
      t1 = previous[0];
    }
    out.singular = out.singular || free1 || free2;
    out.t[static_cast<std::size_t>(out.count)] = {t1, t2};
    ++out.count;
    if (free1 || free2) break;  // one line of solutions, its member nearest `previous` taken
  }
  return out;
}

double joint(const Pose& j, Axis a) noexcept {
  return j[index(a)];
}

/// The tool's tip relative to the gauge point, with the head's axes at 0.
Vec3 tool_tip(double tool_length_mm) noexcept {
  return {0, 0, -tool_length_mm};
}

}  // namespace

const char* to_string(Structure s) noexcept {
  switch (s) {
    case Structure::Identity:
      return "identity";
    case Structure::TableTable:
      return "table-table";
    case Structure::HeadHead:
      return "head-head";
    case Structure::HeadTable:
      return "head-table";
  }
  return "";
}

const char* to_string(ConfigError e) noexcept {
  switch (e) {
    case ConfigError::Ok:
      return "ok";
    case ConfigError::ZeroDirection:
      return "a rotary axis' direction has no length";
    case ConfigError::SameJoint:
      return "the two rotary axes name the same joint";
    case ConfigError::NotRotary:
      return "a rotary axis of the kinematics must be A, B or C";
    case ConfigError::ParallelAxes:
      return "the two rotary axes are parallel: they cannot turn the tool onto every direction";
  }
  return "";
}

ConfigError prepare(Config& c) noexcept {
  if (c.structure == Structure::Identity) return ConfigError::Ok;
  for (RotaryAxis& a : c.rotary) {
    if (!is_rotary(a.joint)) return ConfigError::NotRotary;
    const double n = norm(a.direction);
    if (!(n > 1e-12)) return ConfigError::ZeroDirection;
    a.direction = scaled(a.direction, 1.0 / n);
  }
  if (c.rotary[0].joint == c.rotary[1].joint) return ConfigError::SameJoint;
  if (norm(cross(c.rotary[0].direction, c.rotary[1].direction)) < 1e-6) return ConfigError::ParallelAxes;
  return ConfigError::Ok;
}

ToolPose forward(const Config& c, const Pose& j, double tool_length_mm) noexcept {
  const Vec3 gauge = take3(j);
  const Vec3 tip0 = tool_tip(tool_length_mm);
  const Turn first(c.rotary[0], joint(j, c.rotary[0].joint));
  const Turn second(c.rotary[1], joint(j, c.rotary[1].joint));
  switch (c.structure) {
    case Structure::Identity:
      break;
    case Structure::TableTable:  // the table carries the work: turn the machine's tip back
      return {second.move_back(first.move_back(gauge + tip0)),
              second.rotate(first.rotate(kToolAxis, -1), -1)};
    case Structure::HeadHead:
      return {gauge + first.move(second.move(tip0)), first.rotate(second.rotate(kToolAxis))};
    case Structure::HeadTable:
      return {second.move_back(gauge + first.move(tip0)), second.rotate(first.rotate(kToolAxis), -1)};
  }
  return {gauge + tip0, kToolAxis};
}

Solutions inverse_all(const Config& c, const ToolPose& tool, double tool_length_mm,
                      const Pose& from) noexcept {
  Solutions out;
  const double length = norm(tool.axis);
  if (!(length > 1e-12)) return out;
  const Vec3 d = scaled(tool.axis, 1.0 / length);
  const Vec3 tip0 = tool_tip(tool_length_mm);
  if (c.structure == Structure::Identity) {
    out.status = Solve::Ok;
    out.count = 1;
    out.joints[0] = from;
    put3(out.joints[0], 0, tool.tip_mm - tip0);
    return out;
  }
  const RotaryAxis& a0 = c.rotary[0];
  const RotaryAxis& a1 = c.rotary[1];
  const double from0 = joint(from, a0.joint);
  const double from1 = joint(from, a1.joint);
  // Each structure's orientation equation as R(w1, t1) R(w2, t2) p = q:
  //   head-head    R0(θ0) R1(θ1) ẑ = d                     t1 = θ0, t2 = θ1
  //   table-table  R1(θ1)ᵀ R0(θ0)ᵀ ẑ = d ⇔ R0 R1 d = ẑ       t1 = θ0, t2 = θ1
  //   head-table   R1(θ1)ᵀ R0(θ0) ẑ = d ⇔ R1(−θ1) R0 ẑ = d  t1 = −θ1 (table), t2 = θ0 (head)
  TwoTurns k{};
  std::array<double, 2> previous{};
  switch (c.structure) {
    case Structure::HeadHead:
      k = {a0.direction, a1.direction, kToolAxis, d};
      previous = {from0 * kDegree, from1 * kDegree};
      break;
    case Structure::TableTable:
      k = {a0.direction, a1.direction, d, kToolAxis};
      previous = {from0 * kDegree, from1 * kDegree};
      break;
    case Structure::HeadTable:
    case Structure::Identity:
      k = {a1.direction, a0.direction, kToolAxis, d};
      previous = {-from1 * kDegree, from0 * kDegree};
      break;
  }
  const AngleSet angles = solve_two_turns(k, previous);
  if (angles.count == 0) return out;
  out.status = angles.singular ? Solve::Singular : Solve::Ok;
  for (int n = 0; n < angles.count; ++n) {
    const auto& t = angles.t[static_cast<std::size_t>(n)];
    double deg0 = 0;
    double deg1 = 0;
    if (c.structure == Structure::HeadTable) {
      deg0 = t[1] / kDegree;
      deg1 = -t[0] / kDegree;
    } else {
      deg0 = t[0] / kDegree;
      deg1 = t[1] / kDegree;
    }
    Pose& j = out.joints[static_cast<std::size_t>(out.count)];
    j = from;
    j[index(a0.joint)] = nearest_turn(deg0, from0);
    j[index(a1.joint)] = nearest_turn(deg1, from1);
    const Turn first(a0, j[index(a0.joint)]);
    const Turn second(a1, j[index(a1.joint)]);
    Vec3 gauge{};
    switch (c.structure) {
      case Structure::TableTable:
        gauge = first.move(second.move(tool.tip_mm)) - tip0;
        break;
      case Structure::HeadHead:
        gauge = tool.tip_mm - first.move(second.move(tip0));
        break;
      case Structure::HeadTable:
      case Structure::Identity:
        gauge = second.move(tool.tip_mm) - first.move(tip0);
        break;
    }
    put3(j, 0, gauge);
    ++out.count;
  }
  return out;
}

Inverse inverse(const Config& c, const ToolPose& tool, double tool_length_mm, const Pose& from) noexcept {
  const Solutions all = inverse_all(c, tool, tool_length_mm, from);
  if (all.count == 0) return {Solve::Unreachable, from};
  std::size_t best = 0;
  if (all.count == 2 && c.structure != Structure::Identity) {
    const auto motion = [&](const Pose& j) {
      return std::abs(j[index(c.rotary[0].joint)] - from[index(c.rotary[0].joint)]) +
             std::abs(j[index(c.rotary[1].joint)] - from[index(c.rotary[1].joint)]);
    };
    if (motion(all.joints[1]) < motion(all.joints[0])) best = 1;
  }
  return {all.status, all.joints[best]};
}

Jacobian jacobian(const Config& c, const Pose& j, double tool_length_mm) noexcept {
  Jacobian m{};
  const auto set_column = [&m](int col, const Vec3& tip, const Vec3& axis) {
    for (int r = 0; r < 3; ++r) {
      m[static_cast<std::size_t>(r)][static_cast<std::size_t>(col)] = tip[r];
      m[static_cast<std::size_t>(r + 3)][static_cast<std::size_t>(col)] = axis[r];
    }
  };
  const Vec3 tip0 = tool_tip(tool_length_mm);
  const Vec3 gauge = take3(j);
  const RotaryAxis& a0 = c.rotary[0];
  const RotaryAxis& a1 = c.rotary[1];
  const Turn first(a0, joint(j, a0.joint));
  const Turn second(a1, joint(j, a1.joint));
  // A turn of an axis by dθ moves a point x it carries by w × (x − q) dθ, (w, q) the axis' line
  // where it lies now; turning the work back moves the tip by the opposite, seen from the work.
  switch (c.structure) {
    case Structure::Identity:
      for (int col = 0; col < 3; ++col) {
        Vec3 e{};
        e[col] = 1;
        set_column(col, e, {});
      }
      return m;
    case Structure::TableTable: {
      const Vec3 z = first.move_back(gauge + tip0);  // the tip seen from the first axis' frame
      const Vec3 tip = second.move_back(z);
      const Vec3 axis_z = first.rotate(kToolAxis, -1);
      for (int col = 0; col < 3; ++col) {
        Vec3 e{};
        e[col] = 1;
        set_column(col, second.rotate(first.rotate(e, -1), -1), {});
      }
      set_column(3, scaled(second.rotate(cross(a0.direction, z - a0.pivot_mm), -1), -kDegree),
                 scaled(second.rotate(cross(a0.direction, axis_z), -1), -kDegree));
      set_column(4, scaled(cross(a1.direction, tip - a1.pivot_mm), -kDegree),
                 scaled(cross(a1.direction, second.rotate(axis_z, -1)), -kDegree));
      return m;
    }
    case Structure::HeadHead: {
      const Vec3 inner = second.move(tip0);
      const Vec3 outer = first.move(inner);
      const Vec3 axis_inner = second.rotate(kToolAxis);
      for (int col = 0; col < 3; ++col) {
        Vec3 e{};
        e[col] = 1;
        set_column(col, e, {});
      }
      set_column(3, scaled(cross(a0.direction, outer - a0.pivot_mm), kDegree),
                 scaled(cross(a0.direction, first.rotate(axis_inner)), kDegree));
      set_column(4, scaled(first.rotate(cross(a1.direction, inner - a1.pivot_mm)), kDegree),
                 scaled(first.rotate(cross(a1.direction, axis_inner)), kDegree));
      return m;
    }
    case Structure::HeadTable: {
      const Vec3 head_tip = first.move(tip0);
      const Vec3 tip = second.move_back(gauge + head_tip);
      const Vec3 axis_m = first.rotate(kToolAxis);
      for (int col = 0; col < 3; ++col) {
        Vec3 e{};
        e[col] = 1;
        set_column(col, second.rotate(e, -1), {});
      }
      set_column(3, scaled(second.rotate(cross(a0.direction, head_tip - a0.pivot_mm), -1), kDegree),
                 scaled(second.rotate(cross(a0.direction, axis_m), -1), kDegree));
      set_column(4, scaled(cross(a1.direction, tip - a1.pivot_mm), -kDegree),
                 scaled(cross(a1.direction, second.rotate(axis_m, -1)), -kDegree));
      return m;
    }
  }
  return m;
}

}  // namespace opencnc::kinematics
