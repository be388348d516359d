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

namespace opencnc::controller {

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

/// One move against the soft limits by its extent `e`; `errors` counts every crossing, the first
/// kMaxReported are listed. Returns whether the move stays inside. `why`: what widened the extent
/// beyond the programmed path (a MoveReach's words), "" for none.
bool check_extent(const canon::Program& program, canon::SegmentId id, const Extent& e, const std::string& why,
                  const control::ServoConfig& config, Diagnostics& diags, int& errors) {
  bool inside = true;
  for (int j = 0; j < config.joint_count; ++j) {
    const control::JointConfig& jc = config.joints[static_cast<std::size_t>(j)];
    if (jc.wrapped) continue;
    const bool high = e.max[jc.axis] > jc.max_limit + kSlack, low = e.min[jc.axis] < jc.min_limit - kSlack;
    if (!high && !low) continue;
    inside = false;
    if (++errors > kMaxReported) continue;
    const canon::Move& m = program.move(id);
    const char* unit = jc.rotary ? "deg" : "mm";
    diags.error(
        file_of(program, id), m.line, 0,
        fmt::format("{}this move takes {} to {:.4f} {}, beyond its {} soft limit of {} {}", why,
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

bool check_soft_limits(const canon::Program& program, const control::ServoConfig& config,
                       Diagnostics& diags) {
  int errors = 0;
  for (canon::SegmentId id = 0; id < program.size(); ++id)
    check_extent(program, id, move_extent(program, id), "", config, diags, errors);
  report_unlisted(errors, diags);
  return errors == 0;
}

MachineMoveCheck::MachineMoveCheck(const control::ServoConfig& config, const plan::MachineLimits& limits,
                                   std::vector<std::unique_ptr<MoveReach>> reaches)
    : config_(config), limits_(limits), reaches_(std::move(reaches)) {}

// Every reach follows every move, in order, whatever the planner says of it.
bool MachineMoveCheck::check(const canon::Program& program, canon::SegmentId move, Diagnostics& diags) {
  const bool planner_ok = plan::check_move(program, move, limits_, diags);
  Extent e = move_extent(program, move);
  std::string why;
  for (const auto& r : reaches_) why += r->widen(program, move, e);
  // A move the planner cannot make (not finite, a bad arc) has no extent worth checking.
  return planner_ok && check_extent(program, move, e, why, config_, diags, soft_limit_errors_);
}

void MachineMoveCheck::finish(Diagnostics& diags) {
  report_unlisted(soft_limit_errors_, diags);
  soft_limit_errors_ = 0;
  for (const auto& r : reaches_) r->reset();  // the next scan starts from its program's start
}

}  // namespace opencnc::controller
