// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect: program structure, M98/M99/G65, GOTO/IF/WHILE, macro variables and their
// vacancy, system variables, lathe conventions, transforms through the interpreter, replay.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "gcode_test_util.hpp"
#include "opencnc/canon/tee_sink.hpp"
#include "opencnc/gcode/dialect.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

using namespace opencnc;
using namespace opencnc::gcode;

namespace {

Options fanuc(MachineKind machine = MachineKind::Mill) {
  Options o;
  o.dialect = Dialect::Fanuc;
  o.machine = machine;
  o.extensions = standard_extensions(Dialect::Fanuc);
  auto tools = std::make_shared<tools::ToolTable>();
  for (int t = 1; t <= 12; ++t) {
    tools::ToolEntry e;
    e.tool = t;
    e.pocket = t;
    e.offset[Axis::Z] = 0.1 * t;   // inches, as the tool table is read
    e.offset[Axis::X] = 0.01 * t;
    tools->add(e);
  }
  o.tool_table = tools;
  return o;
}

// Motions (kind, end) and the other calls the tests look at.
class Recorder : public canon::Sink {
 public:
  struct Motion {
    char kind;   // 't' traverse, 'f' feed, 'a' arc
    Pose end;
  };
  void straight_traverse(canon::SegmentId, const Pose& end) override { motions.push_back({'t', end}); }
  void straight_feed(canon::SegmentId, const Pose& end) override { motions.push_back({'f', end}); }
  void arc_feed(canon::SegmentId, const canon::ArcFeed& a) override {
    arcs.push_back(a);
    motions.push_back({'a', a.end});
  }
  void dwell(double s) override { dwells.push_back(s); }
  void comment(std::string_view text) override { comments.emplace_back(text); }
  void message(std::string_view text) override { messages.emplace_back(text); }
  void program_stop() override { ++stops; }
  void change_tool(int index) override { tool_changes.push_back(index); }
  void use_tool_length_offset(const Pose& o) override { offsets.push_back(o); }
  void set_spindle_mode(int, double css_max) override { css_max_rpm.push_back(css_max); }
  void set_feed_mode(int, canon::FeedMode m) override { feed_modes.push_back(m); }
  void select_plane(canon::Plane p) override { planes.push_back(p); }

  std::vector<Motion> motions;
  std::vector<canon::ArcFeed> arcs;
  std::vector<double> dwells, css_max_rpm;
  std::vector<std::string> comments, messages;
  std::vector<int> tool_changes;
  std::vector<Pose> offsets;
  std::vector<canon::FeedMode> feed_modes;
  std::vector<canon::Plane> planes;
  int stops = 0;

  // X (and Y, Z) of every motion, for compact expectations.
  std::vector<double> xs() const { return coords(Axis::X); }
  std::vector<double> ys() const { return coords(Axis::Y); }
  std::vector<double> zs() const { return coords(Axis::Z); }

 private:
  std::vector<double> coords(Axis a) const {
    std::vector<double> v;
    for (const auto& m : motions) v.push_back(m.end[a]);
    return v;
  }
};

struct Outcome {
  RunStatus status;
  std::string code;     // first error's code
  std::string message;  // and its text
  std::uint32_t line = 0;
  InterpState state;
};

Outcome run(Recorder& rec, std::string_view program, const Options& options = fanuc()) {
  Interpreter interp(options);
  interp.open_text("test.nc", std::string(program));
  Outcome r{interp.run(rec), "", "", 0, {}};
  for (const auto& d : interp.diagnostics().items()) {
    if (d.severity == Severity::Error) {
      r.code = d.code;
      r.message = d.message;
      r.line = d.line;
      break;
    }
  }
  r.state = interp.state();
  return r;
}

std::string error_of(std::string_view program, const Options& options = fanuc()) {
  Recorder rec;
  const Outcome r = run(rec, program, options);
  EXPECT_EQ(r.status, RunStatus::Error) << program;
  return r.code;
}

class TempDir {
 public:
  TempDir() {
    char name[] = "/tmp/opencnc_fanuc_test_XXXXXX";
    path_ = ::mkdtemp(name);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string write(const std::string& file, const std::string& text) const {
    std::ofstream(path_ / file) << text;
    return (path_ / file).string();
  }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace

// --- programs, calls and returns -------------------------------------------------------------

TEST(FanucPrograms, ProgramNumbersInEveryForm) {
  for (const char* head : {"O1000\n", ":1000 (COLON)\n", "%\nO1000 (NAME)\n", "%O1000(NAME)\n"}) {
    Recorder rec;
    const std::string tail = std::string(head).find('%') != std::string::npos ? "M30\n%\n" : "M30\n";
    const Outcome r = run(rec, std::string(head) + "G21 G1 X1 F100\n" + tail);
    EXPECT_EQ(r.status, RunStatus::Finished) << head << r.message;
    EXPECT_EQ(rec.xs(), std::vector<double>{1.0}) << head;
  }
}

TEST(FanucPrograms, SubprogramsInTheFileWithRepeatsAndTheFanuc0Form) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 G90 F100\nM98 P2 L2\nM98 P0030002\nG0 X0\nM30\n"
                    "O2\nG91 G1 X1\nG90\nM99\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{1, 2, 3, 4, 5, 0}));
  EXPECT_EQ(r.state.frames.size(), 1u);
}

TEST(FanucPrograms, CallsRunAfterTheBlocksMotionAndReturnToASequenceNumber) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 F100\nG1 X5 M98 P2\nG1 X6\nN40 G1 X7\nM30\n"
                    "O2\nG1 Y1\nM99 P40\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{5, 5, 7}));   // M99 P40 skips X6
}

TEST(FanucPrograms, SubprogramFilesComeFromTheSearchPath) {
  TempDir dir;
  dir.write("O0042.nc", "%\nO0042 (FILE)\nG91 G1 X2\nG90\nM99\n%\n");
  dir.write("o43.nc", "G91 G1 Y3\nG90\nM99\n");   // no program line: the file is the program
  Options o = fanuc();
  o.subroutine_path = {dir.str()};
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 F100\nM98 P42\nM98 P43 L2\nM98 P42\nM30\n", o);
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{2, 2, 2, 4}));
  EXPECT_EQ(rec.ys(), (std::vector<double>{0, 3, 6, 6}));
  dir.write("O0044.nc", "O0045\nM99\n");
  EXPECT_EQ(error_of("O1\nM98 P44\nM30\n", o), "fanuc.program-not-found");
  EXPECT_EQ(error_of("O1\nM98 P46\nM30\n", o), "fanuc.program-not-found");
}

