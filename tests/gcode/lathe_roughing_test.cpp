// SPDX-License-Identifier: GPL-3.0-or-later
// The roughing engine (gcode::lathe): an exact hand-traced case, and seeded properties of the
// passes (mirror and rotation symmetry, no cut into the allowance, layer spacing, G70 passes).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "opencnc/gcode/lathe_roughing.hpp"

using namespace opencnc::gcode::lathe;

namespace {

struct Move {
  char kind;   // 'r' rapid, 'f' feed, 'c' arc
  Point end, center;
  bool ccw = false;
};

class Recorder final : public PathSink {
 public:
  void rapid(Point e) override { moves.push_back({'r', e, {}, false}); }
  void feed(Point e) override { moves.push_back({'f', e, {}, false}); }
  void arc(Point e, Point c, bool ccw) override { moves.push_back({'c', e, c, ccw}); }
  std::vector<Move> moves;
};

ProfileElement line(Point a, Point b) { return {ProfileElement::Kind::Line, a, b, {}, false, 0}; }

// A point from X and Z (the engine's points are Z + jX).
Point xz(double x, double z) { return {z, x}; }

// A random type I turning contour (Z falling, X never falling) from a start point above it,
// made of lines; `arcs` adds arcs between some points.
Profile random_contour(std::mt19937_64& rng, bool arcs, Point& start) {
  std::uniform_real_distribution<double> step(0.6, 4.0), rise(0.3, 2.5), unit(0.0, 1.0);
  Profile p;
  double x = 1.0 + unit(rng) * 3, z = 0;
  start = xz(x + 8 + 4 * unit(rng), 1 + unit(rng));
  p.push_back(line(start, xz(x, z)));
  const int n = 3 + static_cast<int>(unit(rng) * 5);
  bool flat = false;
  for (int i = 0; i < n; ++i) {
    const Point a = xz(x, z);
    z -= step(rng);
    if (flat || unit(rng) < 0.6) x += rise(rng);   // never two flat lines in a row (collinear)
    const Point b = xz(x, z);
    flat = a.imag() == b.imag();
    if (arcs && !flat && unit(rng) < 0.4) {
      // A convex bump (G3 seen with Z right, X up): the centre on the chord's bisector, below
      // both ends, so that the arc keeps falling in Z (monotonic, as the cycles need).
      const Point mid = (a + b) / 2.0, chord = b - a;
      const double len = std::abs(chord);
      const double t = (b.imag() - a.imag()) * len / (2 * (a.real() - b.real())) + (0.2 + 1.3 * unit(rng)) * len;
      const Point centre = mid + t * Point(0, 1) * chord / len;
      p.push_back({ProfileElement::Kind::Arc, a, b, centre, true, 0});
      continue;
    }
    p.push_back(line(a, b));
  }
  // The start point clears the contour (above its highest point, right of its first one).
  double top = 0;
  for (const auto& e : p) top = std::max(top, e.end.imag());
  start = xz(top + 0.5 + 3 * unit(rng), start.real());
  p.front().start = start;
  return p;
}

Profile mirrored_x(Profile p) {
  for (auto& e : p) {
    e.start = std::conj(e.start), e.end = std::conj(e.end), e.center = std::conj(e.center);
    e.ccw = !e.ccw;
  }
  return p;
}

Profile rotated(Profile p) {   // the facing frame of a turning profile: Z -> X, X -> -Z
  for (auto& e : p) {
    e.start = -e.start * Point(0, 1), e.end = -e.end * Point(0, 1), e.center = -e.center * Point(0, 1);
  }
  return p;
}

bool near(Point a, Point b, double tol = 1e-9) { return std::abs(a - b) <= tol; }

double distance_to_segment(Point p, Point a, Point b) {
  const Point d = b - a;
  const double len2 = std::norm(d);
  const double t = len2 > 0 ? std::clamp(std::real(std::conj(d) * (p - a)) / len2, 0.0, 1.0) : 0.0;
  return std::abs(p - (a + t * d));
}

}  // namespace

