// SPDX-License-Identifier: GPL-3.0-or-later
// Cutter radius compensation: seeded property tests of the offset geometry on random closed
// contours of lines and arcs (G17 and G18, both sides, both directions), corners against
// LinuxCNC's rules, gouges reported and never cut, errors, and replay inside a contour.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gcode_test_util.hpp"
#include "opencnc/canon/rs274_printer.hpp"
#include "opencnc/canon/tee_sink.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

using namespace opencnc;
using namespace opencnc::gcode;

namespace {

constexpr double kPi = std::numbers::pi;
using Pt = std::array<double, 2>;  // (first, second) of the comp plane: XY = (x, y), XZ = (z, x)

Pt operator-(Pt a, Pt b) {
  return {a[0] - b[0], a[1] - b[1]};
}
Pt operator+(Pt a, Pt b) {
  return {a[0] + b[0], a[1] + b[1]};
}
Pt operator*(double k, Pt a) {
  return {k * a[0], k * a[1]};
}
double dot(Pt a, Pt b) {
  return a[0] * b[0] + a[1] * b[1];
}
double cross(Pt a, Pt b) {
  return a[0] * b[1] - a[1] * b[0];
}
double norm(Pt a) {
  return std::hypot(a[0], a[1]);
}
Pt unit(Pt a) {
  return (1.0 / norm(a)) * a;
}
Pt left_normal(Pt d) {
  return {-d[1], d[0]};
}

// A line or an arc of a planar path (turn: G3 = +1, G2 = -1).
struct Element {
  bool arc = false;
  Pt a{}, b{}, c{};
  int turn = 0;
  std::uint32_t line = 0;  // source line (output elements)
};

double radius(const Element& e) {
  return norm(e.a - e.c);
}

// Signed sweep (rad) of an arc from a to b (a full circle when they coincide).
double sweep(const Element& e) {
  double s = std::atan2(e.a[1] - e.c[1], e.a[0] - e.c[0]);
  double t = std::atan2(e.b[1] - e.c[1], e.b[0] - e.c[0]);
  double d = e.turn > 0 ? t - s : s - t;
  while (d <= 1e-12) d += 2 * kPi;
  return e.turn > 0 ? d : -d;
}

Pt point_at(const Element& e, double u) {
  if (!e.arc) return e.a + u * (e.b - e.a);
  const double s = std::atan2(e.a[1] - e.c[1], e.a[0] - e.c[0]) + u * sweep(e);
  return e.c + radius(e) * Pt{std::cos(s), std::sin(s)};
}

double distance(const Element& e, Pt q) {
  if (!e.arc) {
    const Pt d = e.b - e.a;
    const double u = std::clamp(dot(q - e.a, d) / dot(d, d), 0.0, 1.0);
    return norm(q - (e.a + u * d));
  }
  const double sw = sweep(e);
  const double s = std::atan2(e.a[1] - e.c[1], e.a[0] - e.c[0]);
  double t = std::atan2(q[1] - e.c[1], q[0] - e.c[0]) - s;
  if (sw < 0) t = -t;
  while (t < 0) t += 2 * kPi;
  while (t >= 2 * kPi) t -= 2 * kPi;
  if (t <= std::fabs(sw)) return std::fabs(norm(q - e.c) - radius(e));
  return std::min(norm(q - e.a), norm(q - e.b));
}

double distance(const std::vector<Element>& path, Pt q) {
  double d = 1e300;
  for (const Element& e : path) d = std::min(d, distance(e, q));
  return d;
}

// Unit tangent at the start (u = 0) or end (u = 1) of an element, in its direction.
Pt tangent(const Element& e, double u) {
  if (!e.arc) return unit(e.b - e.a);
  const Pt radial = unit(point_at(e, u) - e.c);
  return e.turn > 0 ? left_normal(radial) : -1.0 * left_normal(radial);
}

// Collects the output path in plane coordinates, with the source line of each motion.
class PathSink : public canon::Sink {
 public:
  explicit PathSink(canon::Plane plane) : xz_(plane == canon::Plane::XZ) {}
  void begin_block(const canon::BlockOrigin& o) override { line_ = o.line; }
  void straight_traverse(canon::SegmentId, const Pose& end) override { line_to(end); }
  void straight_feed(canon::SegmentId, const Pose& end) override { line_to(end); }
  void arc_feed(canon::SegmentId, const canon::ArcFeed& a) override {
    Element e;
    e.arc = true;
    e.a = at_;
    e.b = {a.first_end, a.second_end};
    e.c = {a.first_center, a.second_center};
    e.turn = a.rotation;
    e.line = line_;
    path.push_back(e);
    at_ = e.b;
  }
  std::vector<Element> path;

