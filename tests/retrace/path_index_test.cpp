// SPDX-License-Identifier: GPL-3.0-or-later
// The path index: feed moves only, subprograms in loops, arcs, the compensated path, crossings
// with candidates, XY and 3D, walking the path; and the property that the tree finds what a scan
// of every move finds, on seeded random programs of lines, arcs and helices, with and without
// kerf compensation.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <fmt/format.h>

#include "../control/test_profiles.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/machine_setup.hpp"
#include "opencnc/retrace/path_scan.hpp"

namespace opencnc::recovery {
namespace {

/// Scans `text` as a program file with the shipped mill's G-code source.
PathIndex index_of(const std::string& text, Diagnostics* diags_out = nullptr) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-path-index-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  Diagnostics d;
  auto source = controller::MachineSetup::create(control::test::mill(), {}, d)->source();
  PathIndex index = scan_path(*source, path, Pose{}, {}, d);
  std::filesystem::remove_all(dir);
  EXPECT_FALSE(d.has_errors()) << (d.items().empty() ? "" : d.items()[0].format());
  if (diags_out != nullptr) *diags_out = d;
  return index;
}

TEST(PathIndex, NearestPointOfASquareAndRapidsLeftOut) {
  const PathIndex ix = index_of(
      "G21 G90 F1000\n"
      "G0 X0 Y0 Z0\n"
      "G1 X100\n"     // segment 1, line 3
      "G1 Y100\n"     // 2
      "G1 X0\n"       // 3
      "G1 Y0\n"       // 4
      "G0 X50 Y50\n"  // a rapid through the middle: never a candidate
      "M2\n");
  EXPECT_EQ(ix.size(), 4u);
  const Nearest n = ix.nearest({40, 52, 7});
  ASSERT_TRUE(n.found);
  EXPECT_NEAR(n.nearest.distance_mm, 40.0, 1e-12);  // to the left side X0, not the rapid
  EXPECT_EQ(n.nearest.segment, 4u);
  EXPECT_EQ(n.nearest.line, 6u);
  EXPECT_NEAR(n.nearest.point[0], 0.0, 1e-12);
  EXPECT_NEAR(n.nearest.point[1], 52.0, 1e-12);
  EXPECT_NEAR(n.nearest.param, 0.48, 1e-12);
  EXPECT_EQ(n.candidates.size(), 1u);
}

TEST(PathIndex, ArcsAndTheirSweep) {
  const PathIndex ix = index_of(
      "G21 G90 F1000\n"
      "G0 X10 Y0\n"
      "G3 X-10 Y0 I-10 J0\n"  // upper half circle about the origin, counterclockwise
      "M2\n");
  ASSERT_EQ(ix.size(), 1u);
  Nearest n = ix.nearest({20 * std::cos(1.0), 20 * std::sin(1.0), 0});
  EXPECT_NEAR(n.nearest.distance_mm, 10.0, 1e-12);
  EXPECT_NEAR(n.nearest.point[0], 10 * std::cos(1.0), 1e-12);
  EXPECT_NEAR(n.nearest.point[1], 10 * std::sin(1.0), 1e-12);
  EXPECT_NEAR(n.nearest.param, 1.0 / 3.14159265358979323846, 1e-12);
  // Below the X axis the sweep does not reach: the nearer end.
  n = ix.nearest({3, -5, 0});
  EXPECT_NEAR(n.nearest.point[0], 10.0, 1e-12);
  EXPECT_NEAR(n.nearest.point[1], 0.0, 1e-12);
}

TEST(PathIndex, SubprogramsInLoopsWithTheirCallStack) {
  const PathIndex ix = index_of(
      "G21 G90 F1000\n"
      "o<part> sub\n"
      "  G0 X[#1] Y0\n"
      "  G91 G1 X10\n"
      "  G1 Y10\n"
      "  G90\n"
      "o<part> endsub\n"
      "#2 = 0\n"
      "o1 while [#2 LT 5]\n"
      "  o<part> call [#2 * 20]\n"
      "  #2 = [#2 + 1]\n"
      "o1 endwhile\n"
      "M2\n");
  EXPECT_EQ(ix.size(), 10u);
  // Near the fourth part's rising edge (X 70, Y 0..10).
  const Nearest n = ix.nearest({71, 5, 0});
  EXPECT_NEAR(n.nearest.distance_mm, 1.0, 1e-12);
  EXPECT_EQ(n.nearest.line, 5u);
  EXPECT_EQ(n.nearest.segment, 3u * 3 + 2);  // a rapid and two feeds per part
  ASSERT_TRUE(ix.sources() != nullptr);
  EXPECT_FALSE(ix.sources()->stack(n.nearest.context).empty());
}

TEST(PathIndex, ThePathThatCrossesItselfGivesEveryStretchNearby) {
  const PathIndex ix = index_of(
      "G21 G90 F1000\n"
      "G0 X0 Y0\n"
      "G1 X10 Y10\n"
      "G0 X0 Y10\n"
      "G1 X10 Y0\n"
      "M2\n");
  QueryOptions o;
  o.margin_mm = 0.2;
  Nearest n = ix.nearest({5, 5.1, 0}, o);
  ASSERT_EQ(n.candidates.size(), 2u);
  EXPECT_EQ(n.candidates[0].segment, n.nearest.segment);
  EXPECT_NEAR(n.candidates[0].distance_mm, n.candidates[1].distance_mm, 1e-12);
  o.margin_mm = 0;
  n = ix.nearest({5.2, 5.5, 0}, o);
  EXPECT_EQ(n.candidates.size(), 1u);
  // Within the margin along one stretch is one candidate, not one per move.
  const PathIndex line = index_of("G21 G90 F1000\nG0 X0 Y0\nG1 X1\nG1 X2\nG1 X3\nM2\n");
  o.margin_mm = 5;
  EXPECT_EQ(line.nearest({1.5, 0.5, 0}, o).candidates.size(), 1u);
}

TEST(PathIndex, KerfCompensationGivesTheCompensatedPath) {
  const PathIndex ix = index_of(
      "G21 G90 F1000\n"
      "G0 X-10 Y0\n"
      "G41.1 D3\n"  // kerf 3 mm: the torch runs 1.5 mm to the left of the programmed contour
      "G1 X0 Y0\n"
      "G1 X50\n"
      "G1 Y50\n"
      "G1 X0\n"
      "G1 Y0\n"
      "G40 G1 X-10\n"
      "M2\n");
  // Inside the square (counterclockwise, left is inside): the path is at Y 1.5 along the bottom.
  const Nearest n = ix.nearest({25, 10, 0});
  EXPECT_NEAR(n.nearest.point[1], 1.5, 1e-9);
  EXPECT_NEAR(n.nearest.distance_mm, 8.5, 1e-9);
  EXPECT_EQ(n.nearest.line, 5u);
}

TEST(PathIndex, TorchHeightIgnoredInXyCountedIn3d) {
  const PathIndex ix = index_of(
      "G21 G90 F1000\n"
      "G0 X0 Y0 Z5\n"
      "G1 Z0\n"  // a plunge at the origin
      "G1 X20\n"
      "G0 Z30\n"
      "G0 X0 Y3\n"
      "G1 Z25\n"
      "G1 X20\n"  // high, 3 mm over
      "M2\n");
  QueryOptions xy;
  xy.margin_mm = 0;
  EXPECT_EQ(ix.nearest({10, 2.9, 0}, xy).nearest.line, 8u);
  QueryOptions xyz = xy;
  xyz.metric = Metric::Xyz;
  const Nearest n = ix.nearest({10, 2.9, 0}, xyz);
  EXPECT_EQ(n.nearest.line, 4u);
  EXPECT_NEAR(n.nearest.distance_mm, 2.9, 1e-12);
}

TEST(PathIndex, WalkingAlongThePath) {
  const PathIndex ix = index_of(
      "G21 G90 F1000\n"
      "G0 X0 Y0\n"
      "G1 X10\n"
      "G2 X20 Y0 I5 J0\n"  // half circle R5 below... clockwise from the left end over the top
      "G0 X50\n"
      "G1 X60\n"
      "M2\n");
  const PathPoint start = ix.nearest({0, 0, 0}).nearest;
  PathPoint p = ix.advance(start, 5);
  EXPECT_NEAR(p.point[0], 5, 1e-12);
  p = ix.advance(start, 10 + 5 * 3.14159265358979323846 / 2);  // a quarter of the half circle on
  EXPECT_NEAR(p.point[0], 15, 1e-9);
  EXPECT_NEAR(p.point[1], 5, 1e-9);
  p = ix.advance(p, 5 * 3.14159265358979323846 / 2 + 4);  // over the rapid: 4 mm into the last line
  EXPECT_NEAR(p.point[0], 54, 1e-9);
  p = ix.advance(p, -1000);  // back to the start, no further
  EXPECT_EQ(p.entry, 0u);
  EXPECT_NEAR(p.point[0], 0, 1e-12);
  p = ix.advance(p, 1000);
  EXPECT_NEAR(p.point[0], 60, 1e-12);
}

/// A seeded random program: lines, arcs in XY, helices, arcs in XZ; with kerf compensation on a
/// closed contour of lines and arcs if `kerf`.
std::string random_program(std::mt19937& rng, int moves, bool kerf) {
  std::uniform_real_distribution<double> coord(-50, 50), unit(0, 1), radius(1, 20);
  std::string g = "G21 G90 F1000\nG0 X0 Y0 Z0\n";
  if (kerf) {
    // A star-like closed contour traced counterclockwise, kerf on the left (outside is right).
    g += "G0 X60 Y0\nG41.1 D2\n";
    const int n = moves;
    for (int i = 1; i <= n; ++i) {
      const double a = 2 * 3.14159265358979323846 * i / n;
      const double r = i == n ? 60 : 40 + 20 * unit(rng);
      const double x = r * std::cos(a), y = r * std::sin(a);
      if (i % 3 == 0) {
        g += fmt::format("G3 X{:.6f} Y{:.6f} R{:.6f}\n", x, y, 200.0);
      } else {
        g += fmt::format("G1 X{:.6f} Y{:.6f}\n", x, y);
      }
    }
    return g + "G40 G0 X0 Y0\nM2\n";
  }
  double x = 0, y = 0, z = 0;
  for (int i = 0; i < moves; ++i) {
    const double k = unit(rng);
    if (k < 0.1) {
      x = coord(rng), y = coord(rng);
      g += fmt::format("G0 X{:.6f} Y{:.6f}\n", x, y);
    } else if (k < 0.45) {
      x = coord(rng), y = coord(rng), z = unit(rng) < 0.2 ? coord(rng) / 10 : z;
      g += fmt::format("G1 X{:.6f} Y{:.6f} Z{:.6f}\n", x, y, z);
    } else if (k < 0.85) {
      const double r = radius(rng), a0 = 6.283185307179586 * unit(rng), a1 = 6.283185307179586 * unit(rng);
      const double cx = x - r * std::cos(a0), cy = y - r * std::sin(a0);
      const double ex = cx + r * std::cos(a1), ey = cy + r * std::sin(a1);
      const bool helix = unit(rng) < 0.3;
      const double ez = helix ? z + coord(rng) / 10 : z;
      g += fmt::format("{} X{:.6f} Y{:.6f} Z{:.6f} I{:.6f} J{:.6f}{}\n", unit(rng) < 0.5 ? "G2" : "G3", ex,
                       ey, ez, cx - x, cy - y, unit(rng) < 0.1 ? " P2" : "");
      x = ex, y = ey, z = ez;
    } else {
      const double r = radius(rng), a0 = 6.283185307179586 * unit(rng), a1 = 6.283185307179586 * unit(rng);
      const double cx = x - r * std::cos(a0), cz = z - r * std::sin(a0);
      const double ex = cx + r * std::cos(a1), ez = cz + r * std::sin(a1);
      g += fmt::format("G18 {} X{:.6f} Z{:.6f} I{:.6f} K{:.6f}\nG17\n", unit(rng) < 0.5 ? "G2" : "G3", ex, ez,
                       cx - x, cz - z);
      x = ex, z = ez;
    }
  }
  return g + "M2\n";
}

void expect_same(const Nearest& a, const Nearest& b, const std::string& what) {
  ASSERT_EQ(a.found, b.found) << what;
  ASSERT_EQ(a.candidates.size(), b.candidates.size()) << what;
  for (std::size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_EQ(a.candidates[i].entry, b.candidates[i].entry) << what;
    EXPECT_EQ(a.candidates[i].segment, b.candidates[i].segment) << what;
    EXPECT_EQ(a.candidates[i].distance_mm, b.candidates[i].distance_mm) << what;
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.candidates[i].point[k], b.candidates[i].point[k]) << what;
  }
}