TEST(LatheRoughing, StepProfileMatchesHandTrace) {
  // X10 Z1 start; contour X2 Z0, Z-5, X6, Z-10. Depth 2, retract 0.5, no allowance: layers at
  // X10, 8, 6, 4, each from the approach line to the contour, lift-off at 45° and back at
  // rapid; then along the contour (traced by hand; rs274 prints the same).
  Profile p{line(xz(10, 1), xz(2, 0)), line(xz(2, 0), xz(2, -5)), line(xz(2, -5), xz(6, -5)),
            line(xz(6, -5), xz(6, -10))};
  RoughingParams params;
  params.start = xz(10, 1);
  params.depth = 2;
  params.retract = 0.5;
  Recorder out;
  rough(p, params, out);
  const std::vector<std::pair<char, Point>> want{
      {'r', xz(10, 1)},     {'r', xz(10, 1)},      {'f', xz(10, -10)},   {'r', xz(10.5, -9.5)}, {'r', xz(10.5, 0.5)},
      {'r', xz(10, 1)},     {'r', xz(8, 0.75)},    {'f', xz(8, -10)},    {'r', xz(8.5, -9.5)},  {'r', xz(8.5, 0.25)},
      {'r', xz(8, 0.75)},   {'r', xz(6, 0.5)},     {'f', xz(6, -5)},     {'r', xz(6.5, -4.5)},  {'r', xz(6.5, 0)},
      {'r', xz(6, 0.5)},    {'r', xz(4, 0.25)},    {'f', xz(4, -5)},     {'r', xz(4.5, -4.5)},  {'r', xz(4.5, -0.25)},
      {'r', xz(4, 0.25)},   {'r', xz(2, 0)},       {'f', xz(2, -5)},     {'f', xz(6, -5)},      {'f', xz(6, -10)},
      {'f', xz(10, -10)}};
  ASSERT_EQ(out.moves.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(out.moves[i].kind, want[i].first) << "move " << i;
    EXPECT_TRUE(near(out.moves[i].end, want[i].second, 1e-12)) << "move " << i << ": " << out.moves[i].end;
  }
}

TEST(LatheRoughing, CollinearLinesAndUTurnsAreRejected) {
  Recorder out;
  RoughingParams params;
  params.start = xz(12, 2);
  params.allowance = 0.5;
  const Profile collinear{line(xz(12, 2), xz(5, 0)), line(xz(5, 0), xz(5, -5)), line(xz(5, -5), xz(5, -10)),
                          line(xz(5, -10), xz(8, -10))};
  try {
    rough(collinear, params, out);
    FAIL() << "collinear lines were accepted";
  } catch (const RoughingError& e) {
    EXPECT_EQ(e.kind(), RoughingError::Kind::ParallelLines);
  }
  const Profile back{line(xz(12, 2), xz(5, 0)), line(xz(5, 0), xz(5, -5)), line(xz(5, -5), xz(8, -2)),
                     line(xz(8, -2), xz(8, -9))};
  try {
    rough(back, params, out);
    FAIL() << "a profile going back towards +Z was accepted";
  } catch (const RoughingError& e) {
    EXPECT_EQ(e.kind(), RoughingError::Kind::NotMonotonic);
  }
}

TEST(LatheRoughing, ShortProfilesMakeNoMotion) {
  Recorder out;
  RoughingParams params;
  rough(Profile{line(xz(10, 1), xz(2, 0))}, params, out);
  finish(Profile{}, FinishingParams{}, out);
  EXPECT_TRUE(out.moves.empty());
}

