// SPDX-License-Identifier: GPL-3.0-or-later
// The interpreter's interface: segment ids and source origins, stepping, MDI, execute-mode
// sync points, state values and digests, runaway limits, axis map and extension points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "gcode_test_util.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/canon/tee_sink.hpp"
#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

using namespace opencnc;
using namespace opencnc::gcode;
using test::TempDir;

namespace {

// Records block origins and motions; calls `on_motion` as each motion arrives.
class Recorder : public canon::Sink {
 public:
  struct Motion {
    canon::SegmentId id;
    char kind;   // 't' traverse, 'f' feed, 'a' arc
    Pose end;
    canon::BlockOrigin origin;
  };
  void begin_block(const canon::BlockOrigin& o) override { origin_ = o; }
  void straight_traverse(canon::SegmentId id, const Pose& end) override { add(id, 't', end); }
  void straight_feed(canon::SegmentId id, const Pose& end) override { add(id, 'f', end); }
  void arc_feed(canon::SegmentId id, const canon::ArcFeed& a) override {
    arcs.push_back(a);
    add(id, 'a', a.end);
  }
  void dwell(double s) override { dwells.push_back(s); }
  void comment(std::string_view text) override { comments.emplace_back(text); }
  void message(std::string_view text) override { messages.emplace_back(text); }

  std::vector<Motion> motions;
  std::vector<std::string> messages;
  std::vector<canon::ArcFeed> arcs;
  std::vector<double> dwells;
  std::vector<std::string> comments;
  std::function<void(const Motion&)> on_motion;

 private:
  void add(canon::SegmentId id, char kind, const Pose& end) {
    motions.push_back({id, kind, end, origin_});
    if (on_motion) on_motion(motions.back());
  }
  canon::BlockOrigin origin_;
};

RunStatus run_into(Interpreter& interp, canon::Sink& sink, std::string_view text, const char* name = "test.ngc") {
  interp.open_text(name, std::string(text));
  return interp.run(sink);
}

// The first error (warnings may come before it).
const Diagnostic* first_error(const Interpreter& interp) {
  for (const auto& d : interp.diagnostics().items()) {
    if (d.severity == Severity::Error) return &d;
  }
  return nullptr;
}

std::string first_code(const Interpreter& interp) {
  const Diagnostic* d = first_error(interp);
  return d == nullptr ? std::string() : d->code;
}

}  // namespace

// --- segment ids and the source map ------------------------------------------------------

TEST(Interpreter, NumbersMotionsInOrderFromZero) {
  Interpreter interp;
  Recorder rec;
  ASSERT_EQ(run_into(interp, rec, "G21 F100\nG0 X1\nG1 X2\nG2 X4 I1\nG1 Y1\nM2\n"), RunStatus::Finished);
  ASSERT_EQ(rec.motions.size(), 4u);
  for (std::size_t i = 0; i < rec.motions.size(); ++i) EXPECT_EQ(rec.motions[i].id, i);
  EXPECT_EQ(std::string(1, rec.motions[2].kind), "a");
  EXPECT_EQ(interp.segments(), 4u);
  EXPECT_EQ(interp.state().segments, 4u);
}

TEST(Interpreter, OriginsNameTheLineTheNWordAndTheCallStack) {
  Interpreter interp;
  Recorder rec;
  const char* program =
      "o<leg> sub\n"            // 1
      "  G1 X#1\n"              // 2
      "o<leg> endsub\n"         // 3
      "o<two> sub\n"            // 4
      "  o<leg> call [#1]\n"    // 5
      "  G1 Y#1\n"              // 6
      "o<two> endsub\n"         // 7
      "G21 F100\n"              // 8
      "N0070 G1 X1\n"           // 9
      "o<two> call [5]\n"       // 10
      "o<leg> call [6]\n"       // 11
      "M2\n";
  ASSERT_EQ(run_into(interp, rec, program, "main.ngc"), RunStatus::Finished);
  ASSERT_EQ(rec.motions.size(), 4u);
  const auto& m = rec.motions;
  EXPECT_EQ(m[0].origin.line, 9u);
  EXPECT_TRUE(m[0].origin.n_present);
  EXPECT_EQ(std::string(m[0].origin.n_digits, m[0].origin.n_length), "0070");
  EXPECT_EQ(m[0].origin.context, 0u);
  // X5 comes from line 2 inside o<leg>, called from line 5 inside o<two>, called from line 10.
  EXPECT_EQ(m[1].origin.line, 2u);
  const auto& sources = *interp.sources();
  const auto stack = sources.stack(m[1].origin.context);
  ASSERT_EQ(stack.size(), 2u);
  EXPECT_EQ(sources.context_info(stack[0]).name, "o<two>");
  EXPECT_EQ(sources.context_info(stack[0]).call_site.line, 10u);
  EXPECT_EQ(sources.context_info(stack[1]).name, "o<leg>");
  EXPECT_EQ(sources.context_info(stack[1]).call_site.line, 5u);
  // Y5 on line 6 belongs to o<two> alone; X6 to o<leg> called from the main program.
  EXPECT_EQ(m[2].origin.line, 6u);
  EXPECT_EQ(m[2].origin.context, stack[0]);
  EXPECT_EQ(m[3].origin.line, 2u);
  EXPECT_EQ(sources.stack(m[3].origin.context).size(), 1u);
  EXPECT_EQ(sources.context_info(m[3].origin.context).call_site.line, 11u);
  EXPECT_EQ(sources.file(m[0].origin.file), "main.ngc");
}

TEST(Interpreter, SubprogramFilesComeFromTheSearchPathInOrder) {
  TempDir first, second;
  first.write("wiggle.ngc", "o<wiggle> sub\nG1 X#1\no<wiggle> endsub\nM2\n");
  second.write("wiggle.ngc", "o<wiggle> sub\nG1 X99\no<wiggle> endsub\nM2\n");
  second.write("up.ngc", "o<up> sub\nG1 Z#1\no<up> endsub\n");
  Options options;
  options.subroutine_path = {first.str(), second.str()};
  Interpreter interp(options);
  Recorder rec;
  ASSERT_EQ(run_into(interp, rec, "G21 F10\no<wiggle> call [3]\no<up> call [2]\no<wiggle> call [4]\nM2\n"),
            RunStatus::Finished) << first_code(interp);
  ASSERT_EQ(rec.motions.size(), 3u);
  EXPECT_EQ(rec.motions[0].end[Axis::X], 3.0);   // the first directory wins
  EXPECT_EQ(rec.motions[1].end[Axis::Z], 2.0);
  EXPECT_EQ(rec.motions[2].end[Axis::X], 4.0);
  const auto& sources = *interp.sources();
  EXPECT_EQ(sources.file(rec.motions[0].origin.file), first.str() + "/wiggle.ngc");
  EXPECT_EQ(sources.file(rec.motions[1].origin.file), second.str() + "/up.ngc");
  EXPECT_EQ(rec.motions[1].origin.line, 2u);
}