 private:
  void line_to(const Pose& end) {
    const Pt p = xz_ ? Pt{end[2], end[0]} : Pt{end[0], end[1]};
    path.push_back({false, at_, p, {}, 0, line_});
    at_ = p;
  }
  bool xz_;
  Pt at_{};
  std::uint32_t line_ = 0;
};

// A random closed contour around the origin (star-shaped, wide compared with the tool),
// written as a compensated program: entry from the origin to the middle M of the closing
// line, the contour from M round to M, once more to the first vertex, then G40 back.
struct Contour {
  std::vector<Element> elements;  // programmed, M -> v0 -> ... -> M
  std::string program;
  std::uint32_t first_checked = 0, last_checked = 0;  // source lines whose output must be at r
  double r = 0;
  bool left = true;
  canon::Plane plane = canon::Plane::XY;
};

// Turn (rad, + = left) between the end of `in` and the start of `out`.
double turn_between(const Element& in, const Element& out) {
  const Pt t1 = tangent(in, 1), t2 = tangent(out, 0);
  return std::atan2(cross(t1, t2), dot(t1, t2));
}

// A contour the tool (radius up to 2) can follow all round: no corner LinuxCNC treats as
// straight (< 0.05 rad, where the offset falls slightly short of r), no hairpin, and away from
// its ends every element keeps clear of the others.
bool wide(const std::vector<Element>& edges) {
  const std::size_t n = edges.size();
  if (norm(0.5 * (edges.back().a + edges.back().b)) < 6.0) return false;  // room for the entry move
  for (std::size_t i = 0; i < n; ++i) {
    const double t = std::fabs(turn_between(edges[i], edges[(i + 1) % n]));
    if (t < 0.1 || t > kPi - 0.3) return false;
    for (int k = 1; k < 8; ++k) {
      const Pt q = point_at(edges[i], 0.1 + 0.8 * k / 8.0);
      for (std::size_t j = 0; j < n; ++j) {
        if (j != i && distance(edges[j], q) < 6.0) return false;
      }
    }
  }
  return true;
}

std::vector<Element> random_outline(std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (;;) {
    const int n = 3 + static_cast<int>(rng() % 6);
    // Vertices at increasing angles round the origin, 25..40 from it.
    std::vector<Pt> v;
    for (int i = 0; i < n; ++i) {
      const double a = (i + 0.15 + 0.7 * u01(rng)) * 2 * kPi / n;
      const double rad = 25 + 15 * u01(rng);
      v.push_back({rad * std::cos(a), rad * std::sin(a)});
    }
    // Edge i goes v[i] -> v[i+1]; the last (v[n-1] -> v[0]) stays a line: M lies on it.
    std::vector<Element> edges;
    for (int i = 0; i < n; ++i) {
      Element e;
      e.a = v[static_cast<std::size_t>(i)];
      e.b = v[static_cast<std::size_t>((i + 1) % n)];
      if (i + 1 < n && u01(rng) < 0.5) {
        // An arc through both ends with sagitta h (left of the chord for h > 0: clockwise).
        const double length = norm(e.b - e.a);
        const double h = (u01(rng) < 0.5 ? -1 : 1) * (0.05 + 0.2 * u01(rng)) * length;
        const double rad = (length * length / 4 + h * h) / (2 * std::fabs(h));
        const Pt mid = 0.5 * (e.a + e.b);
        e.arc = true;
        e.c = mid + (h - (h > 0 ? rad : -rad)) * left_normal(unit(e.b - e.a));
        e.turn = h > 0 ? -1 : 1;
      }
      edges.push_back(e);
    }
    if (wide(edges)) return edges;
  }
}

Contour random_contour(std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Contour c;
  std::vector<Element> edges = random_outline(rng);
  if (rng() % 2) {  // clockwise: the same outline backwards
    std::vector<Element> back;
    for (auto it = edges.rbegin(); it != edges.rend(); ++it)
      back.push_back({it->arc, it->b, it->a, it->c, -it->turn, 0});
    // keep the closing line last
    std::rotate(back.begin(), back.begin() + 1, back.end());
    edges = back;
  }
  const Element& closing = edges.back();
  const Pt m = 0.5 * (closing.a + closing.b);
  c.elements.push_back({false, m, closing.b, {}, 0, 0});
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) c.elements.push_back(edges[i]);
  c.elements.push_back({false, closing.a, m, {}, 0, 0});
  c.r = 0.5 + 1.5 * u01(rng);
  c.left = rng() % 2 == 0;
  c.plane = rng() % 3 == 0 ? canon::Plane::XZ : canon::Plane::XY;
  const bool xz = c.plane == canon::Plane::XZ;
  const char a1 = xz ? 'Z' : 'X', a2 = xz ? 'X' : 'Y', i1 = xz ? 'K' : 'I', i2 = xz ? 'I' : 'J';
  auto at = [&](Pt p) { return fmt::format("{}{:.12f} {}{:.12f}", a1, p[0], a2, p[1]); };
  std::vector<std::string> lines = {xz ? "G18 G21 G90 F100" : "G17 G21 G90 F100", "G0 " + at({0, 0}),
                                    fmt::format("G4{}.1 D{:.12f}", c.left ? 1 : 2, 2 * c.r), "G1 " + at(m)};
  auto move = [&](const Element& e) {
    if (!e.arc) return "G1 " + at(e.b);
    return fmt::format("G{} {} {}{:.12f} {}{:.12f}", e.turn > 0 ? 3 : 2, at(e.b), i1, e.c[0] - e.a[0], i2,
                       e.c[1] - e.a[1]);
  };
  for (const Element& e : c.elements) lines.push_back(move(e));
  // Lines are 1-based; the first contour move is line 5 (M -> v0), its corner is not checked.
  c.first_checked = 6;
  c.last_checked = static_cast<std::uint32_t>(lines.size());
  lines.push_back("G1 " + at(c.elements.front().b));  // once more to v0: the last corner is a real one
  lines.push_back("G40 G1 " + at({0, 0}));
  lines.push_back("M2");
  for (const auto& l : lines) c.program += l + "\n";
  return c;
}