TEST(FanucPrograms, MdiCallsRunTheirProgramToTheEnd) {
  TempDir dir;
  dir.write("O0007.nc", "O0007\nG91 G1 X#1\nG90\nM99\n");
  Options o = fanuc();
  o.subroutine_path = {dir.str()};
  Interpreter interp(o);
  Recorder rec;
  EXPECT_EQ(interp.execute_mdi("G21 F100", rec), RunStatus::Ok);
  EXPECT_EQ(interp.execute_mdi("G65 P7 A2", rec), RunStatus::Ok);
  EXPECT_EQ(interp.execute_mdi("#1 = 3", rec), RunStatus::Ok);
  EXPECT_EQ(interp.execute_mdi("M98 P7 L2", rec), RunStatus::Ok);
  EXPECT_EQ(rec.xs(), (std::vector<double>{2, 5, 8}));
  EXPECT_EQ(interp.state().frames.size(), 1u);
  EXPECT_EQ(interp.execute_mdi("GOTO 10", rec), RunStatus::Error);   // flow needs a program
  EXPECT_EQ(interp.execute_mdi("M98 P8", rec), RunStatus::Error);
  EXPECT_EQ(interp.execute_mdi("G1 X0", rec), RunStatus::Ok);        // the session goes on
}

TEST(FanucPrograms, MdiCalledReturnToASequenceNumberFails) {
  // M99 P returns to a block of the caller; an MDI line has no blocks to return to (found by the
  // fuzzer as a read past the open files).
  TempDir dir;
  dir.write("O0007.nc", "O0007\nG91 G1 X1\nG90\nM99 P5\n");
  Options o = fanuc();
  o.subroutine_path = {dir.str()};
  Interpreter interp(o);
  Recorder rec;
  EXPECT_EQ(interp.execute_mdi("G21 F100", rec), RunStatus::Ok);
  EXPECT_EQ(interp.execute_mdi("M98 P7", rec), RunStatus::Error);
  EXPECT_EQ(interp.state().frames.size(), 1u);
  EXPECT_EQ(interp.execute_mdi("G1 X0", rec), RunStatus::Ok);
}

TEST(FanucPrograms, MdiCallToASubprogramInNoFileFails) {
  // LinuxCNC's G70 Q (a profile subprogram) from Fanuc MDI, with no program open: an error
  // (found by the fuzzer as a read past the open files), and the session goes on.
  Interpreter interp(fanuc());
  Recorder rec;
  EXPECT_EQ(interp.execute_mdi("G18 G70 Q2", rec), RunStatus::Error);
  EXPECT_EQ(interp.execute_mdi("G21 G0 X1", rec), RunStatus::Ok);
  EXPECT_EQ(rec.xs().back(), 1.0);
}

TEST(FanucPrograms, ProgramsMustEndBeforeTheNextOne) {
  EXPECT_EQ(error_of("O1\nG21\nM98 P2\nM30\nO2\nG0 X1\nO3\nM99\n"), "fanuc.program-end-missing");
  EXPECT_EQ(error_of("O1\nG21\nM98 P2\nM30\nO2\nG0 X1\n"), "fanuc.program-end-missing");
  EXPECT_EQ(error_of("O1\nG21\nG0 X1\nO2\nM99\n"), "fanuc.program-end-missing");
}

TEST(FanucPrograms, M99InTheMainProgramEndsAScanAndRepeatsWhenExecuting) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 G91 G0 X1\nM99\n");
  EXPECT_EQ(r.status, RunStatus::Finished);
  EXPECT_EQ(rec.xs(), std::vector<double>{1.0});
  Options o = fanuc();
  o.mode = Mode::Execute;
  o.limits.max_loop_iterations = 3;
  Recorder again;
  const Outcome e = run(again, "O1\nG21 G91 G0 X1\nM99\n", o);
  EXPECT_EQ(e.code, "gcode.limit-loop-iterations");
  EXPECT_EQ(again.xs(), (std::vector<double>{1, 2, 3, 4}));
}

TEST(FanucPrograms, MacroCallsHaveTheirOwnLocals) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 F100\n#1 = 7\n#24 = 8\nG65 P9 X2 A3 L2\nG1 X#1 Y#24\nM30\n"
                    "O9\nG1 X#24 Y#1 Z#2\n#1 = #1 + 1\nM99\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  // The L repeats run in one local level: run 2 sees the #1 that run 1 left (4); the caller's
  // #1 and #24 come back after the last run.
  EXPECT_EQ(rec.xs(), (std::vector<double>{2, 2, 7}));
  EXPECT_EQ(rec.ys(), (std::vector<double>{3, 4, 8}));
  EXPECT_EQ(rec.zs(), (std::vector<double>{0, 0, 0}));   // B not given: #2 vacant
  EXPECT_EQ(r.state.parameters[1], 7.0);
}

// --- GOTO, IF, WHILE -------------------------------------------------------------------------

TEST(FanucFlow, GotoIfAndLoops) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 F100\n#1 = 0\nN10 #1 = #1 + 1\nG1 X#1\nIF [#1 LT 3] GOTO 10\n"
                    "#2 = 0\nWHILE [#2 LT 2] DO 1\n#3 = 0\nWHILE [#3 LT 2] DO 2\nG1 Y[#2 * 10 + #3]\n#3 = #3 + 1\nEND 2\n"
                    "#2 = #2 + 1\nEND 1\nGOTO 0070\nG1 Z99\nN70 G1 Z1\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{1, 2, 3, 3, 3, 3, 3, 3}));
  EXPECT_EQ(rec.ys(), (std::vector<double>{0, 0, 0, 0, 1, 10, 11, 11}));
  EXPECT_EQ(rec.zs().back(), 1.0);
}

TEST(FanucFlow, AFalseIfIsNotReadFurther) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 F100\nIF [0] THEN #1 = 1/0\nIF [0] GOTO #999\nIF [1] THEN #2 = 5 (SET)\nG1 X#2\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), std::vector<double>{5.0});
}

TEST(FanucFlow, GotoLeavesLoopsAndDoAloneLoopsForever) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 F100\n#1 = 0\nDO 1\n#1 = #1 + 1\nIF [#1 EQ 4] GOTO 9\nEND 1\nN9 G1 X#1\nDO 1\nGOTO 20\nEND 1\nN20 M30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), std::vector<double>{4.0});
}