TEST(Interpreter, ErrorsCarryFileLineAndColumn) {
  Interpreter interp;
  canon::Sink quiet;
  EXPECT_EQ(run_into(interp, quiet, "G21\n  G1 X1 Q\nM2\n", "bad.ngc"), RunStatus::Error);
  ASSERT_EQ(interp.diagnostics().error_count(), 1u);
  const auto& d = *first_error(interp);
  EXPECT_EQ(d.code, "gcode.missing-value");
  EXPECT_EQ(d.file, "bad.ngc");
  EXPECT_EQ(d.line, 2u);
  EXPECT_EQ(d.col, 9u);  // the Q that has no value
  // The run cannot continue after an error.
  EXPECT_EQ(interp.run(quiet), RunStatus::Error);
  // A word nothing uses is pointed at.
  Interpreter words;
  EXPECT_EQ(run_into(words, quiet, "G21\nG0 X 1  I5\nM2\n"), RunStatus::Error);
  ASSERT_NE(first_error(words), nullptr);
  EXPECT_EQ(first_error(words)->code, "gcode.unused-word");
  EXPECT_EQ(first_error(words)->col, 9u);
}

// Each error names its problem and points at the word to change (line and column of the raw
// text, blanks included).
TEST(Interpreter, ErrorsPointAtTheOffendingWord) {
  struct Case {
    const char* program;
    const char* code;
    std::uint32_t line, col;
  };
  const std::string long_line = "G0 X1 (" + std::string(300, 'x') + ")\n";
  const Case cases[] = {
      {"G21 F10\nG2 X2 Y0 R0.1\nM2\n", "gcode.arc-radius-too-small", 2, 10},
      {"G21 F10\nG2 X2 Y0 I1 J0 R1\nM2\n", "gcode.arc-mixed-format", 2, 16},
      {"G21 F10\nG2 X2 Y0 I1 K1\nM2\n", "gcode.arc-offset-wrong-plane", 2, 13},
      {"G21 F10\nG3 X10 Y0.6 I5 J0\nM2\n", "gcode.arc-end-off-circle", 2, 13},
      {"G21\n  G1 Y2 Y3\nM2\n", "gcode.repeated-word", 2, 9},
      {"G21\nG0 X1 G1 Y2\nM2\n", "gcode.modal-group-conflict", 2, 7},
      {"G21\nM3 M7 M48 M62 P1 M0\nM2\n", "gcode.too-many-m-codes", 2, 18},
      {"G21\nG1 F10 X1\nG94\n  X2\nM2\n", "gcode.feed-zero", 4, 3},
      {"G21\nG91 G1 F10 @1\nM2\n", "gcode.polar-at-origin", 2, 12},
      {"G21\nG43 H7\nM2\n", "gcode.tool-not-found", 2, 5},
      {"G21\nG10 L2 P12 X1\nM2\n", "gcode.g10-p-range", 2, 8},
      {"G21\nM66 P1 L2\nM2\n", "gcode.io-m66-timeout-missing", 2, 8},
      {"G21\nG0 X1 Q1\nM2\n", "gcode.unused-word", 2, 7},
      {"G21\nG0 U1\nM2\n", "gcode.axis-not-available", 2, 4},
      {"G21\nG1 X[1 + 2 F100\nM2\n", "gcode.unclosed-expression", 2, 12},
      {"G21\nG1 X F100\nM2\n", "gcode.missing-value", 2, 4},
      {"G21\n  o<nope> call\nM2\n", "gcode.oword-sub-not-found", 2, 3},
      {"G21\n#1=0\n  o1 if [#1]\nG0 X1\nM2\n", "gcode.oword-unclosed", 3, 3},
      {"G21\nG0 X1\n", "gcode.missing-program-end", 3, 1},
      {long_line.c_str(), "gcode.line-too-long", 1, 254},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.program);
    Interpreter interp;
    canon::Sink quiet;
    EXPECT_EQ(run_into(interp, quiet, c.program), RunStatus::Error);
    const Diagnostic* d = first_error(interp);
    ASSERT_NE(d, nullptr);
    EXPECT_EQ(d->code, c.code) << d->message;
    EXPECT_EQ(d->line, c.line) << d->message;
    EXPECT_EQ(d->col, c.col) << d->message;
    EXPECT_FALSE(d->message.empty());
  }
}

// rs274 ends a DEBUG text at a #< that is never closed (and then prints bytes it never set):
// opencnc keeps the text before it and goes on, without an error.
TEST(Interpreter, AnUnclosedNameEndsACommentsText) {
  Interpreter interp;
  Recorder rec;
  ASSERT_EQ(run_into(interp, rec, "G21\n#<foo>=3\n(DEBUG, value #<foo> then #<foo never closed)\nM2\n"),
            RunStatus::Finished);
  EXPECT_EQ(rec.messages, (std::vector<std::string>{" value 3.000000 then "}));
}