struct CompRun {
  RunStatus status = RunStatus::Ok;
  std::string code;
  std::uint32_t error_line = 0;
  std::vector<Element> path;
};

CompRun run_comp(const std::string& program, canon::Plane plane) {
  Options options;
  options.extensions = standard_extensions(Dialect::LinuxCnc);
  Interpreter interp(options);
  interp.open_text("comp.ngc", program);
  PathSink sink(plane);
  CompRun r;
  r.status = interp.run(sink);
  for (const auto& d : interp.diagnostics().items()) {
    if (d.severity == Severity::Error && r.code.empty()) {
      r.code = d.code;
      r.error_line = d.line;
    }
  }
  r.path = std::move(sink.path);
  return r;
}

// Every point of the output from `first` to `last` (source lines) lies exactly r from the
// programmed contour.
void expect_offset_by_r(const Contour& c, const std::vector<Element>& path, std::uint32_t first,
                        std::uint32_t last) {
  int checked = 0;
  for (const Element& e : path) {
    if (e.line < first || e.line > last) continue;
    for (int k = 0; k <= 8; ++k) {
      const Pt q = point_at(e, k / 8.0);
      ASSERT_NEAR(distance(c.elements, q), c.r, 1e-7)
          << "output of line " << e.line << " at " << q[0] << "," << q[1];
    }
    ++checked;
  }
  EXPECT_GE(checked, static_cast<int>(c.elements.size()) - 2);
}

// Line-to-line corners as LinuxCNC makes them: a convex corner gets an arc of radius r about
// the corner point (clockwise for G41); a concave one ends both offset lines where they cross.
void expect_linuxcnc_corners(const Contour& c, const std::vector<Element>& path) {
  for (std::size_t i = 1; i + 1 < c.elements.size(); ++i) {
    const Element& in = c.elements[i];
    const Element& out = c.elements[i + 1];
    if (in.arc || out.arc) continue;
    const Pt v = in.b;
    const double turn = turn_between(in, out);
    const bool convex = c.left ? turn < 0 : turn > 0;
    bool found = false;
    for (const Element& e : path) {
      if (convex) {
        found |=
            e.arc && norm(e.c - v) < 1e-9 && std::fabs(radius(e) - c.r) < 1e-9 && e.turn == (c.left ? -1 : 1);
      } else {
        const Pt n1 = (c.left ? 1.0 : -1.0) * left_normal(unit(in.b - in.a));
        const Pt n2 = (c.left ? 1.0 : -1.0) * left_normal(unit(out.b - out.a));
        const Pt meet = v + (c.r / (1 + dot(n1, n2))) * (n1 + n2);
        found |= !e.arc && norm(e.b - meet) < 1e-9;
      }
    }
    EXPECT_TRUE(found) << (convex ? "convex" : "concave") << " corner at " << v[0] << "," << v[1];
  }
}

}  // namespace