TEST(FanucFlow, LoopAndJumpErrors) {
  EXPECT_EQ(error_of("O1\nWHILE [1] DO 1\nM30\n"), "fanuc.do-without-end");
  EXPECT_EQ(error_of("O1\nEND 2\nM30\n"), "fanuc.end-without-do");
  EXPECT_EQ(error_of("O1\nDO 1\nDO 1\nEND 1\nEND 1\nM30\n"), "fanuc.loop-structure");
  EXPECT_EQ(error_of("O1\nDO 1\nDO 2\nEND 1\nEND 2\nM30\n"), "fanuc.loop-structure");
  EXPECT_EQ(error_of("O1\nDO 4\nEND 4\nM30\n"), "fanuc.loop-structure");
  EXPECT_EQ(error_of("O1\nGOTO 5\nM30\n"), "fanuc.goto-target-missing");
  EXPECT_EQ(error_of("O1\nGOTO 0\nM30\n"), "fanuc.goto-target-missing");
  // A sequence number of another program is not a target.
  EXPECT_EQ(error_of("O1\nGOTO 5\nM30\nO2\nN5 M99\n"), "fanuc.goto-target-missing");
  EXPECT_EQ(error_of("O1\nIF [1] G1 X1\nM30\n"), "fanuc.if-syntax");
  EXPECT_EQ(error_of("O1\nIF [1] THEN G1 X1\nM30\n"), "fanuc.if-syntax");
  EXPECT_EQ(error_of("O1\no100 sub\nM30\n"), "dialect.unsupported");
  EXPECT_EQ(error_of("O1\nGOTO 5 X1\nN5 M30\n"), "fanuc.statement-syntax");
  Options o = fanuc();
  o.limits.max_loop_iterations = 100;
  EXPECT_EQ(error_of("O1\nN1 GOTO 1\nM30\n", o), "gcode.limit-loop-iterations");
}

// --- variables -------------------------------------------------------------------------------

TEST(FanucVariables, VacantValuesAreZeroInArithmeticAndLeaveWordsOut) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 F100\nG1 X1 Y1 Z1\n#5 = #0\n#6 = [#0]\n#7 = #0 + 2\n"
                    "IF [#5 EQ #0] THEN #8 = 1\nIF [#6 EQ #0] THEN #9 = 1\nIF [#5 LT 1] THEN #10 = 1\n"
                    "G1 X#5 Y#7 Z#100\nG1 X#8 Y#9 Z#10\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{1, 1, 1}));   // X#5: vacant, left out
  EXPECT_EQ(rec.ys(), (std::vector<double>{1, 2, 2}));   // #9 vacant: [#0] is 0, not vacant
  EXPECT_EQ(rec.zs(), (std::vector<double>{1, 1, 1}));
  EXPECT_TRUE(r.state.fanuc.vacant[5]);
  EXPECT_FALSE(r.state.fanuc.vacant[6]);
  EXPECT_TRUE(r.state.fanuc.vacant[9]);
  EXPECT_EQ(error_of("O1\n#0 = 1\nM30\n"), "fanuc.read-only-variable");
  EXPECT_EQ(error_of("O1\n#40 = 1\nM30\n"), "gcode.parameter-out-of-range");
  EXPECT_EQ(error_of("O1\n#1 = #2001\nM30\n"), "fanuc.variable-unavailable");
  EXPECT_EQ(error_of("O1\n#5041 = 1\nM30\n"), "fanuc.read-only-variable");
}

TEST(FanucVariables, FunctionsFollowFanuc) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 F100\n#1 = FIX[-2.7]\n#2 = FUP[-2.2]\n#3 = ATAN[-1]/[1]\n#4 = ATAN[1, -1]\n#5 = ASIN[-0.5]\n"
                    "#6 = 2 + 3 * 4\n#7 = SQRT[16] + ABS[-1] + ROUND[2.5]\nG1 X#1 Y#2\nG1 X#3 Y#4\nG1 X#5 Y#6 Z#7\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{-2, 315, 330}));
  EXPECT_EQ(rec.ys(), (std::vector<double>{-3, 135, 14}));
  EXPECT_EQ(rec.zs().back(), 8.0);
}

TEST(FanucVariables, SystemVariablesReadTheState) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 G91 G1 X3 Y4 F250\n#1 = #4001\n#2 = #4003\n#3 = #4109\n#4 = #5001\n#5 = #5042\n"
                    "G90 G1 X#1 Y#2\nG1 X#3 Y#4 Z#5\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{3, 1, 250}));
  EXPECT_EQ(rec.ys(), (std::vector<double>{4, 91, 3}));
  EXPECT_EQ(rec.zs().back(), 4.0);
}

TEST(FanucVariables, PositionNumbersPastTheNinthAxisReadZero) {
  // #5010..#5020 lie between the blocks of nine axes (#5001-#5009, #5021-#5029): they name no axis.
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 G1 X3 Y4 F250\n#1 = #5010\n#2 = #5020\n#3 = #5021\nG1 X#1 Y#2 Z#3\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs().back(), 0.0);
  EXPECT_EQ(rec.ys().back(), 0.0);
  EXPECT_EQ(rec.zs().back(), 3.0);   // #5021: machine X
}

TEST(FanucVariables, AlarmsStopAndMessagesPause) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 F100\nG1 X1\n#3006 = 1 (CHECK PART)\nG1 X2\n#3000 = 15 (TOOL LIFE)\nG1 X3\nM30\n");
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_EQ(r.code, "fanuc.alarm");
  EXPECT_NE(r.message.find("3015: TOOL LIFE"), std::string::npos) << r.message;
  EXPECT_EQ(r.line, 6u);
  EXPECT_EQ(rec.xs(), (std::vector<double>{1, 2}));
  EXPECT_EQ(rec.messages, std::vector<std::string>{"CHECK PART"});
  EXPECT_EQ(rec.stops, 1);
}

TEST(FanucVariables, CommentsMayNest) {
  Recorder rec;
  const Outcome r = run(rec, "O1 (A (NESTED) COMMENT)\nG21 F100 (MORE (TEXT))\nG1 X1\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.comments, std::vector<std::string>{"MORE (TEXT)"});
}

// --- codes -----------------------------------------------------------------------------------

TEST(FanucCodes, DwellUnitsPartsCounterAndMachineFunctions) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21\nG4 P1500\nG4 P2.5\nG04 X0.25\nM31\nM31\nM41\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.dwells, (std::vector<double>{1.5, 2.5, 0.25}));
  EXPECT_EQ(r.state.parameters[3901], 2.0);
  ASSERT_EQ(rec.comments.size(), 3u);
  EXPECT_EQ(rec.comments[2], "fanuc: M41 is a machine function (no action here)");
  // LinuxCNC's M codes keep their meaning, and M100-M199 stay user codes.
  EXPECT_EQ(error_of("O1\nM101\nM30\n"), "gcode.unknown-m-code");
}