// Mirroring the profile about the Z axis mirrors every move (and reverses arcs); the engine
// normalises both to the same working frame.
TEST(LatheRoughingProperty, MirrorInXMirrorsThePasses) {
  std::mt19937_64 rng(20240611);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Point start;
    const Profile p = random_contour(rng, true, start);
    RoughingParams params;
    params.start = start;
    params.allowance = (trial % 3) * 0.2;
    params.depth = 0.4 + 0.1 * (trial % 7);
    params.retract = 0.3;
    params.pockets = static_cast<Pockets>(trial % 3);
    Recorder a, b;
    RoughingParams mirrored = params;
    mirrored.start = std::conj(start);
    bool ok_a = true, ok_b = true;
    try { rough(p, params, a); } catch (const RoughingError&) { ok_a = false; }
    try { rough(mirrored_x(p), mirrored, b); } catch (const RoughingError&) { ok_b = false; }
    ASSERT_EQ(ok_a, ok_b) << "trial " << trial;
    if (!ok_a) continue;
    ASSERT_EQ(a.moves.size(), b.moves.size()) << "trial " << trial;
    for (std::size_t i = 0; i < a.moves.size(); ++i) {
      EXPECT_EQ(a.moves[i].kind, b.moves[i].kind);
      EXPECT_TRUE(near(std::conj(a.moves[i].end), b.moves[i].end)) << "trial " << trial << " move " << i;
      if (a.moves[i].kind == 'c') {
        EXPECT_TRUE(near(std::conj(a.moves[i].center), b.moves[i].center));
        EXPECT_NE(a.moves[i].ccw, b.moves[i].ccw);
      }
    }
    ++compared;
  }
  EXPECT_GT(compared, 200);
}

// G72 on a profile is G71 on the profile turned by 90°, turned back.
TEST(LatheRoughingProperty, FacingIsTurningRotated) {
  std::mt19937_64 rng(77);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Point start;
    const Profile turning = random_contour(rng, true, start);
    // The same contour as a facing profile: rotate it the other way.
    Profile facing = turning;
    for (auto& e : facing) e.start *= Point(0, 1), e.end *= Point(0, 1), e.center *= Point(0, 1);
    RoughingParams t;
    t.start = start;
    t.allowance = 0.25 * (trial % 2);
    t.depth = 0.7;
    RoughingParams f = t;
    f.direction = Direction::Facing;
    f.start = start * Point(0, 1);
    Recorder a, b;
    bool ok_a = true, ok_b = true;
    try { rough(rotated(facing), t, a); } catch (const RoughingError&) { ok_a = false; }
    try { rough(facing, f, b); } catch (const RoughingError&) { ok_b = false; }
    ASSERT_EQ(ok_a, ok_b) << "trial " << trial;
    if (!ok_a) continue;
    ASSERT_EQ(a.moves.size(), b.moves.size()) << "trial " << trial;
    for (std::size_t i = 0; i < a.moves.size(); ++i) {
      EXPECT_TRUE(near(a.moves[i].end * Point(0, 1), b.moves[i].end)) << "trial " << trial << " move " << i;
    }
    ++compared;
  }
  EXPECT_GT(compared, 200);
}

