// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI's toolpath preview: arcs drawn the way they run, the moves the program source makes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/hmi/preview.hpp"

namespace opencnc::hmi {
namespace {

using nlohmann::json;

std::string write_program(const std::string& name, const std::string& text) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}

config::MachineProfile profile(const std::string& name) {
  const config::ProfileLoad l = config::load_profile(OPENCNC_SOURCE_DIR "/configs/" + name, {});
  EXPECT_TRUE(l.profile) << l.diagnostics.items().size();
  return l.profile ? *l.profile : config::MachineProfile{};
}

json preview_of(const std::string& text) {
  Diagnostics d;
  const auto source = controller::GcodeProgramSource::create(profile("mill-3axis.toml"), d);
  EXPECT_TRUE(source);
  return program_preview(*source, write_program("opencnc-preview-test.ngc", text), Pose{});
}

/// The preview's points in order, each once (a polyline starts where the one before it ends).
std::vector<double> all_points(const json& preview) {
  std::vector<double> out;
  for (const json& line : preview["polylines"]) {
    const std::vector<double> pts = line["points"];
    out.insert(out.end(), pts.begin() + (out.empty() ? 0 : 3), pts.end());
  }
  return out;
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

// The drill's quill is fed by hand: its feature's pass turns every programmed Z move into a wait
// for the operator, and the machine's Z stays where it stands. The preview draws what the program
// source with the features' passes makes, the moves that run, not the interpreter's own.
TEST(Preview, ShowsTheProgramTheFeaturesPassesMake) {
  const std::string text = "G21 G90 M3 S500 G0 X10 Y20\nZ-57\nG1 Z-88 F80\nG0 Z-57\nX50\nM2\n";
  const std::string path = write_program("opencnc-preview-drill.ngc", text);
  Diagnostics d;
  const auto setup = features::machine_setup(profile("drill-retrofit.toml"), d);
  ASSERT_TRUE(setup) << d.items().size();
  const json p = program_preview(*setup->source(), path, Pose{});
  ASSERT_EQ(p["diagnostics"].size(), 0u) << p["diagnostics"].dump();
  const std::vector<double> pts = all_points(p);

  // What runs: the same source's stream, read to its end.
  const auto stream = setup->source()->execute(path, Pose{}, {});
  while (stream->read(1000) == controller::StreamState::Reading) {
  }
  ASSERT_EQ(stream->state(), controller::StreamState::Finished);
  const canon::Program& run = stream->program();
  ASSERT_EQ(pts.size(), 3 * (1 + run.size()));
  for (canon::SegmentId id = 0; id < run.size(); ++id) {
    for (int i = 0; i < 3; ++i)
      EXPECT_EQ(pts[3 * (id + 1) + static_cast<std::size_t>(i)], run.end(id)[i]) << id << " " << i;
    EXPECT_EQ(pts[3 * (id + 1) + 2], 0.0) << "move " << id << ": the quill is not the program's to move";
  }

  // Without the feature's pass the same program would draw the quill's plunge to Z-88.
  const auto plain = controller::GcodeProgramSource::create(profile("drill-retrofit.toml"), d);
  ASSERT_TRUE(plain);
  const std::vector<double> raw = all_points(program_preview(*plain, path, Pose{}));
  double lowest_z = 0;
  for (std::size_t i = 2; i < raw.size(); i += 3) lowest_z = std::min(lowest_z, raw[i]);
  EXPECT_EQ(lowest_z, -88.0);
}

}  // namespace
}  // namespace opencnc::hmi