TEST(FanucCodes, LatheWordsToolsClampAndFeedModes) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21\nT0202\nG50 S2000\nG96 S200 M3\nG0 X40 Z5\nG1 U-10 W-2 F0.2\nG98 G1 X20 F100\n"
                    "T0200\nG4 U0.5\nM30\n",
                    fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  ASSERT_GE(rec.planes.size(), 1u);
  EXPECT_EQ(rec.planes[0], canon::Plane::XZ);
  EXPECT_EQ(rec.feed_modes[0], canon::FeedMode::UnitsPerRevolution);
  EXPECT_EQ(rec.tool_changes, std::vector<int>{2});   // T0200 keeps tool 2: no second change
  ASSERT_EQ(rec.offsets.size(), 2u);
  EXPECT_NEAR(rec.offsets[0][Axis::Z], 0.2 * 25.4, 1e-9);   // tool 2's offset
  EXPECT_EQ(rec.offsets[1][Axis::Z], 0.0);                 // offset 00 cancels it
  EXPECT_EQ(rec.css_max_rpm, (std::vector<double>{2000.0, 0.0}));   // G96 takes the clamp; M30 ends CSS
  EXPECT_EQ(rec.xs(), (std::vector<double>{20, 15, 10}));   // diameters 40, 30, 20
  EXPECT_EQ(rec.zs(), (std::vector<double>{5, 3, 3}));
  EXPECT_EQ(rec.feed_modes.back(), canon::FeedMode::UnitsPerMinute);
  EXPECT_EQ(rec.dwells, std::vector<double>{0.5});
  EXPECT_EQ(error_of("O1\nG21 G1 X1 U1 F1\nM30\n", fanuc(MachineKind::Lathe)), "gcode.repeated-word");
}

TEST(FanucCodes, G76ThreadsWithEqualChipAreaPassesAlongTheFlank) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 M3 S500\nG0 X12 Z2\nG76 P010060 Q100 R0.05\nG76 X8 Z-10 P1000 Q400 F1.5\nM30\n",
                    fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  // Depths 0.4 * sqrt(n) (at least 0.1 more each time) up to 1.0 - 0.05, then one pass at 1.0.
  const double depths[] = {0.4, 0.4 * std::sqrt(2.0), 0.4 * std::sqrt(3.0), 0.8, 0.9, 0.95, 1.0};   // 0.894 is < 0.1 deeper
  std::vector<Recorder::Motion> cuts;
  for (const auto& m : rec.motions) {
    if (m.kind == 'f') cuts.push_back(m);
  }
  ASSERT_EQ(cuts.size(), std::size(depths));
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    EXPECT_NEAR(cuts[i].end[Axis::X], 4.0 + (1.0 - depths[i]), 1e-12);   // root radius 4, height 1
    EXPECT_EQ(cuts[i].end[Axis::Z], -10.0);
  }
  // Each pass starts further along Z by depth * tan(30 degrees) (infeed along the flank).
  std::vector<double> starts;
  for (std::size_t i = 1; i < rec.motions.size(); ++i) {
    if (rec.motions[i].kind == 'f') starts.push_back(rec.motions[i - 1].end[Axis::Z]);
  }
  EXPECT_NEAR(starts[0], 2.0 - 0.4 * std::tan(3.14159265358979323846 / 6), 1e-12);
  EXPECT_EQ(rec.motions.back().end[Axis::X], 6.0);   // back at the start point
  EXPECT_EQ(rec.motions.back().end[Axis::Z], 2.0);
  EXPECT_EQ(error_of("O1\nG21 G0 X12 Z2\nG76 X8 Z-10 P1000 Q400 F1.5\nM30\n", fanuc(MachineKind::Lathe)),
            "gcode.spindle-stopped");
  EXPECT_EQ(error_of("O1\nG21 M3 S100 G0 X12 Z2\nG76 X8 Z-10 Q400 F1.5\nM30\n", fanuc(MachineKind::Lathe)),
            "fanuc.cycle-word-missing");
}

TEST(FanucCodes, G75PecksAndStepsAcrossTheGroove) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 M3 S500\nG0 X20 Z-2\nG75 R0.5\nG75 X10 Z-8 P2000 Q3000 F0.1\nM30\n",
                    fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  // Per plunge: pecks of 2 (radius) to 8, 6, then 5, backing off 0.5 between; out to 10.
  const std::vector<double> plunge = {8, 8.5, 6, 6.5, 5, 10};
  std::vector<double> expect_x = {10};   // the G0
  for (int j = 0; j < 3; ++j) {
    if (j > 0) expect_x.push_back(10);
    expect_x.insert(expect_x.end(), plunge.begin(), plunge.end());
  }
  expect_x.push_back(10);
  EXPECT_EQ(rec.xs(), expect_x);
  EXPECT_EQ(rec.zs().back(), -2.0);
  EXPECT_EQ(rec.motions[8].end[Axis::Z], -5.0);
  EXPECT_EQ(rec.motions[rec.motions.size() - 3].end[Axis::Z], -8.0);
}

TEST(FanucCodes, G70RunsTheProfileBlocksAndReturnsToItsStart) {
  Recorder rec;
  const Outcome r = run(rec,
                    "O1\nG21 M3 S500\nG0 X30 Z2\nG70 P10 Q20 F0.1\nG0 X40\nM30\n"
                    "N10 G0 X10\nG1 Z-5\nN20 X30 Z-10\n",
                    fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{15, 5, 5, 15, 15, 20}));
  EXPECT_EQ(rec.zs(), (std::vector<double>{2, 2, -5, -10, 2, 2}));
  EXPECT_EQ(r.state.modal.feed_rate, 0.0);   // M30 ended it; the profile ran at F0.1
  EXPECT_EQ(error_of("O1\nG21 G70 P10 Q30\nM30\nN10 G0 X1\n", fanuc(MachineKind::Lathe)), "fanuc.goto-target-missing");
  EXPECT_EQ(error_of("O1\nG21 G70 P10\nM30\nN10 G0 X1\n", fanuc(MachineKind::Lathe)), "fanuc.cycle-word-missing");
  // Past the int range (found by the fuzzer as an undefined conversion): names no block.
  EXPECT_EQ(error_of("O1\nG21 G70 P16666666666666666666666 Q10\nM30\nN10 G0 X1\n", fanuc(MachineKind::Lathe)),
            "fanuc.goto-target-missing");
  EXPECT_EQ(error_of("O1\nGOTO 99999999999999999999\nM30\n"), "gcode.not-an-integer");   // read as an int: refused
}

// --- G71/G72 stock removal (fanuc_roughing.cpp) ------------------------------------------------

