// SPDX-License-Identifier: GPL-3.0-or-later
// Soft-limit preflight: the extent of every move (arcs by their extreme points) against the limits.
#include "opencnc/controller/preflight.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/core/vec3.hpp"
#include "opencnc/plan/planner.hpp"

namespace opencnc::control {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kSlack = 1e-7;   ///< as the tick's check
constexpr int kMaxReported = 20;  ///< errors listed before the rest are summed up

/// The part of `q − c` in the plane with unit normal n.
Vec3 in_plane(const Pose& q, int base, const Vec3& c, const Vec3& n) {
  const Vec3 d = take3(q, base) - c;
  return d - dot(d, n) * n;
}

/// Whether some angle α + 2πm lies in [lo, hi].
bool passes(double alpha, double lo, double hi) {
  const double m = std::ceil((lo - alpha) / kTwoPi);
  return alpha + kTwoPi * m <= hi;
}

/// An arc in its plane: centre, start direction e1, e2 = n × e1, radius, signed sweep.
struct ArcFrame {
  int base = 0;
  Vec3 c, e1, e2;
  double radius = 0, sweep = 0;
};

bool arc_frame(const canon::ArcGeometry& g, const Pose& start, const Pose& end, ArcFrame& f) {
  f.base = canon::plane_base(g.plane);
  f.c = g.center;
  const Vec3& n = g.normal;
  const Vec3 rs = in_plane(start, f.base, f.c, n), re = in_plane(end, f.base, f.c, n);
  const double r = std::sqrt(dot(rs, rs));
  if (!(r > 0)) return false;
  for (int k = 0; k < 3; ++k) f.e1[k] = rs[k] / r;
  f.e2 = cross(n, f.e1);
  f.sweep = canon::arc_sweep(std::atan2(dot(re, f.e2), dot(re, f.e1)), g.turns == 0 ? 1 : g.turns);
  f.radius = std::max(r, std::sqrt(dot(re, re)));
  return true;
}

void widen_by_arc(const canon::ArcGeometry& g, const Pose& start, const Pose& end, Extent& e) {
  ArcFrame f;
  if (!arc_frame(g, start, end, f)) return;
  const double lo = std::min(0.0, f.sweep), hi = std::max(0.0, f.sweep);
  // Along axis k the circle is c_k + r·A·cos(θ − α), A = |(e1_k, e2_k)|, α = atan2(e2_k, e1_k):
  // its largest value at θ = α, its smallest at θ = α + π, where the sweep passes them.
  for (int k = 0; k < 3; ++k) {
    const double amp = std::hypot(f.e1[k], f.e2[k]);
    if (amp < 1e-12) continue;
    const double alpha = std::atan2(f.e2[k], f.e1[k]);
    const int axis = f.base + k;
    if (passes(alpha, lo, hi)) e.max[axis] = std::max(e.max[axis], f.c[k] + f.radius * amp);
    if (passes(alpha + std::numbers::pi, lo, hi))
      e.min[axis] = std::min(e.min[axis], f.c[k] - f.radius * amp);
  }
}

double linear_length(const Pose& d) {
  const double xyz = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return xyz > 0 ? xyz : std::sqrt(d[6] * d[6] + d[7] * d[7] + d[8] * d[8]);
}

/// The file a move came from, or "" when the program has no file table.
std::string file_of(const canon::Program& p, canon::SegmentId id) {
  const std::uint32_t f = p.file_of(id);
  return f < p.sources().file_count() ? p.sources().file(f) : std::string();
}

}  // namespace

Extent move_extent(const canon::Program& program, canon::SegmentId id) {
  const Pose a = program.start_of(id), b = program.end(id);
  Extent e;
  for (int i = 0; i < kAxisCount; ++i) {
    e.min[i] = std::min(a[i], b[i]);
    e.max[i] = std::max(a[i], b[i]);
  }
  if (program.move(id).kind == canon::MoveKind::Arc) widen_by_arc(program.arc(id), a, b, e);
  return e;
}

double move_length(const canon::Program& program, canon::SegmentId id) {
  const Pose a = program.start_of(id), b = program.end(id);
  Pose d;
  for (int i = 0; i < kAxisCount; ++i) d[i] = b[i] - a[i];
  ArcFrame f;
  if (program.move(id).kind != canon::MoveKind::Arc || !arc_frame(program.arc(id), a, b, f))
    return linear_length(d);
  // The helix rise: the part of the move along the plane normal.
  const canon::ArcGeometry& g = program.arc(id);
  double rise = 0;
  for (int k = 0; k < 3; ++k) rise += d[f.base + k] * g.normal[k];
  return std::hypot(f.radius * std::fabs(f.sweep), rise);
}