// With an allowance D, no move of a type I cycle ends closer than D to the contour, every
// cut along Z lies on a layer start.x - k·I, and the tool never leaves the box between the
// contour and the start point (plus the retract).
TEST(LatheRoughingProperty, PassesKeepTheAllowanceAndTheLayers) {
  std::mt19937_64 rng(4242);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Point start;
    const Profile p = random_contour(rng, false, start);
    RoughingParams params;
    params.start = start;
    params.allowance = 0.05 + 0.5 * unit(rng);
    params.depth = 0.3 + unit(rng);
    params.retract = 0.1 + 0.4 * unit(rng);
    params.pockets = Pockets::None;
    Recorder out;
    try {
      rough(p, params, out);
    } catch (const RoughingError&) {
      continue;
    }
    double zmin = start.real();
    for (const auto& e : p) zmin = std::min(zmin, e.end.real());
    Point at = start;
    for (std::size_t i = 0; i < out.moves.size(); ++i) {
      const Move& m = out.moves[i];
      double d = 1e9;
      for (std::size_t k = 1; k < p.size(); ++k) d = std::min(d, distance_to_segment(m.end, p[k].start, p[k].end));
      EXPECT_GE(d, params.allowance - 1e-9) << "trial " << trial << " move " << i;
      EXPECT_LE(m.end.imag(), start.imag() + params.retract + 1e-9);
      EXPECT_LE(m.end.real(), start.real() + 1e-9);
      EXPECT_GE(m.end.real(), zmin - params.allowance - 1e-9);
      const bool layer = m.kind == 'f' && at.imag() == m.end.imag() && i + 1 < out.moves.size() &&
                         out.moves[i + 1].kind == 'r';
      if (layer) {
        const double k = (start.imag() - m.end.imag()) / params.depth;
        EXPECT_NEAR(k, std::round(k), 1e-9) << "trial " << trial << " move " << i;
      }
      at = m.end;
    }
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

// G70: P passes (truncated), each starting with the approach rapid from the start point,
// the allowance falling from D to E: the last pass runs on the contour itself when E = 0.
TEST(LatheRoughingProperty, FinishingPassesStepTheAllowance) {
  std::mt19937_64 rng(99);
  for (int trial = 0; trial < 200; ++trial) {
    Point start;
    const Profile p = random_contour(rng, trial % 2 == 0, start);
    FinishingParams params;
    params.start = start;
    params.first_allowance = 0.6;
    params.last_allowance = 0;
    params.passes = 1 + trial % 3 + 0.5;
    Recorder out;
    try {
      finish(p, params, out);
    } catch (const RoughingError&) {
      continue;
    }
    // Each pass: a rapid to the start point, a rapid to the pass's first point, then feeds.
    int rapids = 0, to_start = 0;
    for (const auto& m : out.moves) {
      if (m.kind != 'r') continue;
      to_start += rapids % 2 == 0 && near(m.end, start);
      ++rapids;
    }
    EXPECT_EQ(rapids, 2 * (1 + trial % 3)) << "trial " << trial;
    EXPECT_EQ(to_start, 1 + trial % 3) << "trial " << trial;
    // The last pass ends where the contour ends.
    EXPECT_TRUE(near(out.moves.back().end, p.back().end, 1e-9)) << "trial " << trial;
    EXPECT_TRUE(near(out.moves.front().end, start)) << "trial " << trial;
  }
}

// --- Fanuc's reading of the profile (Convention::Fanuc) ------------------------------------

namespace {

// The highest point of a line contour over z (lines only), -inf where none is.
double height(const Profile& p, double z) {
  double h = -1e300;
  for (std::size_t k = 1; k < p.size(); ++k) {
    const Point a = p[k].start, b = p[k].end;
    if (z < std::min(a.real(), b.real()) || z > std::max(a.real(), b.real())) continue;
    if (a.real() == b.real()) h = std::max({h, a.imag(), b.imag()});
    else h = std::max(h, a.imag() + (z - a.real()) / (b.real() - a.real()) * (b.imag() - a.imag()));
  }
  return h;
}

// True when q lies inside the part below the contour (not just on its boundary).
bool inside_part(const Profile& p, Point q, double tol) {
  const double z0 = p.back().end.real(), z1 = p[1].start.real();
  if (q.real() <= z0 + tol || q.real() >= z1 - tol) return false;
  return q.imag() < std::min(height(p, q.real() - tol), height(p, q.real() + tol)) - tol;
}

Profile shifted(Profile p, Point d) {
  for (std::size_t k = 1; k < p.size(); ++k) p[k].start += d, p[k].end += d;
  p.front().end = p[1].start;
  return p;
}

}  // namespace

// Fanuc's U/W move the contour: no move of the roughing passes (rapids included, sampled
// along their length) enters the part grown by them; every cut runs on a layer one or more
// depths below the start point; the passes start at the start point itself.
TEST(LatheRoughingProperty, FanucAllowancesShiftTheContourAndNothingCutsIntoIt) {
  std::mt19937_64 rng(5150);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Point start;
    const Profile p = random_contour(rng, false, start);
    RoughingParams params;
    params.convention = Convention::Fanuc;
    params.start = start;
    params.shift = Point(0.4 * unit(rng), 0.4 * unit(rng));
    params.depth = 0.3 + unit(rng);
    params.retract = 0.1 + 0.4 * unit(rng);
    Recorder out;
    try {
      rough(p, params, out);
    } catch (const RoughingError&) {
      continue;
    }
    const Profile part = shifted(p, params.shift);
    EXPECT_EQ(out.moves.front().end, start);
    Point at = start;
    for (std::size_t i = 0; i < out.moves.size(); ++i) {
      const Move& m = out.moves[i];
      ASSERT_NE(m.kind, 'c') << "a line contour gives no arcs";
      for (int s = 0; s <= 16; ++s) {
        const Point q = at + (m.end - at) * (s / 16.0);
        EXPECT_FALSE(inside_part(part, q, 1e-9)) << "trial " << trial << " move " << i << " at " << q;
      }
      EXPECT_LE(m.end.imag(), start.imag() + params.retract + 1e-9);
      const bool layer = m.kind == 'f' && at.imag() == m.end.imag() && i + 1 < out.moves.size() && out.moves[i + 1].kind == 'r';
      if (layer) {
        const double k = (start.imag() - m.end.imag()) / params.depth;
        EXPECT_NEAR(k, std::round(k), 1e-9) << "trial " << trial << " move " << i;
        EXPECT_GE(std::round(k), 1.0) << "the first cut is one depth below the start point";
      }
      at = m.end;
    }
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

// A contour that starts with a face falling towards the axis ends lower than it starts;
// LinuxCNC's rule reads it as a bore, Fanuc's takes the side from the approach: the same
// passes as the contour without its first face, plus the face.
TEST(LatheRoughing, FanucTakesTheStockSideFromTheApproach) {
  // Start X10 Z1; approach to X6 Z1, Z0, face down to X2, then X4 at Z-5 (below X6).
  const Profile p{line(xz(10, 1), xz(6, 1)), line(xz(6, 1), xz(6, 0)), line(xz(6, 0), xz(2, 0)),
                  line(xz(2, 0), xz(4, -5))};
  RoughingParams params;
  params.convention = Convention::Fanuc;
  params.start = xz(10, 1);
  params.depth = 2;
  params.retract = 0.5;
  Recorder out;
  rough(p, params, out);
  // Traced by hand: the layer at X8 runs from the approach to Z-5 (where the contour ends,
  // closed upwards). At X6 the approach ends on the flat: the tool follows it to the face,
  // where a pocket starts; its layers (X6, X4) run from the face to Z-5, lift off at 45° and
  // come back at feed (inside the pocket). At X2, the face's foot, the last pass follows the
  // contour and goes up at Z-5.
  const std::vector<std::pair<char, Point>> want{
      {'r', xz(10, 1)},    {'r', xz(8, 1)},     {'f', xz(8, -5)},   {'r', xz(8.5, -4.5)}, {'r', xz(8.5, 0.5)},
      {'r', xz(8, 1)},     {'r', xz(6, 1)},     {'f', xz(6, 0)},    {'f', xz(6, 0)},      {'f', xz(6, -5)},
      {'r', xz(6.5, -4.5)}, {'r', xz(6.5, -0.5)}, {'f', xz(6, 0)},  {'f', xz(4, 0)},      {'f', xz(4, -5)},
      {'r', xz(4.5, -4.5)}, {'r', xz(4.5, -0.5)}, {'f', xz(4, 0)},  {'f', xz(2, 0)},      {'f', xz(4, -5)},
      {'f', xz(10, -5)}};
  ASSERT_EQ(out.moves.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(out.moves[i].kind, want[i].first) << "move " << i;
    EXPECT_TRUE(near(out.moves[i].end, want[i].second, 1e-12)) << "move " << i << ": " << out.moves[i].end;
  }
  params.convention = Convention::LinuxCnc;   // mirrored: cuts on the wrong side (or fails)
  Recorder linuxcnc;
  try {
    rough(p, params, linuxcnc);
    EXPECT_NE(linuxcnc.moves.size(), want.size());
  } catch (const RoughingError&) {
  }
}

// Lines at the contour's end along or above the start height (a retract to the start point)
// cut nothing: the passes are those of the contour without them.
TEST(LatheRoughing, FanucLeavesOutTheRetractAtTheContoursEnd) {
  const Profile core{line(xz(10, 1), xz(2, 0)), line(xz(2, 0), xz(2, -5)), line(xz(2, -5), xz(6, -5)),
                     line(xz(6, -5), xz(6, -10)), line(xz(6, -10), xz(10, -10))};
  Profile tail = core;
  tail.push_back(line(xz(10, -10), xz(10, 1)));   // back to the start at its height
  RoughingParams params;
  params.convention = Convention::Fanuc;
  params.start = xz(10, 1);
  params.depth = 1.5;
  params.shift = Point(0.2, 0.3);
  Recorder a, b;
  rough(core, params, a);
  rough(tail, params, b);
  ASSERT_EQ(a.moves.size(), b.moves.size());
  for (std::size_t i = 0; i < a.moves.size(); ++i) EXPECT_TRUE(near(a.moves[i].end, b.moves[i].end)) << "move " << i;
  // LinuxCNC's reading keeps the element, which turns back along Z.
  params.convention = Convention::LinuxCnc;
  Recorder c;
  EXPECT_THROW(rough(tail, params, c), RoughingError);
}

// Fanuc's reading in the other frames: a bore (the profile mirrored about the axis, U negative)
// gives the mirrored passes, and G72 on a profile turned by 90° the turned passes; the
// allowance is turned and mirrored with the profile, so it keeps its meaning in each.
TEST(LatheRoughingProperty, FanucBoringAndFacingAreTurningMirroredAndTurned) {
  std::mt19937_64 rng(6060);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Point start;
    const Profile p = random_contour(rng, true, start);
    RoughingParams t;
    t.convention = Convention::Fanuc;
    t.start = start;
    t.shift = Point(0.3 * unit(rng), 0.3 * unit(rng));
    t.depth = 0.4 + unit(rng);
    t.retract = 0.3;
    RoughingParams bore = t;
    bore.start = std::conj(start);
    bore.shift = std::conj(t.shift);
    RoughingParams face = t;
    face.direction = Direction::Facing;
    face.start = start * Point(0, 1);
    face.shift = t.shift * Point(0, 1);
    Profile facing = p;
    for (auto& e : facing) e.start *= Point(0, 1), e.end *= Point(0, 1), e.center *= Point(0, 1);
    Recorder a, b, c;
    bool ok_a = true, ok_b = true, ok_c = true;
    try { rough(p, t, a); } catch (const RoughingError&) { ok_a = false; }
    try { rough(mirrored_x(p), bore, b); } catch (const RoughingError&) { ok_b = false; }
    try { rough(facing, face, c); } catch (const RoughingError&) { ok_c = false; }
    ASSERT_EQ(ok_a, ok_b) << "trial " << trial;
    ASSERT_EQ(ok_a, ok_c) << "trial " << trial;
    if (!ok_a) continue;
    ASSERT_EQ(a.moves.size(), b.moves.size()) << "trial " << trial;
    ASSERT_EQ(a.moves.size(), c.moves.size()) << "trial " << trial;
    for (std::size_t i = 0; i < a.moves.size(); ++i) {
      EXPECT_TRUE(near(std::conj(a.moves[i].end), b.moves[i].end)) << "trial " << trial << " move " << i;
      EXPECT_TRUE(near(a.moves[i].end * Point(0, 1), c.moves[i].end)) << "trial " << trial << " move " << i;
    }
    ++compared;
  }
  EXPECT_GT(compared, 200);
}
