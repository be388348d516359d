// SPDX-License-Identifier: GPL-3.0-or-later
// ProgramSource::resume: a program resumed at segment k from a point on it makes the same moves
// (segment ids, end points, arcs) as the whole program from there on — through subprograms in
// loops, work offsets and kerf compensation —, repeats the spindle and outputs it had set, and
// refuses to replay past what only the machine knew (a probe, an input).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/features/features.hpp"

namespace opencnc::controller {
namespace {

class ResumeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Diagnostics d;
    source_ = features::machine_setup(control::test::mill(), d)->source();
    dir_ = std::filesystem::temp_directory_path() /
           ("opencnc-resume-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& text) {
    const std::string path = (dir_ / "p.ngc").string();
    std::ofstream(path) << text;
    return path;
  }
  /// Reads a stream to its end (answering stops), keeping every move (no release).
  static void read_all(ProgramStream& s) {
    for (int i = 0; i < 100000 && s.state() != StreamState::Finished && s.state() != StreamState::Error;
         ++i) {
      if (s.state() == StreamState::Sync) {
        SyncAnswer a;
        a.kind = s.sync_request().kind;
        s.answer(a);
      }
      s.read(1000);
    }
  }
  std::shared_ptr<GcodeProgramSource> source_;
  std::filesystem::path dir_;
};

constexpr const char* kProgram =
    "G21 G90 G17 F900\n"
    "G10 L2 P1 X5 Y-3\n"
    "G54 S1000 M3\n"
    "M64 P1\n"
    "o<part> sub\n"
    "  G0 X[#1 - 5] Y0\n"
    "  G41.1 D2 G1 X#1 Y0\n"
    "  G1 Y20\n"
    "  G3 X[#1 - 10] Y20 R5\n"
    "  G1 Y0\n"
    "  G1 X#1\n"
    "  G40 G1 X[#1 + 5]\n"
    "  M0\n"
    "o<part> endsub\n"
    "#1 = 0\n"
    "o1 while [#1 LT 4]\n"
    "  o<part> call [20 + 30 * #1]\n"
    "  #1 = [#1 + 1]\n"
    "o1 endwhile\n"
    "M65 P1\n"
    "M2\n";

TEST_F(ResumeTest, TheRestOfTheProgramFromAPointOfSegmentKIsTheOriginal) {
  const std::string path = write(kProgram);
  auto whole = source_->execute(path, Pose{}, {});
  read_all(*whole);
  ASSERT_EQ(whole->state(), StreamState::Finished);
  const canon::Program& w = whole->program();
  // In the second part: its first compensated feed line and its first arc; a line of the last.
  const auto first_after = [&](std::size_t from, canon::MoveKind kind) {
    while (from < w.size() && w.move(from).kind != kind) ++from;
    return from;
  };
  const std::size_t line = first_after(w.size() / 4 + 1, canon::MoveKind::Feed);
  const std::size_t arc = first_after(line, canon::MoveKind::Arc);
  const std::size_t late = first_after(w.size() * 3 / 4 + 1, canon::MoveKind::Feed);
  ASSERT_LT(arc, w.size());
  ASSERT_LT(late, w.size());
  for (std::size_t from : {line, arc, late}) {
    const canon::SegmentId k = w.segment_of(from);
    // A point 40 % along the move (its start on the arc: the rest of an arc is from a point on it).
    Pose c = w.start_of(from);
    if (w.move(from).kind != canon::MoveKind::Arc) {
      for (int a = 0; a < kAxisCount; ++a) c[a] += 0.4 * (w.end(from)[a] - w.start_of(from)[a]);
    }
    auto rest = source_->resume(path, Pose{}, c, k, {});
    ASSERT_TRUE(rest != nullptr);
    read_all(*rest);
    ASSERT_EQ(rest->state(), StreamState::Finished)
        << (rest->diagnostics().items().empty() ? "" : rest->diagnostics().items()[0].format());
    const canon::Program& r = rest->program();
    ASSERT_EQ(r.size(), w.size() - from) << "from move " << from;
    EXPECT_EQ(r.start(), c);
    for (std::size_t m = 0; m < r.size(); ++m) {
      ASSERT_EQ(r.segment_of(m), w.segment_of(from + m));
      ASSERT_EQ(r.move(m).kind, w.move(from + m).kind);
      ASSERT_EQ(r.move(m).line, w.move(from + m).line);
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(r.end(m)[a], w.end(from + m)[a], 1e-9) << "move " << m;
      if (r.move(m).kind == canon::MoveKind::Arc) {
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(r.arc(m).center[a], w.arc(from + m).center[a], 1e-9);
      }
    }
    // The spindle and the output the program had on are repeated before the first move.
    bool spindle = false, output = false;
    for (std::size_t i = 0; i < r.action_count() && r.action(i).before_move == 0; ++i) {
      spindle |= r.action(i).kind == canon::ActionKind::SpindleCw;
      output |= r.action(i).kind == canon::ActionKind::AuxOutputBit && r.action(i).index == 1 &&
                r.action(i).index2 == 1;
    }
    EXPECT_TRUE(spindle);
    EXPECT_TRUE(output);
  }
}

TEST_F(ResumeTest, APastProbeOrInputOrTheEndCannotBeReplayed) {
  auto past_input = source_->resume(write("G21 G90 F900\nG1 X10\nM66 P0 L0\nG1 X20\nG1 X30\nM2\n"), Pose{},
                                    Pose{20, 0, 0}, 2, {});
  read_all(*past_input);
  ASSERT_EQ(past_input->state(), StreamState::Error);
  EXPECT_EQ(past_input->diagnostics().items()[0].code, "control.resume-past-sync");
  EXPECT_EQ(past_input->diagnostics().items()[0].line, 3u);
  auto past_end = source_->resume(write("G21 G90 F900\nG1 X10\nM2\n"), Pose{}, Pose{10, 0, 0}, 5, {});
  read_all(*past_end);
  ASSERT_EQ(past_end->state(), StreamState::Error);
  EXPECT_EQ(past_end->diagnostics().items()[0].code, "control.resume-past-end");
}

// A machine module's modal codes (the EDM's M180 P<n> / M181, one group): the last of the group
// before segment k is passed again before k's move, earlier ones not; codes after k pass live.
TEST_F(ResumeTest, TheProcessCodeInForceAtSegmentKIsSelectedAgain) {
  const config::MachineProfile edm =
      control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml"));
  Diagnostics d;
  auto source = features::machine_setup(edm, d)->source();
  const std::string path = write(
      "G21 G90\nG0 Z-19.97\nM180 P1\nG1 Z-20.0 F60\nM180 P2\nG1 Z-20.01 F30\nG1 Z-20.02\nM181\nG0 Z0\n"
      "G0 Z-19.98\nM180 P3\nG1 Z-20.03 F20\nM2\n");
  auto whole = source->execute(path, Pose{}, {});
  read_all(*whole);
  ASSERT_EQ(whole->state(), StreamState::Finished);
  const canon::Program& w = whole->program();
  const auto segment_at_line = [&](std::uint32_t line) {
    for (std::size_t m = 0; m < w.size(); ++m)
      if (w.move(m).line == line) return w.segment_of(m);
    ADD_FAILURE() << "no move at line " << line;
    return canon::SegmentId{0};
  };
  struct Case {
    std::uint32_t line;
    std::vector<std::pair<int, double>> before;  // the codes before the first move (code, P)
  };
  const Case cases[] = {
      {7, {{180, 2}}},  // the second feed of condition 2: P2 again, not P1
      {9, {{181, 0}}},  // after M181: the generator stays off
      {4, {{180, 1}}},  // the first feed
      {2, {}},          // the approach: nothing in force yet
  };
  for (const Case& c : cases) {
    const canon::SegmentId k = segment_at_line(c.line);
    auto rest = source->resume(path, Pose{}, Pose{0, 0, -19.97, 0, 0}, k, {});
    ASSERT_TRUE(rest != nullptr);
    read_all(*rest);
    ASSERT_EQ(rest->state(), StreamState::Finished);
    const canon::Program& r = rest->program();
    std::vector<std::pair<int, double>> before, all;
    for (std::size_t i = 0; i < r.action_count(); ++i) {
      if (r.action(i).kind != canon::ActionKind::ProcessCode) continue;
      all.emplace_back(r.action(i).index, r.action(i).value);
      if (r.action(i).before_move == 0) before.emplace_back(r.action(i).index, r.action(i).value);
    }
    EXPECT_EQ(before, c.before) << "from line " << c.line;
    ASSERT_FALSE(all.empty() && c.line != 9 && c.line != 2) << "from line " << c.line;
    EXPECT_EQ(all.back(), (std::pair<int, double>{180, 3})) << "from line " << c.line;  // live after k
  }
}

}  // namespace
}  // namespace opencnc::controller