namespace {

/// What condition `c` adds to a move while it machines.
EdmReach reach_of(const machine::EdmCondition& c) {
  EdmReach r;
  if (c.orbit != machine::OrbitKind::None && c.orbit_radius_mm > 0) {
    r.orbit_mm = c.orbit_radius_mm;
    r.orbit_condition = c.number;
  }
  if (c.jump_period_s > 0 && c.jump_mode == machine::JumpMode::Axis) {
    r.jump_mm = c.jump_height_mm;
    r.jump_condition = c.number;
  }
  return r;
}

/// The larger orbit and the larger jump of two.
EdmReach wider(EdmReach a, const EdmReach& b) {
  if (b.orbit_mm > a.orbit_mm) {
    a.orbit_mm = b.orbit_mm;
    a.orbit_condition = b.orbit_condition;
  }
  if (b.jump_mm > a.jump_mm) {
    a.jump_mm = b.jump_mm;
    a.jump_condition = b.jump_condition;
  }
  return a;
}

/// The move's extent widened by an EDM orbit (both orbit axes) and axis jump (the tool axis, away
/// from the work); a jump along the path stays on the path.
void widen_by_edm(const machine::EdmConfig& edm, const EdmReach& r, Extent& e) {
  for (const std::int8_t a : edm.orbit_axes) {
    e.min[a] -= r.orbit_mm;
    e.max[a] += r.orbit_mm;
  }
  (edm.lift_direction > 0 ? e.max : e.min)[edm.tool_axis] += edm.lift_direction * r.jump_mm;
}

/// "with EDM condition 2's orbit (0.08 mm) and jump (0.4 mm) ": what widened the move, for the message.
std::string edm_reason(const EdmReach& r) {
  const bool orbit = r.orbit_condition != 0, jump = r.jump_condition != 0;
  if (!orbit && !jump) return "";
  std::string s = "with EDM ";
  if (orbit) s += fmt::format("condition {}'s orbit ({} mm)", r.orbit_condition, r.orbit_mm);
  if (orbit && jump) s += " and ";
  if (jump && orbit && r.jump_condition == r.orbit_condition) {
    s += fmt::format("jump ({} mm)", r.jump_mm);
  } else if (jump) {
    s += fmt::format("condition {}'s jump ({} mm)", r.jump_condition, r.jump_mm);
  }
  return s + " ";
}

/// One move against the soft limits; `errors` counts every crossing, the first kMaxReported are
/// listed. Returns whether the move stays inside. `edm`: what the gap servo adds to the move.
bool check_move_limits(const canon::Program& program, canon::SegmentId id, const ServoConfig& config,
                       Diagnostics& diags, int& errors, const EdmReach& edm = {}) {
  Extent e = move_extent(program, id);
  if (config.edm.enabled) widen_by_edm(config.edm, edm, e);
  bool inside = true;
  for (int j = 0; j < config.joint_count; ++j) {
    const JointConfig& jc = config.joints[static_cast<std::size_t>(j)];
    if (jc.wrapped) continue;
    const bool high = e.max[jc.axis] > jc.max_limit + kSlack, low = e.min[jc.axis] < jc.min_limit - kSlack;
    if (!high && !low) continue;
    inside = false;
    if (++errors > kMaxReported) continue;
    const canon::Move& m = program.move(id);
    const char* unit = jc.rotary ? "deg" : "mm";
    diags.error(
        file_of(program, id), m.line, 0,
        fmt::format("{}this move takes {} to {:.4f} {}, beyond its {} soft limit of {} {}", edm_reason(edm),
                    kAxisLetters[static_cast<std::size_t>(jc.axis)], high ? e.max[jc.axis] : e.min[jc.axis],
                    unit, high ? "maximum" : "minimum", high ? jc.max_limit : jc.min_limit, unit),
        "control.soft-limit");
  }
  return inside;
}

void report_unlisted(int errors, Diagnostics& diags) {
  if (errors > kMaxReported) {
    diags.error("", 0, 0, fmt::format("{} more moves cross a soft limit", errors - kMaxReported),
                "control.soft-limit");
  }
}

}  // namespace

bool check_soft_limits(const canon::Program& program, const ServoConfig& config, Diagnostics& diags) {
  int errors = 0;
  for (canon::SegmentId id = 0; id < program.size(); ++id) check_move_limits(program, id, config, diags, errors);
  report_unlisted(errors, diags);
  return errors == 0;
}

bool MachineMoveCheck::check(const canon::Program& program, canon::SegmentId move, Diagnostics& diags) {
  const bool planner_ok = plan::check_move(program, move, limits_, diags);
  const EdmReach edm = edm_reach_at(program, move);
  // A move the planner cannot make (not finite, a bad arc) has no extent worth checking.
  return planner_ok && check_move_limits(program, move, config_, diags, soft_limit_errors_, edm);
}