TEST(Interpreter, WarnsOnceAboutHabitsLinuxCncAccepts) {
  Interpreter interp;
  canon::Sink quiet;
  ASSERT_EQ(run_into(interp, quiet, "F100\nG0 X1\nG1 X2\nG1 X3\nM3 S100\nG21 G1 X4\nM2\n"), RunStatus::Finished);
  const auto& items = interp.diagnostics().items();
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[0].severity, Severity::Warning);
  EXPECT_EQ(items[0].code, "gcode.units-not-programmed");
  EXPECT_EQ(items[0].line, 2u);
  EXPECT_EQ(items[1].code, "gcode.feed-with-spindle-stopped");
  EXPECT_EQ(items[1].line, 3u);
  EXPECT_FALSE(interp.diagnostics().has_errors());
  Interpreter careful;
  ASSERT_EQ(run_into(careful, quiet, "G21 F100 M3 S1000\nG1 X1\nG2 X2 I0.5\nM2\n"), RunStatus::Finished);
  EXPECT_TRUE(careful.diagnostics().empty());
  // A machine without a spindle (an EDM, a flame cutter) feeds with none turning as a rule.
  Options spindleless;
  spindleless.spindle = false;
  Interpreter cutter(spindleless);
  ASSERT_EQ(run_into(cutter, quiet, "G21 F100\nG1 X1\nM2\n"), RunStatus::Finished);
  EXPECT_TRUE(cutter.diagnostics().empty());
}

// --- stepping, MDI and sync points ---------------------------------------------------------

TEST(Interpreter, StepExecutesOneBlockAtATime) {
  Interpreter interp;
  Recorder rec;
  interp.open_text("t.ngc", "G21 F100\nG1 X1\n\nG1 X2\nM2\n");
  std::vector<std::size_t> motions_after_step;
  RunStatus s;
  while ((s = interp.step(rec)) == RunStatus::Ok) motions_after_step.push_back(rec.motions.size());
  EXPECT_EQ(s, RunStatus::Finished);
  EXPECT_EQ(motions_after_step, (std::vector<std::size_t>{0, 1, 1, 2}));
  EXPECT_EQ(interp.step(rec), RunStatus::Finished);
}

TEST(Interpreter, MdiLinesRunWithoutAProgramAndSurviveErrors) {
  TempDir dir;
  dir.write("hop.ngc", "o<hop> sub\nG0 Z#1\nG0 Z0\no<hop> endsub\n");
  Options options;
  options.subroutine_path = {dir.str()};
  Interpreter interp(options);
  Recorder rec;
  EXPECT_EQ(interp.execute_mdi("G21 G0 X1 Y2", rec), RunStatus::Ok);
  EXPECT_EQ(interp.execute_mdi("G1 X3", rec), RunStatus::Error);   // no feed rate yet
  EXPECT_EQ(first_code(interp), "gcode.feed-zero");
  EXPECT_EQ(interp.execute_mdi("G1 X3 F100", rec), RunStatus::Ok);
  EXPECT_EQ(interp.execute_mdi("o<hop> call [5]", rec), RunStatus::Ok);
  ASSERT_EQ(rec.motions.size(), 4u);
  EXPECT_EQ(rec.motions[2].end[Axis::Z], 5.0);
  EXPECT_EQ(rec.motions[3].end[Axis::Z], 0.0);
  EXPECT_EQ(interp.state().position.current[Axis::X], 3.0);
  EXPECT_EQ(interp.state().frames.size(), 1u);   // the call returned
}

TEST(Interpreter, ExecuteModeStopsAfterAnInputWaitUntilSynced) {
  Options options;
  options.mode = Mode::Execute;
  Interpreter interp(options);
  Recorder rec;
  interp.open_text("t.ngc", "G21 F100\nM66 P2 L3 Q5\n#1 = #5399\nG1 X#1\nM2\n");
  EXPECT_EQ(interp.run(rec), RunStatus::NeedSync);
  EXPECT_EQ(interp.pending_sync(), SyncKind::Input);
  EXPECT_EQ(interp.state().next.line, 3u);   // the block after M66 has not been read
  EXPECT_EQ(interp.run(rec), RunStatus::NeedSync);   // still waiting
  SyncValues v;
  v.kind = SyncKind::Input;
  v.input_value = 1;
  interp.sync(v);
  EXPECT_EQ(interp.pending_sync(), SyncKind::None);
  EXPECT_EQ(interp.run(rec), RunStatus::Finished);
  ASSERT_EQ(rec.motions.size(), 1u);
  EXPECT_EQ(rec.motions[0].end[Axis::X], 1.0);
}

TEST(Interpreter, ScanModeAssumesTheInputKeepsItsValue) {
  Interpreter interp;
  Recorder rec;
  ASSERT_EQ(run_into(interp, rec, "G21 F100\n#5399=1\nM66 P2 L0\nG1 X[#5399+1]\nM2\n"), RunStatus::Finished);
  ASSERT_EQ(rec.motions.size(), 1u);
  EXPECT_EQ(rec.motions[0].end[Axis::X], 2.0);
}

TEST(Interpreter, ExecuteModeTakesThePositionAfterAToolChange) {
  Options options;
  options.mode = Mode::Execute;
  auto table = std::make_shared<tools::ToolTable>();
  tools::ToolEntry t;
  t.tool = 4;
  t.pocket = 4;
  table->add(t);
  options.tool_table = table;
  Interpreter interp(options);
  Recorder rec;
  interp.open_text("t.ngc", "G21 G0 X1 Y1\nT4 M6\nG91 G0 X1\nM2\n");
  ASSERT_EQ(interp.run(rec), RunStatus::NeedSync);
  EXPECT_EQ(interp.pending_sync(), SyncKind::ToolChange);
  SyncValues v;
  v.kind = SyncKind::ToolChange;
  v.position[Axis::X] = 10;   // the changer left the tool elsewhere
  v.position[Axis::Y] = 20;
  interp.sync(v);
  ASSERT_EQ(interp.run(rec), RunStatus::Finished);
  ASSERT_EQ(rec.motions.size(), 2u);
  EXPECT_EQ(rec.motions[1].end[Axis::X], 11.0);
  EXPECT_EQ(rec.motions[1].end[Axis::Y], 20.0);
}

// --- the tool-change position ([tool_change] of the profile) --------------------------------

