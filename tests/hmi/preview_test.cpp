// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI's toolpath preview: arcs drawn the way they run, the moves the program source makes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/hmi/preview.hpp"

namespace opencnc::hmi {
namespace {

using nlohmann::json;

std::string write_program(const std::string& name, const std::string& text) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}

json preview_of(const std::string& text) {
  const config::ProfileLoad l = config::load_profile(OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml", {});
  EXPECT_TRUE(l.profile) << l.diagnostics.items().size();
  Diagnostics d;
  const auto source = control::GcodeProgramSource::create(*l.profile, d);
  EXPECT_TRUE(source);
  return program_preview(*source, write_program("opencnc-preview-test.ngc", text), Pose{});
}

// A clockwise quarter from (10, 0) to (0, −10) about the origin stays in the fourth quadrant; drawn
// counterclockwise it would pass through (0, 10) and (−10, 0).
TEST(Preview, AClockwiseArcIsDrawnOnItsOwnSide) {
  const json p = preview_of("G21 G90 G17 M3 S1000\nG0 X10 Y0\nG2 X0 Y-10 I-10 J0 F600\nM2\n");
  ASSERT_EQ(p["diagnostics"].size(), 0u) << p["diagnostics"].dump();
  const json& arc = p["polylines"].back();
  EXPECT_FALSE(arc["rapid"].get<bool>());
  const std::vector<double> pts = arc["points"];
  ASSERT_GE(pts.size(), 3u * 4);
  for (std::size_t i = 0; i + 2 < pts.size(); i += 3) {
    EXPECT_GE(pts[i], -1e-9) << "x of point " << i / 3;
    EXPECT_LE(pts[i + 1], 1e-9) << "y of point " << i / 3;
    EXPECT_NEAR(std::hypot(pts[i], pts[i + 1]), 10, 0.01) << "point " << i / 3;
  }
  // A quarter at a chord every 5 degrees: 18 points after the start.
  EXPECT_EQ(pts.size(), 3u * (1 + 18));
}

TEST(Preview, ACounterclockwiseArcToo) {
  const json p = preview_of("G21 G90 G17 M3 S1000\nG0 X10 Y0\nG3 X0 Y10 I-10 J0 F600\nM2\n");
  const std::vector<double> pts = p["polylines"].back()["points"];
  for (std::size_t i = 0; i + 2 < pts.size(); i += 3) {
    EXPECT_GE(pts[i], -1e-9);
    EXPECT_GE(pts[i + 1], -1e-9);
  }
  EXPECT_EQ(pts.size(), 3u * (1 + 18));
}

}  // namespace
}  // namespace opencnc::hmi