// The tree finds exactly what looking at every move finds; and no point of any move, sampled
// densely along it, is nearer than the answer (the per-move nearest point is the true one).
TEST(PathIndexProperty, TreeEqualsLinearScanAndNoSampleIsNearer) {
  std::mt19937 rng(20261126);
  std::uniform_real_distribution<double> coord(-80, 80);
  for (int program = 0; program < 6; ++program) {
    const bool kerf = program % 3 == 2;
    const PathIndex ix = index_of(random_program(rng, kerf ? 24 : 120, kerf));
    ASSERT_GT(ix.size(), 10u);
    for (int q = 0; q < 60; ++q) {
      QueryOptions o;
      o.metric = q % 2 == 0 ? Metric::Xy : Metric::Xyz;
      o.margin_mm = q % 3 == 0 ? 0.0 : 3.0;
      const Vec3 b{coord(rng), coord(rng), coord(rng) / 10};
      const Nearest tree = ix.nearest(b, o), linear = ix.nearest_linear(b, o);
      const std::string what =
          fmt::format("program {} query {} at ({}, {}, {})", program, q, b[0], b[1], b[2]);
      expect_same(tree, linear, what);
      if (q % 10 != 0) continue;
      double sampled = 1e300;
      for (std::uint32_t e = 0; e < ix.size(); ++e) {
        for (int k = 0; k <= 400; ++k) {
          const PathPoint p = ix.point_on(e, k / 400.0);
          const double dz = o.metric == Metric::Xyz ? p.point[2] - b[2] : 0.0;
          sampled = std::min(sampled, std::hypot(p.point[0] - b[0], p.point[1] - b[1], dz));
        }
      }
      EXPECT_LE(tree.nearest.distance_mm, sampled + 1e-9) << what;
      EXPECT_GE(tree.nearest.distance_mm, sampled - 0.2) << what;  // 400 samples of ≤ 2π·20 mm
    }
  }
}

}  // namespace
}  // namespace opencnc::recovery
