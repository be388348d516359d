// SPDX-License-Identifier: GPL-3.0-or-later
// The broaching job generator: stroke depths to the exact total, the coupling code of each helix
// type, grooves indexed around the bore, bad parameters named; its programs run through the
// interpreter with the coupling codes without an error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "opencnc/broaching/coupling_codes.hpp"
#include "opencnc/broaching/helix_job.hpp"
#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/interpreter.hpp"

namespace opencnc::cam {
namespace {

std::vector<std::string> matches(const std::string& text, const std::string& pattern) {
  std::vector<std::string> out;
  const std::regex re(pattern);
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back(it->str(1));
  return out;
}

/// Records the coupling calls and counts the moves.
struct CouplingCalls final : canon::Sink {
  void set_axis_coupling(const canon::AxisCoupling& c) override { calls.push_back(c); }
  void straight_feed(canon::SegmentId, const Pose&) override { ++moves; }
  std::vector<canon::AxisCoupling> calls;
  int moves = 0;
};

CouplingCalls interpret(const std::string& program) {
  const auto path = std::filesystem::temp_directory_path() / "opencnc-helix-job.ngc";
  std::ofstream(path) << program;
  gcode::Options o;
  o.axes = AxisMask::from_letters("XZC");
  o.extensions = gcode::coupling_extensions(o.dialect);
  gcode::Interpreter interp(o);
  CouplingCalls sink;
  EXPECT_TRUE(interp.open(path.string()));
  EXPECT_EQ(interp.run(sink), gcode::RunStatus::Finished);
  EXPECT_FALSE(interp.diagnostics().has_errors());
  std::filesystem::remove(path);
  return sink;
}

TEST(HelixJob, StrokesReachTheDepthExactlyAndRepeatIt) {
  HelixJob j;
  j.pitch_mm = 600;
  j.depth_mm = 0.25;
  j.infeed_mm = 0.1;
  j.spring_passes = 1;
  ASSERT_FALSE(validate(j).has_value());
  EXPECT_EQ(strokes_per_groove(j), 4);
  const std::string p = helix_program(j, "test");
  EXPECT_EQ(matches(p, R"(\(stroke \d+ of 4: depth ([0-9.]+)\))"),
            (std::vector<std::string>{"0.1000", "0.2000", "0.2500", "0.2500"}));
  EXPECT_EQ(matches(p, R"((M17\d[^\n(]*))"), (std::vector<std::string>{"M171 P600.0000 ", "M175"}));
  j.infeed_mm = 0.05;  // divides the depth: no stroke of rounding
  j.spring_passes = 0;
  EXPECT_EQ(strokes_per_groove(j), 5);
}

TEST(HelixJob, EachTypeWritesItsCouplingAndRunsThroughTheInterpreter) {
  HelixJob j;
  j.z_start = 1000;  // cutting towards −Z
  j.z_end = -10;
  j.depth_mm = 0.2;
  j.grooves = 3;
  j.type = HelixType::Variable;
  j.pitch_mm = 600;
  j.pitch_end_mm = 900;
  CouplingCalls calls = interpret(helix_program(j, "test"));
  ASSERT_EQ(calls.calls.size(), 6u);  // on and off per groove
  EXPECT_EQ(calls.calls[0].law, 2);
  EXPECT_NEAR(calls.calls[0].rate, (900.0 - 600.0) / (-10.0 - 1000.0), 1e-8);
  EXPECT_EQ(calls.calls[1].law, 0);
  EXPECT_EQ(calls.moves,
            3 * 2 * 3);  // 3 grooves × 2 strokes × feeds (infeed, cut, lift; the return is a rapid)
  j.type = HelixType::Cam;
  j.table = 2;
  calls = interpret(helix_program(j, "test"));
  EXPECT_EQ(calls.calls[0].law, 4);
  EXPECT_EQ(calls.calls[0].table, 2);
  const std::string p = helix_program(j, "test");
  EXPECT_EQ(matches(p, R"(\nG0 (C[0-9.]+)\n)"), (std::vector<std::string>{"C120.0000", "C240.0000"}));
}

TEST(HelixJob, BadParametersAreNamed) {
  const auto problem = [](auto change) {
    HelixJob j;
    j.pitch_mm = 600;
    change(j);
    return validate(j).value_or("");
  };
  EXPECT_NE(problem([](HelixJob& j) { j.pitch_mm = 0; }).find("--pitch"), std::string::npos);
  EXPECT_NE(problem([](HelixJob& j) { j.z_end = j.z_start; }).find("--z-start"), std::string::npos);
  EXPECT_NE(problem([](HelixJob& j) {
              j.type = HelixType::Variable;
              j.pitch_end_mm = -5;
            }).find("--pitch-end"),
            std::string::npos);
  EXPECT_NE(problem([](HelixJob& j) { j.type = HelixType::Table; }).find("--table"), std::string::npos);
  EXPECT_NE(problem([](HelixJob& j) { j.infeed_mm = 1e-9; }).find("10000 strokes"), std::string::npos);
}

}  // namespace
}  // namespace opencnc::cam
