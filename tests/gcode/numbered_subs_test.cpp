// SPDX-License-Identifier: GPL-3.0-or-later
// LinuxCNC's numbered subprograms in its own dialect: M98 P L calls of O-numbered bodies that
// end with M99, their errors, and M99 in the main program (a program end, or an endless program).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gcode_test_util.hpp"

using namespace opencnc;
using namespace opencnc::gcode;
using test::TempDir;

namespace {

// The ends of the program's moves, in order ('t' traverse, 'f' feed) and their source lines.
class Moves : public canon::Sink {
 public:
  struct Move {
    char kind;
    Pose end;
    std::uint32_t line;
  };
  void begin_block(const canon::BlockOrigin& o) override { line_ = o.line; }
  void straight_traverse(canon::SegmentId, const Pose& end) override { moves.push_back({'t', end, line_}); }
  void straight_feed(canon::SegmentId, const Pose& end) override { moves.push_back({'f', end, line_}); }
  std::vector<Move> moves;

 private:
  std::uint32_t line_ = 0;
};

struct Outcome {
  RunStatus status = RunStatus::Ok;
  Moves sink;
  InterpState state;
  Diagnostic error;  // the first error
};

Outcome run(const std::string& program, Options options = {}) {
  Outcome r;
  Interpreter interp(options);
  interp.open_text("main.ngc", program);
  r.status = interp.run(r.sink);
  r.state = interp.state();
  for (const auto& d : interp.diagnostics().items()) {
    if (d.severity == Severity::Error) {
      r.error = d;
      break;
    }
  }
  return r;
}

// X of every feed move.
std::vector<double> feed_x(const Outcome& o) {
  std::vector<double> x;
  for (const auto& m : o.sink.moves) {
    if (m.kind == 'f') x.push_back(m.end[Axis::X]);
  }
  return x;
}

}  // namespace

// --- calls and returns -----------------------------------------------------------------------

TEST(NumberedSubprograms, AnM98CallRunsTheOBodyThatFollowsAndM99ReturnsAfterTheCall) {
  const Outcome r =
      run("G21 F100\n"      // 1
          "G1 X1\n"         // 2
          "M98 P100\n"      // 3
          "G1 X3\n"         // 4
          "M30\n"           // 5
          "O100 (a sub)\n"  // 6
          "G1 X2\n"         // 7
          "M99\n");         // 8
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error.message;
  EXPECT_EQ(feed_x(r), (std::vector<double>{1, 2, 3}));
  ASSERT_EQ(r.sink.moves.size(), 3u);
  EXPECT_EQ(r.sink.moves[1].line, 7u);  // the body's own line
  EXPECT_EQ(r.state.frames.size(), 1u);
}