namespace {

/// Millimetre options with tools 1 (Z offset 50) and 2, and a tool-change position at machine
/// X 100, Z 200 when `axes` names any.
Options tool_change_options(AxisMask axes, bool z_first = true) {
  Options o;
  o.user_units = canon::Units::Mm;
  auto table = std::make_shared<tools::ToolTable>();
  for (int t = 1; t <= 2; ++t) {
    tools::ToolEntry e;
    e.tool = t;
    e.pocket = t;
    e.offset[Axis::Z] = t == 1 ? 50.0 : 0.0;
    table->add(e);
  }
  o.tool_table = table;
  o.tool_change.axes = axes;
  o.tool_change.machine[Axis::X] = 100;
  o.tool_change.machine[Axis::Z] = 200;
  o.tool_change.z_first = z_first;
  return o;
}

/// The traverses and tool changes of a run, in order.
std::vector<std::string> moves_and_changes(const test::Result& r) {
  std::vector<std::string> out;
  for (const auto& c : r.calls) {
    if (c.starts_with("STRAIGHT_TRAVERSE") || c.starts_with("CHANGE_TOOL(")) out.push_back(c);
  }
  return out;
}

// G54 at X10 Z5; tool 1 (Z offset 50) under G43 when tool 2 is changed in.
constexpr const char* kTwoChanges =
    "G21 G10 L2 P1 X10 Z5\nG54 T1 M6 G43\nG0 X1 Y2 Z3\nT2 M6\nG91 G0 X1\nM2\n";

}  // namespace

TEST(ToolChangePosition, WithoutOneM6ChangesWhereTheToolStands) {
  const test::Result r = test::run(kTwoChanges, tool_change_options(AxisMask{}));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.code();
  EXPECT_EQ(moves_and_changes(r), (std::vector<std::string>{
                                      "CHANGE_TOOL(1)",
                                      "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)",
                                      "CHANGE_TOOL(2)",
                                      "STRAIGHT_TRAVERSE(2.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)",
                                  }));
}

TEST(ToolChangePosition, M6RetractsZFirstThenGoesAcrossInMachineCoordinates) {
  const test::Result r = test::run(kTwoChanges, tool_change_options(AxisMask::from_letters("XZ")));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.code();
  // Each change's moves stop where they end (Z up before anything goes across), then the
  // program's own path control is back.
  std::vector<std::string> modes;
  for (const auto& c : r.calls) {
    if (c.starts_with("SET_MOTION_CONTROL_MODE")) modes.push_back(c);
  }
  EXPECT_EQ(modes, (std::vector<std::string>{"SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)",
                                             "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.000000)",
                                             "SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)",
                                             "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.000000)"}));
  // Machine = program + G54 (X10 Z5) + tool length (Z50 after the G43): Z 200 is program Z 195
  // with no tool offset, 145 with tool 1's; X 100 is program X 90; Y stays. The machine stands
  // at its origin at first: program X -10 once G54 is set.
  EXPECT_EQ(moves_and_changes(r), (std::vector<std::string>{
                                      "STRAIGHT_TRAVERSE(-10.0000, 0.0000, 195.0000, 0.0000, 0.0000, 0.0000)",
                                      "STRAIGHT_TRAVERSE(90.0000, 0.0000, 195.0000, 0.0000, 0.0000, 0.0000)",
                                      "CHANGE_TOOL(1)",
                                      "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)",
                                      "STRAIGHT_TRAVERSE(1.0000, 2.0000, 145.0000, 0.0000, 0.0000, 0.0000)",
                                      "STRAIGHT_TRAVERSE(90.0000, 2.0000, 145.0000, 0.0000, 0.0000, 0.0000)",
                                      "CHANGE_TOOL(2)",
                                      // the next move starts at the tool-change position
                                      "STRAIGHT_TRAVERSE(91.0000, 2.0000, 145.0000, 0.0000, 0.0000, 0.0000)",
                                  }));
  EXPECT_EQ(r.state.position.current[Axis::X], 91.0);
  EXPECT_EQ(r.state.position.current[Axis::Z], 145.0);
}

TEST(ToolChangePosition, WithoutZFirstAllAxesGoTogetherAndInchProgramsGetInches) {
  const test::Result r =
      test::run("G20 G0 X1 Y2 Z3\nT2 M6\nM2\n", tool_change_options(AxisMask::from_letters("XZ"), false));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.code();
  // 100 mm and 200 mm in the program's inches, in one move.
  EXPECT_EQ(moves_and_changes(r), (std::vector<std::string>{
                                      "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)",
                                      "STRAIGHT_TRAVERSE(3.9370, 2.0000, 7.8740, 0.0000, 0.0000, 0.0000)",
                                      "CHANGE_TOOL(2)",
                                  }));
  // Only Z named: one move, whether Z goes first or not; already there: no move.
  const test::Result z =
      test::run("G21 G0 X1 Z3\nT2 M6\nT1 M6\nM2\n", tool_change_options(AxisMask::from_letters("Z")));
  EXPECT_EQ(moves_and_changes(z), (std::vector<std::string>{
                                      "STRAIGHT_TRAVERSE(1.0000, 0.0000, 3.0000, 0.0000, 0.0000, 0.0000)",
                                      "STRAIGHT_TRAVERSE(1.0000, 0.0000, 200.0000, 0.0000, 0.0000, 0.0000)",
                                      "CHANGE_TOOL(2)",
                                      "CHANGE_TOOL(1)",
                                  }));
}

TEST(ToolChangePosition, AnXyRotationTurnsTheAcrossMoveButNotTheMachinePoint) {
  // G54 at X10 turned by 90 degrees: machine X 100, Y 0 is program X 0, Y -90.
  Options o = tool_change_options(AxisMask::from_letters("XYZ"));
  const test::Result r = test::run("G21 G10 L2 P1 X10 R90\nG54 G0 X1 Y1 Z0\nT2 M6\nM2\n", o);
  ASSERT_EQ(r.status, RunStatus::Finished) << r.code();
  const auto m = moves_and_changes(r);
  ASSERT_EQ(m.size(), 4u);
  EXPECT_EQ(m[1], "STRAIGHT_TRAVERSE(1.0000, 1.0000, 200.0000, 0.0000, 0.0000, 0.0000)");
  EXPECT_EQ(m[2], "STRAIGHT_TRAVERSE(0.0000, -90.0000, 200.0000, 0.0000, 0.0000, 0.0000)");
}

TEST(ToolChangePosition, UnderAFanucRotationM6IsRefusedAtTheM6) {
  Options o = tool_change_options(AxisMask::from_letters("Z"));
  o.dialect = Dialect::Fanuc;
  o.extensions = standard_extensions(Dialect::Fanuc);
  const test::Result r = test::run("O1\nG21 G68 X0 Y0 R30\nT2 M6\nM30\n", o);
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_EQ(r.code(), "fanuc.transform-active");
  ASSERT_FALSE(r.diagnostics.items().empty());
  EXPECT_EQ(r.diagnostics.items().front().line, 3u);
  EXPECT_NE(r.diagnostics.items().front().message.find("tool-change position"), std::string::npos);
}