void MachineMoveCheck::finish(Diagnostics& diags) {
  report_unlisted(soft_limit_errors_, diags);
  soft_limit_errors_ = 0;
  edm_program_ = nullptr;  // the next scan starts from its program's start
}

namespace {

/// The shortest time move `id` can take: its widest axis' travel at that axis' max_velocity.
double shortest_time_s(const canon::Program& program, canon::SegmentId id, const ServoConfig& config) {
  const Extent e = move_extent(program, id);
  double t = 0;
  for (int j = 0; j < config.joint_count; ++j) {
    const JointConfig& jc = config.joints[static_cast<std::size_t>(j)];
    if (jc.max_velocity > 0) t = std::max(t, (e.max[jc.axis] - e.min[jc.axis]) / jc.max_velocity);
  }
  return t;
}

}  // namespace

// How long condition n's offsets may stay out once it is off: the orbit spirals in at the rate it
// grew (a step per quarter turn), a jump under way goes up and comes back at half the tool axis'
// acceleration (GapServo).
void MachineMoveCheck::start_edm_tail(int n) {
  const machine::EdmCondition* c = config_.edm.find(n);
  if (c == nullptr) return;
  double t = 0;
  if (c->orbit != machine::OrbitKind::None && c->orbit_period_s > 0 && c->orbit_radius_mm > 0) {
    const double step = c->orbit_step_mm > 0 ? c->orbit_step_mm : c->orbit_radius_mm;
    t = 0.25 * c->orbit_period_s * c->orbit_radius_mm / step;
  }
  if (c->jump_period_s > 0 && c->jump_speed_mm_s > 0) {
    double a = 0;
    for (int j = 0; j < config_.joint_count; ++j) {
      if (config_.joints[static_cast<std::size_t>(j)].axis == config_.edm.tool_axis)
        a = 0.5 * config_.joints[static_cast<std::size_t>(j)].max_acceleration;
    }
    t = std::max(t, 2 * (c->jump_height_mm / c->jump_speed_mm_s + (a > 0 ? c->jump_speed_mm_s / a : 0)));
  }
  const double left = edm_tail_s_ - edm_since_s_;
  edm_tail_ = left > 0 || edm_tail_first_ ? wider(edm_tail_, reach_of(*c)) : reach_of(*c);
  edm_tail_s_ = std::max(left, t);
  edm_since_s_ = 0;
  edm_tail_first_ = true;
}

// The moves are checked in order; the codes before each are read once (a new program, or a move
// before the last one, starts afresh). Actions already released were seen before (the scan
// releases only what it has checked). Each move checked adds its shortest time to the time
// since the last code; one not checked adds nothing, which only widens more moves.
EdmReach MachineMoveCheck::edm_reach_at(const canon::Program& program, std::size_t move) {
  if (!config_.edm.enabled) return {};
  if (&program != edm_program_ || move < edm_last_move_) {
    edm_program_ = &program;
    edm_next_action_ = 0;
    edm_on_ = 0;
    edm_tail_ = {};
    edm_tail_s_ = edm_since_s_ = 0;
    edm_tail_first_ = false;
    edm_timed_move_ = move;
  } else if (move == edm_last_move_ && edm_timed_move_ > move) {
    return edm_last_reach_;  // the same move checked again
  }
  edm_last_move_ = move;
  edm_next_action_ = std::max(edm_next_action_, program.first_held_action());
  for (; edm_next_action_ < program.action_count(); ++edm_next_action_) {
    const canon::Action& a = program.action(edm_next_action_);
    if (a.before_move > move) break;
    if (a.kind != canon::ActionKind::ProcessCode) continue;
    if (a.index == machine::kEdmConditionCode) {
      const int n = static_cast<int>(std::lround(a.value));
      if (edm_on_ != 0 && edm_on_ != n) start_edm_tail(edm_on_);
      edm_on_ = n;
    } else if (a.index == machine::kEdmOffCode) {
      if (edm_on_ != 0) start_edm_tail(edm_on_);
      edm_on_ = 0;
    }
  }
  EdmReach r;
  if (edm_on_ != 0) {
    if (const machine::EdmCondition* c = config_.edm.find(edm_on_)) r = reach_of(*c);
  }
  if (edm_tail_first_ || edm_since_s_ < edm_tail_s_) r = wider(r, edm_tail_);
  edm_since_s_ += shortest_time_s(program, move, config_);
  edm_tail_first_ = false;
  edm_timed_move_ = move + 1;
  edm_last_reach_ = r;
  return r;
}

}  // namespace opencnc::control