TEST(CutterCompProperty, RandomContoursAreOffsetByExactlyTheRadius) {
  std::mt19937 rng(20240611);
  int offset = 0, gouges = 0;
  for (int round = 0; round < 300; ++round) {
    const Contour c = random_contour(rng);
    SCOPED_TRACE(c.program);
    const CompRun run = run_comp(c.program, c.plane);
    if (run.status == RunStatus::Error) {
      // A corner the tool cannot reach is reported on the block that closes it; the move
      // into it, which would have to run backwards, never leaves the queue.
      ASSERT_EQ(run.code, "gcode.comp-gouge");
      for (const Element& e : run.path) ASSERT_LT(e.line + 1, run.error_line);
      ++gouges;
      continue;
    }
    ASSERT_EQ(run.status, RunStatus::Finished) << run.code;
    expect_offset_by_r(c, run.path, c.first_checked, c.last_checked);
    expect_linuxcnc_corners(c, run.path);
    if (HasFatalFailure() || HasFailure()) return;
    ++offset;
  }
  // The generator makes wide contours: nearly all of them are cut, none vacuously.
  EXPECT_GE(offset, 270) << gouges << " reported gouges";
}

// A slot in the wall of a pocket: narrower than the tool it is a gouge, reported on the block
// after the slot's end wall, whose cut never leaves the queue (nothing comes closer than r
// to that wall); wider, the tool follows the slot at exactly r.
TEST(CutterCompProperty, SlotsNarrowerThanTheToolAreReportedNeverCut) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int round = 0; round < 100; ++round) {
    const double r = 1 + u01(rng);
    const bool narrow = round % 2 == 0;
    const double w = narrow ? (0.1 + 1.8 * u01(rng)) * r : (2.05 + 2 * u01(rng)) * r;
    const double depth = (2.5 + 3 * u01(rng)) * r;
    const double x = 10 + 30 * u01(rng);
    // A pocket 60 x 40 cut anticlockwise with the tool inside (G41); the slot opens upwards.
    const std::vector<Pt> v = {{30, 0},         {60, 0}, {60, 40}, {x + w, 40}, {x + w, 40 + depth},
                               {x, 40 + depth}, {x, 40}, {0, 40},  {0, 0},      {30, 0}};
    Contour c;
    c.r = r;
    std::string p = fmt::format("G17 G21 G90 F100\nG0 X30 Y20\nG41.1 D{:.12f}\nG1 X30 Y0\n", 2 * r);
    for (std::size_t i = 1; i < v.size(); ++i) {
      c.elements.push_back({false, v[i - 1], v[i], {}, 0, 0});
      p += fmt::format("G1 X{:.12f} Y{:.12f}\n", v[i][0], v[i][1]);
    }
    p += "G1 X60 Y0\nG40 G1 X30 Y20\nM2\n";
    SCOPED_TRACE(p);
    const CompRun run = run_comp(p, canon::Plane::XY);
    if (narrow) {
      ASSERT_EQ(run.status, RunStatus::Error);
      EXPECT_EQ(run.code, "gcode.comp-gouge");
      EXPECT_EQ(run.error_line, 10u);  // the wall back down closes the corner after the end wall
      const Element& end_wall = c.elements[4];
      for (const Element& e : run.path) {
        EXPECT_LT(e.line, 9u);
        for (int k = 0; k <= 8; ++k) ASSERT_GE(distance(end_wall, point_at(e, k / 8.0)), r - 1e-7);
      }
    } else {
      ASSERT_EQ(run.status, RunStatus::Finished) << run.code;
      expect_offset_by_r(c, run.path, 6, 3 + static_cast<std::uint32_t>(v.size()));
    }
  }
}

// --- exact behaviours ------------------------------------------------------------------------

namespace {

std::shared_ptr<tools::ToolTable> tool_table() {
  Diagnostics diags;
  auto t = tools::ToolTable::parse("T1 P1 Z1 D0.25\nT5 P5 Z0 D0\nT7 P7 Z0.1 D0.04 Q2\n", "t.tbl", diags);
  return std::make_shared<tools::ToolTable>(std::move(t));
}

test::Result run_text(const std::string& program) {
  Options options;
  options.extensions = standard_extensions(Dialect::LinuxCnc);
  options.tool_table = tool_table();
  return test::run(program, options);
}

}  // namespace