// --- state, digest and replay ------------------------------------------------------------

TEST(InterpreterState, EqualRunsGiveEqualStatesAndDigests) {
  const char* program = "G20 G91 F10\n#<_k>=3\nG10 L2 P2 X1\nG55 G1 X1 Y[#<_k>]\nM3 S100\n";
  Interpreter a, b;
  canon::Sink quiet;
  a.open_text("t.ngc", program);
  b.open_text("t.ngc", program);
  for (int i = 0; i < 5; ++i) {
    a.step(quiet);
    b.step(quiet);
  }
  EXPECT_EQ(a.state(), b.state());
  EXPECT_EQ(a.state().digest(), b.state().digest());
  InterpState changed = a.state();
  changed.parameters[100] = 1e-300;
  EXPECT_NE(changed, a.state());
  EXPECT_NE(changed.digest(), a.state().digest());
  changed = a.state();
  changed.globals["_k"].value = 4;
  EXPECT_NE(changed.digest(), a.state().digest());
}

namespace {

// States and printed output around every motion of a run with output from segment `quiet`
// on (0: all of it).
struct Trace {
  std::vector<InterpState> states;   // at each forwarded motion, indexed by segment id
  std::vector<std::string> lines;    // printed lines from the first forwarded call, no sequence numbers
  RunStatus status;
  std::string error;                 // the first diagnostic, if any
};

class StateAtMotion : public canon::Sink {
 public:
  StateAtMotion(const Interpreter& interp, Trace& trace) : interp_(interp), trace_(trace) {}
  void straight_traverse(canon::SegmentId id, const Pose&) override { capture(id); }
  void straight_feed(canon::SegmentId id, const Pose&) override { capture(id); }
  void arc_feed(canon::SegmentId id, const canon::ArcFeed&) override { capture(id); }

 private:
  void capture(canon::SegmentId id) {
    if (trace_.states.size() <= id) trace_.states.resize(id + 1);
    trace_.states[id] = interp_.state();
  }
  const Interpreter& interp_;
  Trace& trace_;
};

Trace trace(std::string_view program, canon::SegmentId quiet) {
  Options options;
  options.quiet_until_segment = quiet;
  Interpreter interp(options);
  interp.open_text("replay.ngc", std::string(program));
  Trace t;
  StateAtMotion states(interp, t);
  test::MemoryStream out;
  {
    canon::Rs274Printer printer(out.file(), out.file());
    canon::TeeSink tee(printer, states);
    // Start-up calls are part of the replayed run's output too: skip them on both sides.
    canon::Sink nowhere;
    interp.start(nowhere);
    t.status = interp.run(tee);
  }
  if (const Diagnostic* d = first_error(interp)) t.error = d->format();
  const std::string text = out.text();
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    const std::string line = text.substr(pos, nl - pos);
    t.lines.push_back(line.size() > 6 ? line.substr(6) : line);
    pos = nl + 1;
  }
  return t;
}

void expect_replay_matches(std::string_view program) {
  const Trace full = trace(program, 0);
  ASSERT_EQ(full.status, RunStatus::Finished) << full.error;
  ASSERT_GT(full.states.size(), 3u);
  for (canon::SegmentId k = 1; k < full.states.size(); ++k) {
    SCOPED_TRACE("replay to segment " + std::to_string(k));
    const Trace part = trace(program, k);
    ASSERT_EQ(part.status, RunStatus::Finished);
    ASSERT_EQ(part.states.size(), full.states.size());
    EXPECT_EQ(part.states[k], full.states[k]);
    EXPECT_EQ(part.states[k].digest(), full.states[k].digest());
    // The replayed output is the tail of the full output.
    ASSERT_LE(part.lines.size(), full.lines.size());
    EXPECT_TRUE(std::equal(part.lines.begin(), part.lines.end(), full.lines.end() - static_cast<std::ptrdiff_t>(part.lines.size())));
  }
}

}  // namespace

TEST(InterpreterReplay, NumberedSubprogramRepeatsReplayToTheSameState) {
  // M98 L keeps its count in the caller's frame and reads its own line again: state like any other.
  expect_replay_matches(
      "G21 F100\n#1 = 0\nM98 P3 L4\nG1 X0\nM98 P3 L2\nM30\nO3\n#1 = [#1 + 1]\nG91 G1 X#1\nG90\nM99\n");
}

TEST(InterpreterReplay, StateAtSegmentKEqualsTheFullRunsState) {
  const char* program =
      "o<corner> sub\n"
      "  #<side> = #1\n"
      "  G91 G1 X#<side>\n"
      "  G1 Y#<side>\n"
      "  G90\n"
      "  o<corner> return [#<side> * 2]\n"
      "o<corner> endsub\n"
      "G21 G90 F200\n"
      "G10 L2 P2 X5 Y5\n"
      "#<_n> = 0\n"
      "o10 while [#<_n> LT 3]\n"
      "  #<_n> = [#<_n> + 1]\n"
      "  o<corner> call [#<_n>]\n"
      "  G92 X[#<_value>]\n"
      "  o11 repeat [2]\n"
      "    G91 G2 X1 Y1 R5\n"
      "    G90\n"
      "  o11 endrepeat\n"
      "  G92.1\n"
      "o10 endwhile\n"
      "G55 G20 G0 X1 Y1\n"
      "M3 S500\n"
      "G21 G1 Z-1 F50\n"
      "M2\n";
  expect_replay_matches(program);
}

