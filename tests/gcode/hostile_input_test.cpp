// SPDX-License-Identifier: GPL-3.0-or-later
// Hostile input to the interpreter (issue 7): NUL bytes, a byte-order mark, program files that
// are folders or cannot be read, and program numbers beyond the int range (fuzzer findings).
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "gcode_test_util.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

namespace opencnc::gcode {
namespace {

using test::run;

const Diagnostic* first_error(const test::Result& r) {
  for (const Diagnostic& d : r.diagnostics.items()) {
    if (d.severity == Severity::Error) return &d;
  }
  return nullptr;
}

TEST(HostileInput, ANulByteIsRefusedWhereItIs) {
  // LinuxCNC reads C strings: `G1 X1<NUL>Y2` would move X only.
  const test::Result r = run(std::string("G21 G90 F100\nG1 X1\0Y2\nM2\n", 24));
  ASSERT_EQ(r.status, RunStatus::Error);
  const Diagnostic* e = first_error(r);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->code, "gcode.bad-character");
  EXPECT_EQ(e->line, 2u);
  EXPECT_EQ(e->col, 6u);
  EXPECT_NE(e->message.find("NUL byte"), std::string::npos) << e->message;
  EXPECT_TRUE(r.calls.empty() || r.calls.back().find("STRAIGHT_FEED") == std::string::npos);
}

TEST(HostileInput, ANulByteInACommentIsRefusedToo) {
  const std::pair<std::string, std::uint32_t> cases[] = {{std::string("G0 X1 (a\0b)\n", 12), 9},
                                                         {std::string("G0 X1 ; a\0b\n", 12), 10}};
  for (const auto& [line, col] : cases) {
    const test::Result r = run("G21\n" + line + "M2\n");
    ASSERT_EQ(r.status, RunStatus::Error) << line;
    const Diagnostic* e = first_error(r);
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->line, 2u);
    EXPECT_EQ(e->col, col);
  }
}

TEST(HostileInput, AByteOrderMarkIsSkipped) {
  const test::Result plain = run("G21 G90\nG0 X1\nM2\n");
  const test::Result marked = run("\xEF\xBB\xBFG21 G90\nG0 X1\nM2\n");
  EXPECT_EQ(marked.status, RunStatus::Finished) << (first_error(marked) ? first_error(marked)->format() : "");
  EXPECT_EQ(marked.calls, plain.calls);
  // Columns count from the character after the mark.
  const test::Result bad = run("\xEF\xBB\xBFG21 Q\nM2\n");
  const Diagnostic* e = first_error(bad);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->line, 1u);
  EXPECT_EQ(e->col, 5u);
}

TEST(HostileInput, AByteOrderMarkOnlyCountsAtTheStart) {
  const test::Result r = run("G21\n\xEF\xBB\xBFG0 X1\nM2\n");
  EXPECT_EQ(r.status, RunStatus::Error);
}

class ProgramFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("opencnc-hostile-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string open_error(const std::string& path) {
    Interpreter interp{Options{}};
    EXPECT_FALSE(interp.open(path));
    return interp.diagnostics().items().empty() ? "" : interp.diagnostics().items()[0].format();
  }
  std::filesystem::path dir_;
};

TEST_F(ProgramFiles, AFolderIsNotAnEmptyProgram) {
  EXPECT_EQ(open_error(dir_.string()),
            dir_.string() + ": error: cannot open the program file: it is a folder, not a file");
}

TEST_F(ProgramFiles, AMissingFileSaysWhy) {
  const std::string p = (dir_ / "none.ngc").string();
  EXPECT_EQ(open_error(p), p + ": error: cannot open the program file: No such file or directory");
}

TEST_F(ProgramFiles, AnUnreadableFileSaysWhy) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files whatever their mode";
  const std::string p = (dir_ / "locked.ngc").string();
  std::ofstream(p) << "M2\n";
  ::chmod(p.c_str(), 0);
  EXPECT_EQ(open_error(p), p + ": error: cannot open the program file: Permission denied");
}

TEST_F(ProgramFiles, APipeIsRefusedWithoutWaitingForAWriter) {
  const std::string p = (dir_ / "fifo.ngc").string();
  ASSERT_EQ(::mkfifo(p.c_str(), 0600), 0);
  EXPECT_NE(open_error(p).find("not a regular file"), std::string::npos);
}