TEST(CutterComp, ANegativeDiameterOffsetsToTheOtherSide) {
  const std::string body = "G1 X0 Y0\nG1 X30\nG1 Y20\nG40 G1 X40 Y30\nM2\n";
  const auto neg = run_text("G21 F100\nG0 X-10 Y-10\nG41.1 D-4\n" + body);
  const auto pos = run_text("G21 F100\nG0 X-10 Y-10\nG42.1 D4\n" + body);
  ASSERT_EQ(neg.status, RunStatus::Finished);
  ASSERT_EQ(neg.calls.size(), pos.calls.size());
  for (std::size_t i = 0; i < neg.calls.size(); ++i) {
    if (neg.calls[i].starts_with("COMMENT")) continue;
    EXPECT_EQ(neg.calls[i], pos.calls[i]);
  }
  EXPECT_NE(std::find(neg.calls.begin(), neg.calls.end(),
                      "COMMENT(\"interpreter: cutter radius compensation on right\")"),
            neg.calls.end());
}

TEST(CutterComp, AZeroRadiusLeavesThePathAsProgrammed) {
  const std::string body = "G1 X0 Y0\nG1 X30\nG2 X40 Y10 R10\nG40 G1 X40 Y30\nM2\n";
  const auto comp = run_text("G21 F100\nG0 X-10 Y-10\nT5 M6\nG41\n" + body);
  const auto plain = run_text("G21 F100\nG0 X-10 Y-10\nT5 M6\n" + body);
  ASSERT_EQ(comp.status, RunStatus::Finished);
  std::vector<std::string> a, b;
  for (const auto& c : comp.calls)
    if (!c.starts_with("COMMENT")) a.push_back(c);
  for (const auto& c : plain.calls)
    if (!c.starts_with("COMMENT")) b.push_back(c);
  EXPECT_EQ(a, b);
}

TEST(CutterComp, HeldMovesAreInTheInterpreterState) {
  Options options;
  options.extensions = standard_extensions(Dialect::LinuxCnc);
  Interpreter interp(options);
  interp.open_text("held.ngc",
                   "G21 F100\nG0 X-10 Y-10\nG41.1 D2\nG1 X0 Y0\nG1 X30\nF50\nG40 G1 X40 Y-10\nM2\n");
  canon::Sink quiet;
  for (int i = 0; i < 4; ++i) ASSERT_EQ(interp.step(quiet), RunStatus::Ok);
  InterpState s = interp.state();
  ASSERT_EQ(s.comp.queued.size(), 1u);  // the entry move, waiting for its corner
  EXPECT_EQ(s.comp.queued[0].kind, CompQueuedMove::Kind::Feed);
  EXPECT_TRUE(s.comp.start_valid);
  EXPECT_EQ(s.position.programmed[0], 0.0);
  const std::uint64_t before = s.digest();
  ASSERT_EQ(interp.step(quiet), RunStatus::Ok);  // G1 X30: the entry is released, X30 held
  s = interp.state();
  ASSERT_EQ(s.comp.queued.size(), 1u);
  EXPECT_NE(s.digest(), before);
  EXPECT_EQ(s.position.current[1], 1.0);  // left of +X by the radius
  ASSERT_EQ(interp.run(quiet), RunStatus::Finished);
  EXPECT_TRUE(interp.state().comp.queued.empty());
}