TEST(InterpreterReplay, SeededRandomProgramsReplayExactly) {
  std::mt19937 rng(7);
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  auto num = [&] { return std::to_string(pick(200) - 100) + "." + std::to_string(pick(10)); };
  for (int round = 0; round < 6; ++round) {
    std::string p = "o<s> sub\n  G91 G1 X#1 Y[#1/2]\n  G90\n  #<_calls> = [#<_calls> + 1]\no<s> endsub\nG21 F100\n";
    int label = 100;
    const int blocks = 12 + pick(10);
    for (int i = 0; i < blocks; ++i) {
      switch (pick(9)) {
        case 0: p += "G0 X" + num() + " Y" + num() + "\n"; break;
        case 1: p += "G1 X" + num() + " Z" + num() + " F" + std::to_string(50 + pick(500)) + "\n"; break;
        case 2: p += "G91 G2 X0 Y0 I" + std::to_string(1 + pick(5)) + "\nG90\n"; break;
        case 3: p += "G92 X" + num() + "\n"; break;
        case 4: p += "G92.1\n"; break;
        case 5: p += "G10 L2 P" + std::to_string(1 + pick(3)) + " X" + num() + "\nG5" + std::to_string(4 + pick(3)) + "\n"; break;
        case 6: p += "o<s> call [" + num() + "]\n"; break;
        case 7: {
          const std::string l = "o" + std::to_string(label++);
          p += l + " repeat [" + std::to_string(1 + pick(3)) + "]\nG91 G1 Y1\nG90\n" + l + " endrepeat\n";
          break;
        }
        default: p += (pick(2) ? "G20\nG0 X1\n" : "G21\nG0 Y2\n"); break;
      }
    }
    p += "G0 X0 Y0\nM2\n";
    SCOPED_TRACE(p);
    expect_replay_matches(p);
  }
}

// --- runaway limits --------------------------------------------------------------------------

namespace {

std::string run_with_limits(std::string_view program, const Limits& limits, std::uint32_t* line = nullptr) {
  Options options;
  options.limits = limits;
  Interpreter interp(options);
  canon::Sink quiet;
  interp.open_text("limits.ngc", std::string(program));
  EXPECT_EQ(interp.run(quiet), RunStatus::Error);
  if (line != nullptr && first_error(interp) != nullptr) *line = first_error(interp)->line;
  return first_code(interp);
}

}  // namespace

TEST(InterpreterLimits, EndlessLoopStopsAtTheIterationLimit) {
  Limits l;
  l.max_loop_iterations = 1000;
  std::uint32_t line = 0;
  EXPECT_EQ(run_with_limits("G21\no1 while [1]\n  G0 X1\no1 endwhile\nM2\n", l, &line), "gcode.limit-loop-iterations");
  EXPECT_EQ(line, 4u);
  EXPECT_EQ(run_with_limits("G21\no1 do\n  G0 X1\no1 while [1]\nM2\n", l), "gcode.limit-loop-iterations");
}

TEST(InterpreterLimits, RecursionStopsAtTheCallDepth) {
  Limits l;
  std::uint32_t line = 0;
  EXPECT_EQ(run_with_limits("o<r> sub\n  o<r> call\no<r> endsub\nG21\no<r> call\nM2\n", l, &line),
            "gcode.limit-call-depth");
  EXPECT_EQ(line, 2u);
}

TEST(InterpreterLimits, RepeatCountBlocksAndSegmentsAreBounded) {
  Limits l;
  l.max_repeat_count = 100;
  EXPECT_EQ(run_with_limits("G21\no1 repeat [1000000000]\no1 endrepeat\nM2\n", l), "gcode.limit-repeat-count");
  Limits b;
  b.max_blocks = 500;
  EXPECT_EQ(run_with_limits("G21\no1 repeat [1000]\n  G0 X1\no1 endrepeat\nM2\n", b), "gcode.limit-blocks");
  Limits s;
  s.max_segments = 50;
  EXPECT_EQ(run_with_limits("G21\no1 repeat [100]\n  G0 X1\no1 endrepeat\nM2\n", s), "gcode.limit-segments");
  Limits k;
  k.max_skipped_lines = 20;
  std::string long_file = "G21\no<missing> call\n";
  for (int i = 0; i < 100; ++i) long_file += "G0 X1\n";
  long_file += "M2\n";
  EXPECT_EQ(run_with_limits(long_file, k), "gcode.limit-skipped-lines");
}

// --- axis map and extension points -------------------------------------------------------------

TEST(InterpreterOutput, AxisMapExchangesAxesBeforeOutput) {
  Options options;
  options.axis_map[0] = Axis::Y;
  options.axis_map[1] = Axis::X;
  Interpreter interp(options);
  Recorder rec;
  ASSERT_EQ(run_into(interp, rec, "G21 F10\nG1 X1 Y2 Z3\nG3 X-1 Y2 I-1\nM2\n"), RunStatus::Finished);
  ASSERT_EQ(rec.motions.size(), 2u);
  EXPECT_EQ(rec.motions[0].end[Axis::X], 2.0);
  EXPECT_EQ(rec.motions[0].end[Axis::Y], 1.0);
  EXPECT_EQ(rec.motions[0].end[Axis::Z], 3.0);
  // A counterclockwise XY arc seen with X and Y exchanged turns clockwise.
  ASSERT_EQ(rec.arcs.size(), 1u);
  EXPECT_EQ(rec.arcs[0].plane, canon::Plane::XY);
  EXPECT_EQ(rec.arcs[0].rotation, -1);
  EXPECT_EQ(rec.arcs[0].first_end, 2.0);
  EXPECT_EQ(rec.arcs[0].second_end, -1.0);
  EXPECT_EQ(rec.arcs[0].first_center, 2.0);
  EXPECT_EQ(rec.arcs[0].second_center, 0.0);
  // The program's own view of the position is unchanged.
  EXPECT_EQ(interp.state().position.current[Axis::X], -1.0);
}

TEST(InterpreterExtensions, UnsupportedFeaturesNameTheirCode) {
  const std::pair<const char*, const char*> cases[] = {
      {"G21 G41 D1\n", "G41"},   {"G21 G81 X1 Z-1 R1\n", "G81"}, {"G21 G33 X1 K1\n", "G33"},
      {"G21 G38.2 Z-1 F10\n", "G38.2"}, {"G21 G5 X1 I1 J1 P1 Q1\n", "G5"}, {"G21 G71 Q1 D1\n", "G71"},
  };
  for (const auto& [program, code] : cases) {
    Interpreter interp;
    canon::Sink quiet;
    EXPECT_EQ(run_into(interp, quiet, program), RunStatus::Error) << program;
    EXPECT_EQ(first_code(interp), "gcode.unsupported") << program;
    ASSERT_NE(first_error(interp), nullptr);
    EXPECT_NE(first_error(interp)->message.find(std::string(code) + " "), std::string::npos) << first_error(interp)->message;
  }
}