namespace {

// Motions as (kind, X radius, Z), for exact expectations.
using Step = std::tuple<char, double, double>;

void expect_motions(const Recorder& rec, const std::vector<Step>& want, const std::string& what) {
  ASSERT_EQ(rec.motions.size(), want.size()) << what;
  for (std::size_t i = 0; i < want.size(); ++i) {
    const auto& [kind, x, z] = want[i];
    EXPECT_EQ(rec.motions[i].kind, kind) << what << ": move " << i;
    EXPECT_NEAR(rec.motions[i].end[Axis::X], x, 1e-12) << what << ": move " << i;
    EXPECT_NEAR(rec.motions[i].end[Axis::Z], z, 1e-12) << what << ": move " << i;
  }
}

bool same_motions(const Recorder& a, const Recorder& b) {
  if (a.motions.size() != b.motions.size()) return false;
  for (std::size_t i = 0; i < a.motions.size(); ++i) {
    if (a.motions[i].kind != b.motions[i].kind) return false;
    for (const Axis axis : {Axis::X, Axis::Z}) {
      if (std::fabs(a.motions[i].end[axis] - b.motions[i].end[axis]) > 1e-12) return false;
    }
  }
  return true;
}

// A stepped shaft: face to X10, Z-10, taper to X20 at Z-15, Z-25, up to X30 (diameters).
constexpr const char* kShaft = "N10 G0 X10\nG1 Z-10\nX20 Z-15\nZ-25\nN20 X30\n";

}  // namespace