TEST(NumberedSubprograms, LRepeatsTheCallAndL0SkipsIt) {
  // #1..#30 are global for numbered subprograms: the body's count carries from call to call.
  const Outcome r =
      run("G21 F100 G91\n"
          "#1 = 0\n"
          "M98 P7 L3\n"
          "M98 P7 L0\n"
          "M98 P7 L1\n"
          "G90 G1 X[#1 * 100]\n"
          "M30\n"
          "O7\n"
          "#1 = [#1 + 1]\n"
          "G1 X1\n"
          "M99\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error.message;
  EXPECT_EQ(feed_x(r), (std::vector<double>{1, 2, 3, 4, 400}));
  EXPECT_EQ(r.state.frames.size(), 1u);
  EXPECT_EQ(r.state.frames[0].m98_left, -1);
}

TEST(NumberedSubprograms, ParametersOneToThirtyAreSharedButNamedLocalsStayInTheirSub) {
  const Outcome shared =
      run("G21 F100\n#5 = 2\nM98 P1\nG1 X#5 Y#<_g>\nM30\n"
          "O1\n#5 = [#5 * 3]\n#<_g> = 4\nM99\n");
  ASSERT_EQ(shared.status, RunStatus::Finished) << shared.error.message;
  ASSERT_EQ(shared.sink.moves.size(), 1u);
  EXPECT_EQ(shared.sink.moves[0].end[Axis::X], 6);
  EXPECT_EQ(shared.sink.moves[0].end[Axis::Y], 4);
  const Outcome local = run("G21 F100\nM98 P1\nG1 X#<here>\nM30\nO1\n#<here> = 4\nM99\n");
  EXPECT_EQ(local.status, RunStatus::Error);
  EXPECT_EQ(local.error.code, "gcode.named-parameter-undefined");
  EXPECT_EQ(local.error.line, 3u);
}

TEST(NumberedSubprograms, NestedCallsAnExpressionPAndLeadingZerosNameTheSameProgram) {
  const Outcome r =
      run("G21 F100\n"
          "M98 P[50 * 2]\n"
          "G1 X9\n"
          "M30\n"
          "O0100\n"
          "G1 X1\n"
          "M98 P200 L2\n"
          "G1 X4\n"
          "M99\n"
          "O200\n"
          "G91 G1 X1\n"
          "G90\n"
          "M99\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error.message;
  EXPECT_EQ(feed_x(r), (std::vector<double>{1, 2, 3, 4, 9}));
}

TEST(NumberedSubprograms, ReadingFlowsIntoAnOLineThatNoCallSought) {
  // LinuxCNC passes into a numbered body met in the flow of the program (a main program's
  // number line, or the next body after one that the call left): only M98 makes it a call.
  // Here the flow reaches O5 after the call has returned, runs its line, and its M99 is then
  // the main program's: the end.
  const Outcome r = run("O1 (main)\nG21 F100\nM98 P5\nG1 X2\nO5\nG1 X1\nM99\n");
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error.message;
  EXPECT_EQ(feed_x(r), (std::vector<double>{1, 2, 1}));
}

TEST(NumberedSubprograms, ACallFindsItsBodyInAFileOnTheSubroutinePath) {
  TempDir dir;
  dir.write("123.ngc", "O123\nG1 X7\nM99\n");
  Options o;
  o.subroutine_path = {dir.str()};
  const Outcome r = run("G21 F100\nM98 P123 L2\nG1 X1\nM2\n", o);
  ASSERT_EQ(r.status, RunStatus::Finished) << r.error.message;
  EXPECT_EQ(feed_x(r), (std::vector<double>{7, 7, 1}));
}

TEST(NumberedSubprograms, CallsNestDeeperThanTenLevelsNowhere) {
  const Outcome r = run("G21 F100\nM98 P1\nM2\nO1\nG91 G1 X1\nM98 P1\nM99\n");
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_EQ(r.error.code, "gcode.limit-call-depth");
  EXPECT_NE(r.error.message.find("M98 P1"), std::string::npos) << r.error.message;
  EXPECT_EQ(feed_x(r).size(), 9u);
}

// --- errors --------------------------------------------------------------------------------------

TEST(NumberedSubprograms, TheCallLineHoldsPAndLOnly) {
  struct Case {
    const char* line;
    const char* code;
    std::uint32_t col;
  };
  const Case cases[] = {
      {"M98 L2", "fanuc.call-program-missing", 1},
      {"M98 P1.5", "gcode.not-an-integer", 5},
      {"M98 P1 L-1", "gcode.l-word-negative", 8},
      {"M98 P1 Q3", "gcode.unused-word", 8},    // LinuxCNC's word rules first
      {"M98 P1 F30", "gcode.oword-syntax", 8},  // what they let pass LinuxCNC ignores
      {"M98 P1 G1 X3", "gcode.oword-syntax", 8},
      {"M98 P1 #3=7", "gcode.oword-syntax", 1},     // LinuxCNC would not assign it
      {"G0 X1 M98 P1", "gcode.unknown-m-code", 7},  // M98 calls only at the start of a line
  };
  for (const Case& c : cases) {
    const Outcome r = run(std::string("G21 F100 G1\n") + c.line + "\nM30\nO1\nG1 X1\nM99\n");
    EXPECT_EQ(r.status, RunStatus::Error) << c.line;
    EXPECT_EQ(r.error.code, c.code) << c.line << ": " << r.error.message;
    EXPECT_EQ(r.error.line, 2u) << c.line;
    EXPECT_EQ(r.error.col, c.col) << c.line << ": " << r.error.message;
  }
}

TEST(NumberedSubprograms, AMissingBodyIsReportedAtTheCall) {
  const Outcome r = run("G21 F100\nM98 P42\nM30\nO41\nM99\n");
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_EQ(r.error.code, "gcode.oword-sub-not-found");
  EXPECT_EQ(r.error.line, 2u);
  EXPECT_NE(r.error.message.find("M98 P42"), std::string::npos) << r.error.message;
  // A body after the closing '%' is not part of the program (LinuxCNC).
  const Outcome after = run("%\nG21 F100\nM98 P1\nM30\n%\nO1\nM99\n");
  EXPECT_EQ(after.status, RunStatus::Error);
  EXPECT_EQ(after.error.code, "gcode.oword-sub-not-found");
  // A body before its first call is not found either: LinuxCNC looks forward from the call.
  const Outcome before = run("G21 F100\nM98 P1\nM30\n");
  EXPECT_EQ(before.error.code, "gcode.oword-sub-not-found");
}

TEST(NumberedSubprograms, TheTwoSubprogramStylesDoNotMix) {
  struct Case {
    const char* program;
    std::uint32_t line;
  };
  const Case cases[] = {
      {"G21\no100 call\nM2\nO100\nM99\n", 4},                   // a numbered body called with 'call'
      {"G21\nM98 P100\nM2\no100 sub\no100 endsub\n", 4},        // an o-sub called with M98
      {"G21\nM98 P100\nM2\nO100\no100 endsub\n", 5},            // a numbered body ended by endsub
      {"G21\no100 call\nM2\no100 sub\nM99\no100 endsub\n", 5},  // an o-sub ended by M99
  };
  for (const Case& c : cases) {
    const Outcome r = run(c.program);
    EXPECT_EQ(r.status, RunStatus::Error) << c.program;
    EXPECT_EQ(r.error.code, "gcode.oword-mixed-styles") << c.program << r.error.message;
    EXPECT_EQ(r.error.line, c.line) << c.program;
  }
}

TEST(NumberedSubprograms, M99AfterOtherWordsInASubprogramIsRefused) {
  const Outcome r = run("G21 F100\nM98 P1\nM2\nO1\nG1 X1 M99\nM99\n");
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_EQ(r.error.code, "gcode.oword-syntax");
  EXPECT_EQ(r.error.line, 5u);
  EXPECT_EQ(r.error.col, 7u);
  const Outcome words = run("G21 F100\nM98 P1\nM2\nO1\nM99 X1\n");
  EXPECT_EQ(words.error.code, "gcode.oword-syntax");
  EXPECT_EQ(words.error.col, 5u);
}

// --- M99 in the main program ---------------------------------------------------------------------

TEST(NumberedSubprograms, MainProgramM99EndsTheProgramAsRs274Does) {
  // LinuxCNC's stand-alone interpreter ends there, with M2's resets (the default, MainM99::End).
  const test::Result r = test::run("G21 F100\nG91 G1 X1\nM99\nG1 X5\n");
  ASSERT_EQ(r.status, RunStatus::Finished);
  ASSERT_FALSE(r.calls.empty());
  EXPECT_EQ(r.calls.back(), "PROGRAM_END()");
  EXPECT_EQ(r.text.find("PALLET_SHUTTLE"), std::string::npos);
  EXPECT_EQ(r.state.modal.distance, DistanceMode::Absolute);
}

TEST(NumberedSubprograms, MainProgramM99RepeatsInExecuteModeUntilTheCallerStops) {
  // LinuxCNC's task: back to the first line with the state as it is, for ever. Each pass starts
  // the limits' block count afresh, so an endless program outlives max_blocks.
  Options o;
  o.mode = Mode::Execute;
  o.main_m99 = MainM99::Repeat;
  o.limits.max_blocks = 50;
  Interpreter interp(o);
  interp.open_text("warmup.ngc", "#<_n> = [#<_n> + 1]\nG21 F100 G91\nG1 X1\nM98 P5\nM99\nO5\nG1 Y1\nM99\n");
  Moves sink;
  for (int i = 0; i < 100000 && sink.moves.size() < 2 * 5000; ++i)
    ASSERT_EQ(interp.step(sink), RunStatus::Ok) << i;
  ASSERT_EQ(sink.moves.size(), 2u * 5000u);
  EXPECT_DOUBLE_EQ(sink.moves.back().end[Axis::X], 5000);
  EXPECT_DOUBLE_EQ(sink.moves.back().end[Axis::Y], 5000);
  EXPECT_EQ(interp.state().control.main_repeats, 4999u);
  ASSERT_EQ(interp.state().frames.size(), 2u);  // in O5, its Y move just made
  ASSERT_EQ(interp.step(sink), RunStatus::Ok);  // its M99
  EXPECT_EQ(interp.state().frames.size(), 1u);
}

TEST(NumberedSubprograms, MainProgramM99RepeatInScanModeStopsWithAClearError) {
  Options o;
  o.main_m99 = MainM99::Repeat;
  o.limits.max_main_repeats = 4;
  const Outcome r = run("G21 F100 G91\nG1 X1\nM99\n", o);
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_EQ(r.error.code, "gcode.limit-main-repeats");
  EXPECT_EQ(r.error.line, 3u);
  EXPECT_EQ(r.error.col, 1u);
  EXPECT_NE(r.error.message.find("max_main_repeats"), std::string::npos) << r.error.message;
  EXPECT_EQ(feed_x(r).size(), 5u);  // the first pass and four repetitions
  // A /M30 ends the endless program once block delete is off (the operator's tidy stop).
  Options stop = o;
  stop.block_delete = false;
  const Outcome ended = run("G21 F100 G91\nG1 X1\n/M30\nM99\n", stop);
  EXPECT_EQ(ended.status, RunStatus::Finished) << ended.error.message;
  EXPECT_EQ(feed_x(ended).size(), 1u);
  Options skip = o;
  skip.block_delete = true;
  EXPECT_EQ(run("G21 F100 G91\nG1 X1\n/M30\nM99\n", skip).error.code, "gcode.limit-main-repeats");
}

TEST(NumberedSubprograms, AnMdiLineCallsANumberedSubprogramFromTheSearchPath) {
  TempDir dir;
  dir.write("77.ngc", "(a numbered subprogram in a file of its own)\nO77\nG91 G1 X2\nG90\nM99\n");
  Options o;
  o.subroutine_path = {dir.str()};
  Interpreter interp(o);
  Moves sink;
  ASSERT_EQ(interp.execute_mdi("G21 F100", sink), RunStatus::Ok);
  ASSERT_EQ(interp.execute_mdi("M98 P77 L2", sink), RunStatus::Ok)
      << interp.diagnostics().items().back().format();
  ASSERT_EQ(sink.moves.size(), 2u);
  EXPECT_EQ(sink.moves[1].end[Axis::X], 4);
  EXPECT_EQ(interp.state().frames.size(), 1u);
  EXPECT_EQ(interp.execute_mdi("M98 P78", sink), RunStatus::Error);
}