// Fuzzer finding (issue 6): `#3000 = 4.4e93` made the alarm number 3000 + INT_MAX.
TEST(HostileInput, AFanucAlarmNumberOutOfRangeIsNamed) {
  Options o;
  o.dialect = Dialect::Fanuc;
  o.extensions = standard_extensions(Dialect::Fanuc);
  const test::Result r = run("O1\nG21\n#3000 = 44444444444444444444 (TOO FAR)\nM30\n", o);
  ASSERT_EQ(r.status, RunStatus::Error);
  const Diagnostic* e = first_error(r);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->code, "fanuc.alarm");
  EXPECT_NE(e->message.find("is no alarm number (0 to 999"), std::string::npos) << e->message;
  const test::Result ok = run("O1\nG21\n#3000 = 15 (TOOL LIFE)\nM30\n", o);
  ASSERT_NE(first_error(ok), nullptr);
  EXPECT_NE(first_error(ok)->message.find("alarm 3015: TOOL LIFE"), std::string::npos)
      << first_error(ok)->message;
}

// Fuzzer finding (this campaign): a vacant value assigned to a system variable
// (`#3006 = #0`) threw std::out_of_range from the vacancy bitset, out of the interpreter.
TEST(HostileInput, AVacantValueForASystemVariableIsNoCrash) {
  Options o;
  o.dialect = Dialect::Fanuc;
  o.extensions = standard_extensions(Dialect::Fanuc);
  const test::Result r = run("O1\nG21 F100\n#3006 = #0\n#500 = #0\nG1 X1\nM30\n", o);
  EXPECT_EQ(r.status, RunStatus::Finished) << (first_error(r) ? first_error(r)->format() : "");
}

TEST(HostileInput, FinishingPassesBeyondTheLimitAreRefused) {
  Options o;
  o.extensions = standard_extensions(Dialect::LinuxCnc);
  const test::Result r =
      run("G21 G18 G90 F100\nG0 X14 Z3\no100 sub\n  G1 X3 Z1\n  G1 Z-4\n  G1 X10 Z-18\no100 endsub\n"
          "G70 Q100 X14 Z3 D0.3 P[10**300]\nM2\n",
          o);
  ASSERT_EQ(r.status, RunStatus::Error);
  const Diagnostic* e = first_error(r);
  ASSERT_NE(e, nullptr);
  EXPECT_NE(e->message.find("finishing passes"), std::string::npos) << e->format();
}

}  // namespace
}  // namespace opencnc::gcode

namespace opencnc::gcode {
namespace {

// rs274 refuses G95 with the speed at 0 only; with the spindle stopped LinuxCNC's motion waits
// for revolutions for ever. The preflight refuses it (issue 7).
TEST(HostileInput, FeedPerRevolutionWithTheSpindleStoppedIsRefused) {
  for (const char* move : {"G1 X10", "G2 X10 Y0 I5 J0"}) {
    const test::Result r = run(std::string("G21 G90 S1000 G95 F0.1\n") + move + "\nM2\n");
    ASSERT_EQ(r.status, RunStatus::Error) << move;
    const Diagnostic* e = first_error(r);
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->code, "gcode.spindle-stopped") << e->format();
    EXPECT_EQ(e->line, 2u);
    EXPECT_NE(e->message.find("with the spindle stopped: start it with M3 or M4"), std::string::npos);
  }
  EXPECT_EQ(run("G21 G90 S1000 M3 G95 F0.1\nG1 X10\nM5\nM2\n").status, RunStatus::Finished);
  const test::Result after_m5 = run("G21 G90 S1000 M3 G95 F0.1\nG1 X10\nM5\nG1 X0\nM2\n");
  ASSERT_NE(first_error(after_m5), nullptr);
  EXPECT_EQ(first_error(after_m5)->line, 4u);
  // Feed per minute needs no spindle (a warning only, as before).
  EXPECT_EQ(run("G21 G90 F100\nG1 X10\nM2\n").status, RunStatus::Finished);
}

}  // namespace
}  // namespace opencnc::gcode