TEST(InterpreterExtensions, NumberedSubprogramsOfTheLinuxCncDialectNeedTheirBody) {
  // M98 is LinuxCNC's own numbered subprogram call (numbered_subs_test.cpp); without an O1000
  // after it the call has nothing to run.
  Interpreter interp;
  canon::Sink quiet;
  EXPECT_EQ(run_into(interp, quiet, "G21\nM98 P1000\nM30\n"), RunStatus::Error);
  EXPECT_EQ(first_code(interp), "gcode.oword-sub-not-found");
}

namespace {

// A toy drilling cycle for G81: rapid over the hole, feed down, rapid back (enough to show
// that a registered handler runs at the motion step with the block's words).
class ToyDrill : public CodeHandler {
 public:
  std::optional<Rejection> check(const Block& block, int, const InterpState&) const override {
    if (!block.has('r')) return Rejection{ErrorCode::MissingValue, "the toy cycle needs R"};
    return std::nullopt;
  }
  void execute(ExecContext& ctx, const Block& block, int code) override {
    EXPECT_EQ(code, 810);
    const Pose end = ctx.end_point(block);
    Pose above = ctx.state().position.current;
    above[Axis::X] = end[Axis::X];
    above[Axis::Y] = end[Axis::Y];
    above[Axis::Z] = block.get('r');
    ctx.straight(true, above);
    Pose bottom = above;
    bottom[Axis::Z] = end[Axis::Z];
    ctx.straight(false, bottom);
    ctx.straight(true, above);
    ctx.state().modal.motion = code;
  }
};

class CountingM : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& block, int code) override {
    ctx.output().comment("user M" + std::to_string(code) + " P" + std::to_string(static_cast<int>(block.get('p'))));
  }
};

// Scales every motion by 2 (a stand-in for G51 scaling).
class Doubling : public CoordinateTransform {
 public:
  bool active(const InterpState&) const override { return true; }
  Pose point(const InterpState&, const Pose& p) const override {
    Pose q = p;
    for (int i = 0; i < 3; ++i) q[i] *= 2;
    return q;
  }
  void arc(const InterpState& s, canon::ArcFeed& a) const override {
    a.first_end *= 2, a.second_end *= 2, a.first_center *= 2, a.second_center *= 2, a.axis_end *= 2;
    a.end = point(s, a.end);
  }
};

}  // namespace

TEST(InterpreterExtensions, RegisteredHandlersRunInPlaceOfTheCore) {
  auto ext = std::make_shared<Extensions>();
  ext->g[810] = std::make_shared<ToyDrill>();
  ext->m[101] = std::make_shared<CountingM>();
  Options options;
  options.extensions = ext;
  Interpreter interp(options);
  Recorder rec;
  ASSERT_EQ(run_into(interp, rec, "G21 F100\nG0 Z5\nG81 X1 Y2 Z-3 R1\nM101 P7\nM2\n"), RunStatus::Finished)
      << first_code(interp);
  ASSERT_EQ(rec.motions.size(), 4u);
  EXPECT_EQ(rec.motions[1].kind, 't');
  EXPECT_EQ(rec.motions[2].kind, 'f');
  EXPECT_EQ(rec.motions[2].end[Axis::Z], -3.0);
  EXPECT_EQ(rec.motions[3].end[Axis::Z], 1.0);
  EXPECT_EQ(rec.motions[3].id, 3u);
  EXPECT_EQ(interp.state().position.current[Axis::Z], 1.0);
  ASSERT_FALSE(rec.comments.empty());
  EXPECT_EQ(rec.comments.back(), "user M101 P7");
  // The handler's own checks run before the block executes.
  Interpreter again(options);
  Recorder none;
  EXPECT_EQ(run_into(again, none, "G21 F100\nG0 Z5\nN30 G81 X1 Y2 Z-3\nM2\n"), RunStatus::Error);
  EXPECT_EQ(first_code(again), "gcode.missing-value");
  EXPECT_EQ(first_error(again)->col, 5u);  // a handler's rejection points at its code
  EXPECT_EQ(none.motions.size(), 1u);
}

TEST(InterpreterExtensions, TransformAppliesToOutputOnly) {
  auto ext = std::make_shared<Extensions>();
  ext->transform = std::make_shared<Doubling>();
  Options options;
  options.extensions = ext;
  Interpreter interp(options);
  Recorder rec;
  ASSERT_EQ(run_into(interp, rec, "G21 F100\nG1 X1 Y1\nG2 X3 Y1 I1\nM2\n"), RunStatus::Finished);
  ASSERT_EQ(rec.motions.size(), 2u);
  EXPECT_EQ(rec.motions[0].end[Axis::X], 2.0);
  ASSERT_EQ(rec.arcs.size(), 1u);
  EXPECT_EQ(rec.arcs[0].first_end, 6.0);
  EXPECT_EQ(rec.arcs[0].first_center, 4.0);
  EXPECT_EQ(interp.state().position.current[Axis::X], 3.0);
}

namespace {

// A stand-in compensator: records what reaches it, queues its output until G40 ends
// compensation, then emits every move shifted by the radius in Y.
class ShiftingCompensator : public MotionStage {
 public:
  void straight(ExecContext& ctx, bool rapid, const Pose& end) override {
    if (ctx.queued() == 0 && !open_) {
      ctx.open_queue();
      open_ = true;
    }
    Pose shifted = end;
    shifted[Axis::Y] += ctx.state().modal.comp_radius;
    seen.push_back(end[Axis::X]);
    ctx.output().dwell(0.5);   // queued with the moves, in order
    // A compensator writes to the output: ctx.straight() would come back here.
    if (rapid) ctx.output().straight_traverse(0, shifted);
    else ctx.output().straight_feed(0, shifted);
    ctx.state().position.current = end;
  }
  void arc(ExecContext& ctx, const Block&, int, const Pose&) override { ctx.error(ErrorCode::Unsupported, "no arcs"); }
  void finish(ExecContext& ctx) override {
    ctx.flush_queue();
    open_ = false;
  }
  std::vector<double> seen;