TEST(CutterComp, ErrorsNameTheirProblem) {
  struct Case {
    const char* program;
    const char* code;
  };
  const Case cases[] = {
      {"G21 G19 F100\nG41.1 D2\nM2\n", "gcode.comp-yz-plane"},
      {"G21 F100\nG41.1 D2 L3\nM2\n", "gcode.comp-wrong-plane"},
      {"G21 F100\nT7 M6\nG41\nM2\n", "gcode.comp-wrong-plane"},
      {"G21 F100\nG41.1 D2\nG42.1 D2\nM2\n", "gcode.comp-already-on"},
      {"G21 F100\nG41.1\nM2\n", "gcode.comp-diameter-missing"},
      {"G21 F100\nG41 D1.5\nM2\n", "gcode.comp-tool-number"},
      {"G21 F100\nG41 D9\nM2\n", "gcode.tool-not-found"},
      {"G21 F100\nG41.1 D4\nG1 X1.5\nM2\n", "gcode.comp-entry-too-short"},
      {"G21 F100\nG41.1 D4\nG3 X1 Y1 R1\nM2\n", "gcode.comp-entry-too-short"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG3 X2 Y0 I1 J0\nM2\n", "gcode.comp-arc-too-small"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG1 X20\nG1 Y2\nG1 X0\nM2\n", "gcode.comp-gouge"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG1 X20\nG40 G2 X30 Y-10 I0 J-10\nM2\n", "gcode.comp-exit-arc"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG18\nM2\n", "gcode.comp-plane-change"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG55\nM2\n", "gcode.comp-coordinate-system"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG53 G1 X5\nM2\n", "gcode.comp-g53"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG28\nM2\n", "gcode.comp-g28-g30"},
      {"G21 F100\nG0 X-10\nG41.1 D4\nG1 X0\nG43.1 Z1\nM2\n", "gcode.comp-tool-offset"},
      {"G21 F100\nT1 M6\nG0 X-10\nG41\nG1 X0\nT1 M6\nM2\n", "gcode.comp-tool-change"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.program);
    const auto r = run_text(c.program);
    EXPECT_EQ(r.status, RunStatus::Error);
    EXPECT_EQ(r.code(), c.code);
  }
}

// --- replay inside a compensated contour --------------------------------------------------

namespace {

struct Replay {
  std::vector<std::string> lines;   // printed calls without the sequence number
  std::vector<InterpState> states;  // state as each motion arrived
  RunStatus status = RunStatus::Ok;
};

class StateAtMotion : public canon::Sink {
 public:
  StateAtMotion(const Interpreter& interp, std::vector<InterpState>& states)
      : interp_(interp), states_(states) {}
  void straight_traverse(canon::SegmentId id, const Pose&) override { capture(id); }
  void straight_feed(canon::SegmentId id, const Pose&) override { capture(id); }
  void arc_feed(canon::SegmentId id, const canon::ArcFeed&) override { capture(id); }

 private:
  void capture(canon::SegmentId id) {
    if (states_.size() <= id) states_.resize(id + 1);
    states_[id] = interp_.state();
  }
  const Interpreter& interp_;
  std::vector<InterpState>& states_;
};

Replay replay(const std::string& program, canon::SegmentId quiet) {
  Options options;
  options.extensions = standard_extensions(Dialect::LinuxCnc);
  options.quiet_until_segment = quiet;
  Interpreter interp(options);
  interp.open_text("replay.ngc", program);
  Replay r;
  StateAtMotion states(interp, r.states);
  test::MemoryStream out;
  {
    canon::Rs274Printer printer(out.file(), out.file());
    canon::TeeSink tee(printer, states);
    canon::Sink nowhere;
    interp.start(nowhere);
    r.status = interp.run(tee);
  }
  const std::string text = out.text();
  for (std::size_t pos = 0; pos < text.size();) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    if (nl - pos > 6) r.lines.push_back(text.substr(pos + 6, nl - pos - 6));
    pos = nl + 1;
  }
  return r;
}

}  // namespace

// Replaying to any segment of a compensated contour (moves held in the queue, calls queued
// behind them) gives the state and the rest of the output of the uninterrupted run.
TEST(CutterCompReplay, AnySegmentInsideAContourReplaysExactly) {
  std::mt19937 rng(5);
  for (int round = 0; round < 4; ++round) {
    Contour c = random_contour(rng);
    // Calls between the moves: they wait in the queue behind the held move.
    std::string program;
    int n = 0;
    for (std::size_t pos = 0; pos < c.program.size();) {
      const std::size_t nl = c.program.find('\n', pos);
      program += c.program.substr(pos, nl - pos + 1);
      if (++n > 4 && n % 2 == 0) program += fmt::format("F{}\n(between {})\n", 100 + n, n);
      pos = nl + 1;
    }
    SCOPED_TRACE(program);
    const Replay full = replay(program, 0);
    if (full.status != RunStatus::Finished) continue;
    for (canon::SegmentId k = 1; k < full.states.size(); ++k) {
      SCOPED_TRACE("replay to segment " + std::to_string(k));
      const Replay part = replay(program, k);
      ASSERT_EQ(part.status, RunStatus::Finished);
      ASSERT_EQ(part.states.size(), full.states.size());
      EXPECT_EQ(part.states[k], full.states[k]);
      EXPECT_EQ(part.states[k].digest(), full.states[k].digest());
      ASSERT_LE(part.lines.size(), full.lines.size());
      EXPECT_TRUE(std::equal(part.lines.begin(), part.lines.end(),
                             full.lines.end() - static_cast<std::ptrdiff_t>(part.lines.size())));
    }
  }
}