TEST(FanucRoughing, G71TwoBlockFormCutsLayersDownToTheShiftedShapeAndReturns) {
  Recorder rec;
  const Outcome r = run(rec, std::string("O1\nG21 M3 S500\nG0 X30 Z2\nG71 U2 R0.5\nG71 P10 Q20 U1 W0.5 F0.2\n") + kShaft +
                                 "G0 X40\nM30\n",
                        fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  // Traced by hand (radii). Start X15 Z2; the shape moves by U/2 = 0.5 and W = 0.5, so the
  // approach runs from the start to X5.5 Z2.5, and each layer starts on it:
  const auto on_approach = [](double x) { return 2 + (15 - x) / 9.5 * 0.5; };
  std::vector<Step> want{{'t', 15, 2}};
  // Layers X13 and X11 reach the shoulder at Z-24.5, X9 and X7 the taper (Z-13, Z-11); each
  // lifts off 0.5 at 45°, returns above its start and drops back to it.
  for (const auto& [x, end] : {std::pair{13.0, -24.5}, {11.0, -24.5}, {9.0, -13.0}, {7.0, -11.0}}) {
    const double z = on_approach(x);
    want.insert(want.end(), {{'t', x, z}, {'f', x, end}, {'t', x + 0.5, end + 0.5}, {'t', x + 0.5, z - 0.5}, {'t', x, z}});
  }
  // Below the shape's first point the last pass follows the shape, then back to the start.
  want.insert(want.end(), {{'t', 5.5, 2.5}, {'f', 5.5, -9.5}, {'f', 10.5, -14.5}, {'f', 10.5, -24.5}, {'f', 15.5, -24.5},
                           {'t', 15, 2}, {'t', 20, 2}});   // the block after N20: G0 X40
  expect_motions(rec, want, "G71");
  EXPECT_EQ(r.state.fanuc.cycles.rough_depth, 2.0);
  EXPECT_EQ(r.state.fanuc.cycles.rough_retract, 0.5);
}

TEST(FanucRoughing, HaasOneBlockFormTakesTheDepthFromD) {
  const std::string head = "O1\nG21 M3 S500\nG0 X30 Z2\n";
  const std::string tail = std::string(kShaft) + "G0 X40\nM30\n";
  Recorder two, haas, increments;
  ASSERT_EQ(run(two, head + "G71 U2 R0.5\nG71 P10 Q20 U1 W0.5 F0.2\n" + tail, fanuc(MachineKind::Lathe)).status,
            RunStatus::Finished);
  // Without R the retract is 0.5 mm (here also the two-block program's).
  const Outcome r = run(haas, head + "G71 P10 Q20 U1 W0.5 D2. F0.2\n" + tail, fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_TRUE(same_motions(two, haas));
  // D without a decimal point counts 0.001 mm, as Fanuc 0's one-block form writes it.
  ASSERT_EQ(run(increments, head + "G71 P10 Q20 U1 W0.5 D2000 F0.2\n" + tail, fanuc(MachineKind::Lathe)).status,
            RunStatus::Finished);
  EXPECT_TRUE(same_motions(two, increments));
}

TEST(FanucRoughing, G72FacesInLayersAlongZ) {
  Recorder rec;
  const Outcome r = run(rec,
                        "O1\nG21 M3 S500\nG0 X44 Z2\nG72 W1.5 R0.5\nG72 P10 Q20 F0.2\n"
                        "N10 G0 Z-6\nG1 X24\nZ-2\nN20 X0\nG0 X50\nM30\n",
                        fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  // Traced by hand: start X22 Z2 (radius); the shape is a shoulder face at Z-6 down to X12, a
  // stub X12 to Z-2 and its end face to the axis. Layers every 1.5 in Z from Z0.5 run inwards
  // from X22 to the axis (in front of the stub) or to the stub; each lifts off 0.5 towards
  // +Z and +X and returns outside.
  std::vector<Step> want{{'t', 22, 2}};
  for (const auto& [z, end] : {std::pair{0.5, 0.0}, {-1.0, 0.0}, {-2.5, 12.0}, {-4.0, 12.0}, {-5.5, 12.0}})
    want.insert(want.end(), {{'t', 22, z}, {'f', end, z}, {'t', end + 0.5, z + 0.5}, {'t', 21.5, z + 0.5}, {'t', 22, z}});
  // The last pass: along the shape, then along the axis to the start's Z; back to the start.
  want.insert(want.end(),
              {{'t', 22, -6}, {'f', 12, -6}, {'f', 12, -2}, {'f', 0, -2}, {'f', 0, 2}, {'t', 22, 2}, {'t', 25, 2}});
  expect_motions(rec, want, "G72");
}

// U and W leave stock by moving the shape: roughing with them is roughing the moved shape.
TEST(FanucRoughing, AllowancesMoveTheShapeInTheProgramsFrame) {
  const auto passes = [](const std::string& cycle, const std::string& shape) {
    Recorder rec;
    const Outcome r = run(rec, "O1\nG21 M3 S500\nG0 X44 Z2\n" + cycle + "\n" + shape + "G0 X50\nM30\n", fanuc(MachineKind::Lathe));
    EXPECT_EQ(r.status, RunStatus::Finished) << cycle << ": " << r.message;
    return rec;
  };
  EXPECT_TRUE(same_motions(passes("G71 P10 Q20 U2 W0.5 D1.5 F0.2", "N10 G0 X10\nG1 Z-10\nG2 X20 Z-15 R5\nN20 G1 X44\n"),
                           passes("G71 P10 Q20 D1.5 F0.2", "N10 G0 X12 Z2.5\nG1 Z-9.5\nG2 X22 Z-14.5 R5\nN20 G1 X46\n")));
  EXPECT_TRUE(same_motions(passes("G72 P10 Q20 U1 W0.4 D1.5 F0.2", "N10 G0 Z-6\nG1 X24\nG3 X14 Z-1 R5\nN20 G1 X0\n"),
                           passes("G72 P10 Q20 D1.5 F0.2", "N10 G0 X45 Z-5.6\nG1 X25\nG3 X15 Z-0.6 R5\nN20 G1 X1\n")));
  // Negative allowances (inside work) move it the other way.
  EXPECT_TRUE(same_motions(passes("G71 P10 Q20 U-2 W0.5 D1.5 F0.2", "N10 G0 X10\nG1 Z-10\nN20 X30\n"),
                           passes("G71 P10 Q20 D1.5 F0.2", "N10 G0 X8 Z2.5\nG1 Z-9.5\nN20 X28\n")));
}

// The layers end on the arcs of the shape (moved by the allowance); the last pass runs them.
TEST(FanucRoughing, ArcsOfTheShapeBoundTheLayers) {
  Recorder rec;
  const Outcome r = run(rec,
                        "O1\nG21 M3 S500\nG0 X40 Z2\nG71 P10 Q20 U0.4 W0.1 D1. F0.2\n"
                        "N10 G0 X0\nG1 Z0\nG3 X20 Z-10 R10\nN20 G1 Z-20\nG0 X50\nM30\n",
                        fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  // The sphere's centre X0 Z-10, moved by U/2 = 0.2 and W = 0.1.
  const double cx = 0.2, cz = -9.9;
  int on_arc = 0;
  for (std::size_t i = 1; i + 1 < rec.motions.size(); ++i) {
    const auto& m = rec.motions[i];
    const double d = std::hypot(m.end[Axis::X] - cx, m.end[Axis::Z] - cz);
    // A layer: a feed along Z followed by the lift-off.
    const bool layer = m.kind == 'f' && m.end[Axis::X] == rec.motions[i - 1].end[Axis::X] && rec.motions[i + 1].kind == 't';
    if (layer && m.end[Axis::Z] > cz && m.end[Axis::X] < 10.2 - 1e-9) {
      EXPECT_NEAR(d, 10.0, 1e-9) << "layer " << i << " ends off the arc";
      ++on_arc;
    }
  }
  EXPECT_EQ(on_arc, 10);   // layers X19 .. X1 end on the arc (X10.2 and above reach Z-19.9)
  ASSERT_EQ(rec.arcs.size(), 1u);
  EXPECT_NEAR(rec.arcs[0].first_center, cz, 1e-9);    // Z
  EXPECT_NEAR(rec.arcs[0].second_center, cx, 1e-9);   // X
}

// After roughing the program goes on after N Q when the shape follows the cycle, else after
// the cycle; G70 then finishes along the shape.
TEST(FanucRoughing, TheShapeIsPassedOverAndG70FinishesIt) {
  Recorder inline_shape, shape_after_m30;
  ASSERT_EQ(run(inline_shape,
                std::string("O1\nG21 M3 S500\nG0 X30 Z2\nG71 P10 Q20 D2. F0.2\n(SHAPE)\n\n") + kShaft + "G0 X40\nM30\n",
                fanuc(MachineKind::Lathe))
                .status,
            RunStatus::Finished);
  ASSERT_EQ(run(shape_after_m30, std::string("O1\nG21 M3 S500\nG0 X30 Z2\nG71 P10 Q20 D2. F0.2\nG0 X40\nM30\n") + kShaft,
                fanuc(MachineKind::Lathe))
                .status,
            RunStatus::Finished);
  EXPECT_TRUE(same_motions(inline_shape, shape_after_m30));
  EXPECT_EQ(inline_shape.motions.back().end[Axis::X], 20.0);
  Recorder finish;
  const Outcome r = run(finish,
                        std::string("O1\nG21 M3 S500\nG0 X30 Z2\nG71 P10 Q20 U1 W0.5 D2. F0.2\n") + kShaft +
                            "G70 P10 Q20 F0.1\nG0 X40\nM30\n",
                        fanuc(MachineKind::Lathe));
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  const std::vector<Step> tail{{'t', 15, 2},  {'t', 5, 2},    {'f', 5, -10}, {'f', 10, -15},
                               {'f', 10, -25}, {'f', 15, -25}, {'t', 15, 2},  {'t', 20, 2}};
  ASSERT_GT(finish.motions.size(), tail.size());
  Recorder last;
  last.motions.assign(finish.motions.end() - static_cast<std::ptrdiff_t>(tail.size()), finish.motions.end());
  expect_motions(last, tail, "G70 after G71");
}

TEST(FanucRoughing, ProblemsHaveTheirCodes) {
  const Options lathe = fanuc(MachineKind::Lathe);
  const std::string head = "O1\nG21 M3 S500\nG0 X30 Z2\n";
  const std::string tail = std::string(kShaft) + "M30\n";
  EXPECT_EQ(error_of(head + "G71 P10 Q20 F0.2\n" + tail, lathe), "fanuc.cycle-word-missing");   // no depth
  EXPECT_EQ(error_of(head + "G71 P10 D1. F0.2\n" + tail, lathe), "fanuc.cycle-word-missing");
  EXPECT_EQ(error_of(head + "G71 U0 R1\n" + tail, lathe), "fanuc.cycle-word-value");
  EXPECT_EQ(error_of(head + "G71 P10 Q20 D-1 F0.2\n" + tail, lathe), "fanuc.cycle-word-value");
  EXPECT_EQ(error_of(head + "G71 X20 P10 Q20 D1. F0.2\n" + tail, lathe), "fanuc.cycle-word-value");
  EXPECT_EQ(error_of(head + "G71 P10 Q30 D1. F0.2\n" + tail, lathe), "fanuc.goto-target-missing");
  EXPECT_EQ(error_of(head + "G71 P20 Q10 D1. F0.2\n" + tail, lathe), "fanuc.goto-target-missing");
  EXPECT_EQ(error_of(head + "G71 P10 Q20 I1 D1. F0.2\n" + tail, lathe), "gcode.unsupported");
  EXPECT_EQ(error_of("O1\nG21 M3 S500\nG0 X30 Z2\nG71 P10 Q20 D1.\n" + tail, lathe), "gcode.feed-zero");
  EXPECT_EQ(error_of("O1\nG21 G0 X30 Z2\nG71 P10 Q20 D1. F0.2\n" + tail), "gcode.unsupported");   // a mill
  EXPECT_EQ(error_of(head + "T0101\nG41 G0 X32\nG71 P10 Q20 D1. F0.2\n" + tail, lathe), "gcode.lathe-comp-on");
  // The shape: only moves, compensation, feed and spindle modes; no statements or calls.
  for (const char* block : {"G4 P1", "M98 P2", "#1 = 2", "GOTO 20", "G70 P10 Q20", "M30", "G54"}) {
    Recorder rec;
    const Outcome r =
        run(rec, head + "G71 P10 Q20 D1. F0.2\nN10 G0 X10\nG1 Z-10\n" + block + "\nN20 X30\nM30\n", lathe);
    EXPECT_EQ(r.code, "fanuc.profile-block") << block;
    EXPECT_EQ(r.line, 7u) << block << ": the error points at the shape's block";
  }
  // A shape that turns back along Z; one that never leaves its first point.
  EXPECT_EQ(error_of(head + "G71 P10 Q20 D1. F0.2\nN10 G0 X10\nG1 Z-10\nX16\nZ-5\nN20 X30\nM30\n", lathe),
            "gcode.lathe-profile-not-monotonic");
  EXPECT_EQ(error_of(head + "G71 P10 Q20 D1. F0.2\nN10 G0 X10\nN20 M8\nM30\n", lathe), "fanuc.profile-block");
  // From MDI the shape cannot be read (as G70 P Q cannot run); the settings block can.
  Interpreter mdi(lathe);
  mdi.open_text("shape.nc", "O1\nG21\nM30\n" + std::string(kShaft));
  Recorder rec;
  EXPECT_EQ(mdi.execute_mdi("G21 G0 X30 Z2 F0.2", rec), RunStatus::Ok);
  EXPECT_EQ(mdi.execute_mdi("G71 U2 R0.5", rec), RunStatus::Ok);
  EXPECT_EQ(mdi.execute_mdi("G71 P10 Q20", rec), RunStatus::Error);
  EXPECT_EQ(mdi.diagnostics().items().back().code, "gcode.oword-in-mdi");
  EXPECT_EQ(mdi.execute_mdi("G0 X40", rec), RunStatus::Ok);
  EXPECT_EQ(rec.motions.back().end[Axis::X], 20.0);
}

TEST(FanucCodes, G50IsScalingCancelOnAMill) {
  Recorder rec;
  const Outcome r = run(rec, "O1\nG21 F100\nG51 X0 Y0 P2\nG1 X1 Y1\nG50 S1000\nG1 X1 Y1\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{2, 1}));
  EXPECT_EQ(rec.css_max_rpm, std::vector<double>{0.0});   // only M30's: S is a speed here
}

// --- transforms through the interpreter ---------------------------------------------------------

TEST(FanucTransforms, CentresFollowTheStagesBeforeThem) {
  Recorder rec;
  // G68 programmed under G51: its centre (10, 0) is scaled to (20, 0) first (Fanuc's rule).
  const Outcome r = run(rec, "O1\nG21 F100\nG51 X0 Y0 P2\nG68 X10 Y0 R90\nG1 X10 Y0\nG1 X11 Y0\nG69 G50\nM30\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.message;
  EXPECT_EQ(rec.xs(), (std::vector<double>{20, 20}));
  EXPECT_EQ(rec.ys(), (std::vector<double>{0, 2}));
}

TEST(FanucTransforms, CodesThatMayNotRunUnderATransform) {
  EXPECT_EQ(error_of("O1\nG68 X0 Y0 R10\nG18\nM30\n"), "fanuc.rotation-plane-change");
  EXPECT_EQ(error_of("O1\nG68 X0 Y0 R10\nG53 G0 X0\nM30\n"), "fanuc.transform-active");
  EXPECT_EQ(error_of("O1\nG51.1 X1\nG92 X0\nM30\n"), "fanuc.transform-active");
  EXPECT_EQ(error_of("O1\nG51 P2\nG55\nM30\n"), "fanuc.transform-active");
  EXPECT_EQ(error_of("O1\nG51.1\nM30\n"), "fanuc.mirror-axes-missing");
  EXPECT_EQ(error_of("O1\nG51 P0\nM30\n"), "fanuc.scale-zero");
  EXPECT_EQ(error_of("O1\nG51 I2 J0\nM30\n"), "fanuc.scale-zero");
  EXPECT_EQ(error_of("O1\nG51 P2 I2\nM30\n"), "fanuc.scale-words");
  EXPECT_EQ(error_of("O1\nG68 X0 Y0\nM30\n"), "fanuc.rotation-angle-missing");
  EXPECT_EQ(error_of("O1\nG68 Z1 R5\nM30\n"), "gcode.unused-word");
  EXPECT_EQ(error_of("O1\nG21 F100\nG51 I1 J2\nG2 X1 Y1 I1\nM30\n"), "fanuc.arc-nonuniform-scale");
  // Not Fanuc codes in the LinuxCNC dialect, as in rs274.
  EXPECT_EQ(error_of("G68 X0 Y0 R10\nM2\n", Options{}), "gcode.unknown-g-code");
}

// --- other controllers -----------------------------------------------------------------------------

TEST(FanucDialect, OtherControllersAreNamed) {
  for (const Options& o : {Options{}, fanuc()}) {
    for (const char* program : {"$H\nM2\n", "%PM\nN10 G1 X1\n", "%_N_PART_MPF\n", "$BR0137.MIN%\n"}) {
      Recorder rec;
      const Outcome r = run(rec, program, o);
      EXPECT_EQ(r.code, "dialect.unsupported") << program;
      const std::string first(program, std::string_view(program).find('\n'));
      EXPECT_NE(r.message.find("'" + first + "'"), std::string::npos) << r.message;
    }
  }
}

TEST(FanucDialect, MarkersAndMachineKindsComeFromTheFile) {
  TempDir dir;
  EXPECT_EQ(dialect_marker(dir.write("a.nc", "%\n(DIALECT: FANUC)\nO1\nM30\n%\n")), Dialect::Fanuc);
  EXPECT_EQ(dialect_marker(dir.write("b.ngc", "; dialect = linuxcnc\nG0 X1\nM2\n")), Dialect::LinuxCnc);
  EXPECT_EQ(dialect_marker(dir.write("c.ngc", "G0 X1 (no marker: dialect outside)\nM2\n")), std::nullopt);
  EXPECT_EQ(dialect_marker(dir.write("d.ngc", "#<dialect> = 1 (fanuc)\nM2\n")), std::nullopt);
  EXPECT_EQ(guess_machine_kind(dir.write("l.nc", "O1\nG0 X20 Z2\nG1 U-2 W-1 F0.2 (Y IN A COMMENT)\nM30\n")), MachineKind::Lathe);
  EXPECT_EQ(guess_machine_kind(dir.write("m.nc", "O1\nG0 X20 Z2\nG1 Y5\nM30\n")), MachineKind::Mill);
  EXPECT_EQ(guess_machine_kind(dir.write("w.nc", "O1\n#1 = SQRT[EXP[2]]\nG0 X1 Z1\nM30\n")), MachineKind::Lathe);
  EXPECT_EQ(dialect_from_name("FANUC"), Dialect::Fanuc);
  EXPECT_EQ(machine_kind_from_name("lathe"), MachineKind::Lathe);
  EXPECT_EQ(dialect_from_name("sinumerik"), std::nullopt);
}

// --- state and replay ------------------------------------------------------------------------

namespace {

// The state when each motion is made, and the printed calls.
struct Trace {
  RunStatus status = RunStatus::Ok;
  std::vector<InterpState> states;
  std::vector<std::string> lines;
};

class StateAtMotion : public canon::Sink {
 public:
  StateAtMotion(const Interpreter& interp, Trace& t) : interp_(interp), trace_(t) {}
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

Trace trace(std::string_view program, canon::SegmentId quiet, Options o = fanuc()) {
  o.quiet_until_segment = quiet;
  Interpreter interp(o);
  interp.open_text("replay.nc", std::string(program));
  Trace t;
  StateAtMotion states(interp, t);
  test::MemoryStream out;
  {
    canon::Rs274Printer printer(out.file(), out.file());
    canon::TeeSink tee(printer, states);
    canon::Sink nowhere;
    interp.start(nowhere);
    t.status = interp.run(tee);
  }
  const std::string text = out.text();
  for (std::size_t pos = 0; pos < text.size();) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    t.lines.push_back(text.substr(pos + std::min<std::size_t>(6, nl - pos), nl - pos - std::min<std::size_t>(6, nl - pos)));
    pos = nl + 1;
  }
  return t;
}

}  // namespace

// Seeded random Fanuc programs (calls with repeats, macro calls, loops, GOTO, transforms):
// replaying to segment k gives the state of the full run at segment k, and the same tail.
TEST(FanucReplay, SeededRandomProgramsReplayExactly) {
  std::mt19937 rng(11);
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  auto num = [&] { return std::to_string(pick(100) - 50) + "." + std::to_string(pick(10)); };
  for (int round = 0; round < 5; ++round) {
    std::string p = "%\nO1\nG21 G90 G17 F100\n#100 = 0\n";
    int loop = 0;
    const int blocks = 10 + pick(8);
    for (int i = 0; i < blocks; ++i) {
      switch (pick(8)) {
        case 0: p += "G0 X" + num() + " Y" + num() + "\n"; break;
        case 1: p += "M98 P2 L" + std::to_string(1 + pick(3)) + "\n"; break;
        case 2: p += "G65 P3 A" + num() + " B" + num() + "\n"; break;
        case 3: {
          const std::string id = std::to_string(1 + (loop++ % 3));
          p += "#10 = 0\nWHILE [#10 LT " + std::to_string(1 + pick(3)) + "] DO " + id + "\nG91 G1 X1\nG90\n#10 = #10 + 1\nEND " + id + "\n";
          break;
        }
        case 4: p += "G68 X" + num() + " Y" + num() + " R" + num() + "\nG1 X" + num() + "\nG69\n"; break;
        case 5: p += "G51.1 X" + num() + "\nG2 X" + num() + " Y0 R200\nG50.1\n"; break;
        case 6: p += "G51 X0 Y0 P" + std::to_string(1 + pick(3)) + "\nG1 Y" + num() + "\nG50\n"; break;
        default: p += "IF [#100 GT 2] GOTO " + std::to_string(900 + i) + "\nG1 Z" + num() + "\nN" + std::to_string(900 + i) + " G1 Z0\n"; break;
      }
    }
    p += "G0 X0 Y0\nM30\nO2\n#100 = #100 + 1\nG91 G1 Y1\nG90\nM99\nO3\nG1 X#1 Y#2\nM99\n%\n";
    SCOPED_TRACE(p);
    const Trace full = trace(p, 0);
    ASSERT_EQ(full.status, RunStatus::Finished);
    ASSERT_GT(full.states.size(), 3u);
    for (canon::SegmentId k = 1; k < full.states.size(); k += 1 + k / 4) {
      const Trace part = trace(p, k);
      ASSERT_EQ(part.status, RunStatus::Finished);
      ASSERT_EQ(part.states.size(), full.states.size());
      EXPECT_EQ(part.states[k], full.states[k]) << "segment " << k;
      EXPECT_EQ(part.states[k].digest(), full.states[k].digest());
      ASSERT_LE(part.lines.size(), full.lines.size());
      EXPECT_TRUE(std::equal(part.lines.begin(), part.lines.end(), full.lines.end() - static_cast<std::ptrdiff_t>(part.lines.size())));
    }
  }
}

// A roughing cycle (its settings, the shape read and passed over, G70 after it) replays to
// any of its moves exactly.
TEST(FanucReplay, RoughingCyclesReplayExactly) {
  const std::string p = std::string("%\nO1\nG21 M3 S500\nG0 X30 Z2\nG71 U2 R0.5\nG71 P10 Q20 U1 W0.5 F0.2\n") + kShaft +
                        "G70 P10 Q20\nG0 X40\nG72 P30 Q40 D1.5 F0.2\nN30 G0 Z-6\nG1 X24\nN40 X0\nG0 X50\nM30\n%\n";
  const Trace full = trace(p, 0, fanuc(MachineKind::Lathe));
  ASSERT_EQ(full.status, RunStatus::Finished);
  ASSERT_GT(full.states.size(), 40u);
  for (canon::SegmentId k = 1; k < full.states.size(); k += 3) {
    const Trace part = trace(p, k, fanuc(MachineKind::Lathe));
    ASSERT_EQ(part.status, RunStatus::Finished);
    ASSERT_EQ(part.states.size(), full.states.size());
    EXPECT_EQ(part.states[k], full.states[k]) << "segment " << k;
    EXPECT_EQ(part.states[k].digest(), full.states[k].digest());
    ASSERT_LE(part.lines.size(), full.lines.size());
    EXPECT_TRUE(std::equal(part.lines.begin(), part.lines.end(), full.lines.end() - static_cast<std::ptrdiff_t>(part.lines.size())));
  }
}

TEST(FanucState, TransformsAndVacancyAreInTheDigest) {
  Recorder a, b, c;
  const Outcome base = run(a, "O1\nG21\nM30\n");
  const Outcome turned = run(b, "O1\nG21\nG68 X0 Y0 R10\nM30\n");
  const Outcome set = run(c, "O1\nG21\n#500 = 0\nM30\n");
  EXPECT_NE(base.state.digest(), turned.state.digest());
  EXPECT_NE(base.state.digest(), set.state.digest());   // #500 = 0 differs from vacant #500
  EXPECT_FALSE(base.state == set.state);
}
