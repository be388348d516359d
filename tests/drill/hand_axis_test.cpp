// SPDX-License-Identifier: GPL-3.0-or-later
// The hand-axis pass on the drill's programs: moves of the quill become waits (retract before the
// table moves, plunge after it), nothing commands the quill, and what cannot be waited for (arcs,
// helices, targets beyond the stroke) is refused at its line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/drill/hand_axis.hpp"
#include "opencnc/features/features.hpp"

namespace opencnc::controller {
namespace {

config::MachineProfile drill() {
  const config::ProfileLoad load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.toml");
  EXPECT_TRUE(load.ok());
  return *load.profile;
}

/// `text` executed as a program file on the drill from X0 Y0 with the quill at `z`, read to its
/// end (the interpreter never waits here: no sync points), and preflighted.
struct Loaded {
  std::unique_ptr<ProgramStream> stream;
  const canon::Program* program = nullptr;  ///< null when the stream failed
  Diagnostics diagnostics;                  ///< the stream's
  Preflight preflight;
};

class AcceptAll final : public MoveCheck {
 public:
  bool check(const canon::Program&, canon::SegmentId, Diagnostics&) override { return true; }
};

Loaded load(const std::string& text, double z = 0) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-hand-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  Diagnostics d;
  auto source = features::machine_setup(drill(), d)->source();
  Pose start;
  start[Axis::Z] = z;
  Loaded out;
  AcceptAll accept;
  out.preflight = source->preflight(path, start, {}, accept);
  out.stream = source->execute(path, start, {});
  while (out.stream->read(1000) == StreamState::Reading) {
  }
  out.diagnostics = out.stream->diagnostics();
  if (out.stream->state() == StreamState::Finished) out.program = &out.stream->program();
  std::filesystem::remove_all(dir);
  return out;
}

struct Wait {
  std::uint32_t before_move;
  double target;
  bool retract;
};

std::vector<Wait> waits(const canon::Program& p) {
  std::vector<Wait> out;
  for (std::size_t i = 0; i < p.action_count(); ++i) {
    const canon::Action& a = p.action(i);
    if (a.kind == canon::ActionKind::HandAxisWait) {
      EXPECT_EQ(a.index, index(Axis::Z));
      out.push_back({a.before_move, a.value, a.index2 > 0});
    }
  }
  return out;
}

TEST(HandAxisPass, QuillMovesBecomeWaitsAndTheTableMovesAlone) {
  // A hole: down to R, feed to depth, back to R; then the table moves to the next hole.
  const Loaded lp = load("G21 G90 G0 X10 Y20\nZ-57\nG1 Z-88 F80\nG0 Z-57\nX50\nM2\n");
  ASSERT_TRUE(lp.program != nullptr);
  EXPECT_TRUE(lp.preflight.ok());
  const canon::Program& p = *lp.program;
  ASSERT_EQ(p.size(), 5u);  // every move keeps its number
  for (canon::SegmentId id = 0; id < p.size(); ++id) EXPECT_EQ(p.end(id)[Axis::Z], 0.0) << id;
  const std::vector<Wait> w = waits(p);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0].before_move, 1u);  // plunge to R where the Z move was
  EXPECT_EQ(w[0].target, -57.0);
  EXPECT_FALSE(w[0].retract);
  EXPECT_EQ(w[1].target, -88.0);
  EXPECT_EQ(w[2].before_move, 3u);  // back up before the table moves to X50
  EXPECT_TRUE(w[2].retract);
}

TEST(HandAxisPass, ARetractComesBeforeTheTableAPlungeAfterIt) {
  const Loaded lp = load("G21 G90 G0 X10 Z-20\nX30 Z-5\nM2\n", -10);
  ASSERT_TRUE(lp.program != nullptr);
  const std::vector<Wait> w = waits(*lp.program);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[0].before_move, 1u);  // the first move goes down: after the table's part (move 0)
  EXPECT_FALSE(w[0].retract);
  EXPECT_EQ(w[1].before_move, 1u);  // the second goes up: before its table motion (move 1)
  EXPECT_TRUE(w[1].retract);
  // In that order: the plunge of move 0 first.
  EXPECT_EQ(w[0].target, -20.0);
  EXPECT_EQ(w[1].target, -5.0);
}

TEST(HandAxisPass, ProgramsThatDoNotMoveTheQuillHaveNoWaits) {
  const Loaded lp = load("G21 G90 G1 X10 Y5 F600\nM2\n");
  ASSERT_TRUE(lp.program != nullptr);
  EXPECT_TRUE(waits(*lp.program).empty());
  EXPECT_EQ(lp.program->end(0)[Axis::X], 10.0);
}

TEST(HandAxisPass, ArcsHelicesAndTargetsBeyondTheStrokeAreRefusedAtTheirLine) {
  const struct {
    const char* text;
    std::uint32_t line;
  } cases[] = {
      {"G21 G90 G18 G2 X20 Z0 I10 K0 F100\nM2\n", 1},       // an arc in XZ (ending at the same Z)
      {"G21 G90 G17\nG2 X20 Y0 Z-5 I10 J0 F100\nM2\n", 2},  // a helix
      {"G21 G90\nG0 X5\nG1 Z-200 F50\nM2\n", 3},            // below the quill's stroke (−160)
  };
  for (const auto& c : cases) {
    const Loaded lp = load(c.text);
    EXPECT_TRUE(lp.program == nullptr) << c.text;
    // The stream and the preflight both say where.
    for (const Diagnostics* diags : {&lp.diagnostics, &lp.preflight.diagnostics}) {
      const Diagnostic* error = nullptr;
      for (const Diagnostic& d : diags->items()) {
        if (d.severity == Severity::Error && error == nullptr) error = &d;
      }
      ASSERT_NE(error, nullptr) << c.text;
      EXPECT_EQ(error->code, "control.hand-axis") << error->format();
      EXPECT_EQ(error->line, c.line) << error->format();
      EXPECT_NE(error->file.find("p.ngc"), std::string::npos) << error->format();
    }
  }
}

}  // namespace
}  // namespace opencnc::controller