 private:
  bool open_ = false;
};

class CompOn : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& block, int) override {
    ctx.state().modal.cutter_comp = CutterComp::Left;
    ctx.state().modal.comp_radius = block.get('d');
  }
};

}  // namespace

TEST(InterpreterExtensions, CompensatorSeesEveryMoveAndItsQueueHoldsOutput) {
  auto ext = std::make_shared<Extensions>();
  auto comp = std::make_shared<ShiftingCompensator>();
  ext->compensator = comp;
  ext->g[410] = std::make_shared<CompOn>();
  Options options;
  options.extensions = ext;
  Interpreter interp(options);
  Recorder rec;
  interp.open_text("comp.ngc", "G21 F100\nG41 D0.5\nG1 X1\nG1 X2\nG40\nG1 X3\nM2\n");
  for (int i = 0; i < 4; ++i) ASSERT_EQ(interp.step(rec), RunStatus::Ok);
  EXPECT_TRUE(rec.motions.empty());   // held in the queue while compensation runs
  EXPECT_TRUE(rec.dwells.empty());
  ASSERT_EQ(interp.step(rec), RunStatus::Ok);   // G40 flushes
  ASSERT_EQ(interp.run(rec), RunStatus::Finished);
  EXPECT_EQ(comp->seen, (std::vector<double>{1, 2}));
  ASSERT_EQ(rec.motions.size(), 3u);
  EXPECT_EQ(rec.motions[0].end[Axis::Y], 0.5);
  EXPECT_EQ(rec.motions[1].end[Axis::Y], 0.5);
  EXPECT_EQ(rec.motions[2].end[Axis::Y], 0.0);   // after G40, straight to the output
  EXPECT_EQ(rec.motions[0].id, 0u);
  EXPECT_EQ(rec.motions[2].id, 2u);
  EXPECT_EQ(rec.dwells.size(), 2u);
}

// --- scan into a canon::Program ------------------------------------------------------------------

TEST(InterpreterScan, BuildsAMachineCoordinateProgram) {
  Interpreter interp;
  canon::ProgramBuilder builder(kXyzabc);
  builder.program().set_sources(interp.sources());
  ASSERT_EQ(run_into(interp, builder, "G20 F10\nG10 L2 P1 X1\nG0 X1 Y1\nG1 X2\nM2\n"), RunStatus::Finished);
  const canon::Program& prog = builder.program();
  ASSERT_EQ(prog.size(), 2u);
  // Inches and the G54 offset of 1 inch, in machine millimetres.
  EXPECT_NEAR(prog.end(0)[Axis::X], 50.8, 1e-12);
  EXPECT_NEAR(prog.end(1)[Axis::X], 76.2, 1e-12);
  EXPECT_NEAR(prog.end(0)[Axis::Y], 25.4, 1e-12);
  EXPECT_EQ(prog.move(1).line, 4u);
}

// --- conformance gaps of issue 6 -----------------------------------------------------------------

TEST(InterpreterErrors, AnEmptyProgramIsReportedOnItsFirstLine) {
  // A 0-byte file, blank lines only, or an opening '%' with nothing after it: file:1:1 as for
  // every other error (LinuxCNC: "File ended with no percent sign").
  for (const char* text : {"", "\n\n  \n", "%\n", "  %\n\n\t\n"}) {
    Interpreter interp;
    canon::Sink quiet;
    EXPECT_EQ(run_into(interp, quiet, text, "empty.ngc"), RunStatus::Error) << '"' << text << '"';
    const Diagnostic* d = first_error(interp);
    ASSERT_NE(d, nullptr);
    EXPECT_EQ(d->code, "gcode.program-empty");
    EXPECT_EQ(d->format().substr(0, 16), "empty.ngc:1:1: e") << d->format();
  }
  // Two '%' lines are a (empty) program, as rs274 reads them.
  Interpreter interp;
  canon::Sink quiet;
  EXPECT_EQ(run_into(interp, quiet, "%\n%\n"), RunStatus::Finished);
}

TEST(InterpreterOffsets, G28AndG30StoreAndReturnToMachinePositionsUnderARotatedSystem) {
  // G54 at X10 Y5 turned by 30 degrees: the machine origin is (-11.1603, 0.6699) in it.
  const test::Result r =
      test::run("G21 G90\nG10 L2 P1 X10 Y5 R30\nG54\nG28.1\nG0 X20 Y10 Z5\nG28 X30 Y15\nG30.1\nM2\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.code();
  // #5161.. hold machine coordinates (inches for the stand-alone units), here the origin.
  EXPECT_NEAR(r.state.parameters[5161], 0.0, 1e-12);
  EXPECT_NEAR(r.state.parameters[5162], 0.0, 1e-12);
  // The intermediate point is in the rotated system; the home comes back into it.
  const auto at = [&](const std::string& call) {
    return std::find(r.calls.begin(), r.calls.end(), call) != r.calls.end();
  };
  EXPECT_TRUE(at("STRAIGHT_TRAVERSE(30.0000, 15.0000, 5.0000, 0.0000, 0.0000, 0.0000)"));
  EXPECT_TRUE(at("STRAIGHT_TRAVERSE(-11.1603, 0.6699, 5.0000, 0.0000, 0.0000, 0.0000)"));
  // G30.1 at that point stores the machine origin again.
  EXPECT_NEAR(r.state.parameters[5181], 0.0, 1e-9);
  EXPECT_NEAR(r.state.parameters[5182], 0.0, 1e-9);
}

TEST(InterpreterParameters, ASubBodyMayNameItsCallsByLocalsItSetsLater) {
  // While a definition is read (not run), a named parameter without a value reads as 0 for the
  // O-word number of `o#<n> call`, as LinuxCNC allows; running the sub gives it its value.
  const test::Result r = test::run(
      "G21 F100\no1 sub\nG1 X1\no1 endsub\no<pick> sub\n#<n> = #1\no#<n> call\no<pick> endsub\n"
      "o<pick> call [1]\nM2\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.code();
  EXPECT_NE(r.text.find("STRAIGHT_FEED(1.0000, 0.0000"), std::string::npos);
  // In the flow of the program (not a definition) the name must still have a value.
  const test::Result undefined = test::run("G21 F100\no#<m> call\nM2\n");
  EXPECT_EQ(undefined.code(), "gcode.named-parameter-undefined");
}
