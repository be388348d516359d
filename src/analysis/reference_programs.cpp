// SPDX-License-Identifier: GPL-3.0-or-later
// Reference programs from canonical calls (square, dense spiral, small alternating arcs).
#include "opencnc/analysis/reference_programs.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "opencnc/canon/program_builder.hpp"

namespace opencnc::analysis {

namespace {

Pose xyz(double x, double y, double z = 0) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

double round4(double v) {
  return std::round(v * 1e4) / 1e4;
}

void set_mode(canon::ProgramBuilder& b, const PathMode& m) {
  b.set_motion_control_mode(m.mode, m.p);
  if (m.mode == canon::MotionControl::Continuous) b.set_naivecam_tolerance(m.q);
}

}  // namespace

canon::Program square_program(double side_mm, double feed_mm_min, PathMode mode) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  canon::SegmentId id = 0;
  set_mode(b, mode);
  b.straight_traverse(id++, xyz(0, 0));
  b.set_feed_rate(feed_mm_min);
  b.straight_feed(id++, xyz(side_mm, 0));
  b.straight_feed(id++, xyz(side_mm, side_mm));
  b.straight_feed(id++, xyz(0, side_mm));
  b.straight_feed(id++, xyz(0, 0));
  b.program_end();
  return b.take();
}

canon::Program spiral_program(int segments, double feed_mm_min, PathMode mode, std::uint32_t seed) {
  constexpr double r0 = 50.0, dr_per_rev = -0.5;
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  canon::SegmentId id = 0;
  set_mode(b, mode);
  b.straight_traverse(id++, xyz(r0, 0));
  b.set_feed_rate(feed_mm_min);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> length(0.05, 0.2);
  double th = 0, r = r0;
  for (int i = 0; i < segments; ++i) {
    th += length(rng) / r;
    r = r0 + dr_per_rev * th / (2 * std::numbers::pi);
    b.straight_feed(id++, xyz(round4(r * std::cos(th)), round4(r * std::sin(th))));
  }
  b.program_end();
  return b.take();
}

canon::Program small_arcs_program(int arcs, double radius_mm, double sweep_deg, double feed_mm_min,
                                  PathMode mode) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  canon::SegmentId id = 0;
  set_mode(b, mode);
  b.straight_traverse(id++, xyz(0, 0));
  b.set_feed_rate(feed_mm_min);
  const double sweep = sweep_deg * std::numbers::pi / 180.0;
  double x = 0, y = 0, heading = 0;  // direction of travel, radians
  for (int i = 0; i < arcs; ++i) {
    const int turn = i % 2 == 0 ? 1 : -1;                                        // G3 then G2
    const double nx = -std::sin(heading) * turn, ny = std::cos(heading) * turn;  // toward the centre
    const double cx = x + radius_mm * nx, cy = y + radius_mm * ny;
    const double a0 = std::atan2(y - cy, x - cx), a1 = a0 + turn * sweep;
    const double ex = cx + radius_mm * std::cos(a1), ey = cy + radius_mm * std::sin(a1);
    canon::ArcFeed a;
    a.plane = canon::Plane::XY;
    a.first_end = ex;
    a.second_end = ey;
    a.first_center = cx;
    a.second_center = cy;
    a.rotation = turn;
    a.axis_end = 0;
    a.end = xyz(ex, ey);
    b.arc_feed(id++, a);
    x = ex;
    y = ey;
    heading += turn * sweep;
  }
  b.program_end();
  return b.take();
}

}  // namespace opencnc::analysis
