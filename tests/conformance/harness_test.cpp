// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the conformance harness itself: listing parser, comparison, golden files, processes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lzma.h>
#include <random>

#include <fmt/format.h>

#include "harness/cases.hpp"
#include "harness/golden.hpp"
#include "harness/listing.hpp"
#include "harness/process.hpp"
#include "harness/runner.hpp"

namespace fs = std::filesystem;
using namespace opencnc::conformance;

namespace {

constexpr std::string_view kListing =
    "    1 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
    "    2 N..... SELECT_PLANE(CANON_PLANE_XZ)\n"
    "print 3.000000\n"
    "    3 N0020  SET_FEED_RATE(100.0000)\n"
    "    4 N5     STRAIGHT_FEED(1.0000, 2.0000, -0.0000, 0.0000, 0.0000, 0.0000)\n"
    "    5 N..... COMMENT(\"interpreter: (a) comment, with commas\")\n"
    "    6 N..... ARC_FEED(3.0000, 2.0000, 2.0000, 2.0000, -1, -1.0000, 0.0000, 0.0000, 0.0000)\n"
    "    7 N..... SET_SPINDLE_MODE(0 0.0000)\n"
    "    8 N..... PROGRAM_END()\n"
    "    9 N..... ON_RESET()";  // rs274's last line has no newline when it stops early

TEST(Listing, ParsesCallsAndSkipsOtherLines) {
  const auto calls = parse_listing(kListing);
  ASSERT_EQ(calls.size(), 9u);
  EXPECT_EQ(calls[0].name, "USE_LENGTH_UNITS");
  EXPECT_EQ(calls[2].name, "SET_FEED_RATE");
  EXPECT_EQ(calls[2].line, 4u);  // listing line, counting the PRINT line
  EXPECT_EQ(calls[4].args, "\"interpreter: (a) comment, with commas\"");
  EXPECT_EQ(calls[8].name, "ON_RESET");
  EXPECT_EQ(calls[8].line, 10u);
}

TEST(Listing, MotionSubsetKeepsOnlyTheComparedCalls) {
  const auto calls = motion_subset(parse_listing(kListing));
  std::vector<std::string_view> names;
  for (const auto& c : calls) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string_view>{"SELECT_PLANE", "SET_FEED_RATE", "STRAIGHT_FEED", "ARC_FEED",
                                                   "PROGRAM_END"}));
}

TEST(Listing, SplitsArgumentsAtCommasAndBlanks) {
  EXPECT_EQ(split_arguments("0 0.0000"), (std::vector<std::string_view>{"0", "0.0000"}));
  EXPECT_EQ(split_arguments("1.0000, -2.5000,CANON_XYZ"), (std::vector<std::string_view>{"1.0000", "-2.5000", "CANON_XYZ"}));
  EXPECT_TRUE(split_arguments("").empty());
}

TEST(Listing, ArgumentsMatchWithinTolerance) {
  EXPECT_TRUE(arguments_match("1.0000, 2.0000", "1.0000, 2.0000", 1e-4));
  EXPECT_TRUE(arguments_match("-0.0000", "0.0000", 1e-4));
  EXPECT_TRUE(arguments_match("1.0000, 2.0001", "1.0000, 2.0000", 1e-4));        // last-digit rounding
  EXPECT_TRUE(arguments_match("10000.0001", "10000.0000", 1e-4));               // binary slack
  std::size_t bad = 99;
  EXPECT_FALSE(arguments_match("1.0000, 2.0002", "1.0000, 2.0000", 1e-4, &bad));
  EXPECT_EQ(bad, 1u);
  EXPECT_FALSE(arguments_match("CANON_PLANE_XY", "CANON_PLANE_XZ", 1e-4, &bad));
  EXPECT_EQ(bad, 0u);
  EXPECT_FALSE(arguments_match("1, 2, 3", "1, 2", 1e-4, &bad));
  EXPECT_EQ(bad, 2u);
  EXPECT_FALSE(arguments_match("-1", "1", 1e-4));
}

// A random listing of motion calls with two numbers each, in rs274's number format.
std::string random_listing(std::mt19937_64& rng, int count, std::vector<double>& values) {
  static constexpr const char* kNames[] = {"STRAIGHT_FEED", "STRAIGHT_TRAVERSE", "SET_FEED_RATE", "DWELL"};
  std::uniform_real_distribution<double> value(-5000, 5000);
  std::uniform_int_distribution<int> pick(0, 3);
  std::string text;
  values.clear();
  for (int i = 0; i < count; ++i) {
    const double a = std::round(value(rng) * 1e4) / 1e4;
    const double b = std::round(value(rng) * 1e4) / 1e4;
    values.push_back(a);
    values.push_back(b);
    text += fmt::format("{:5d} N..... {}({:.4f}, {:.4f})\n", i + 1, kNames[pick(rng)], a, b);
  }
  return text;
}

// Seeded property test: a perturbation within the tolerance never fails a comparison; one beyond
// it always does, and the report names the perturbed call and both listing lines.
TEST(Listing, ComparisonFindsExactlyThePerturbedCall) {
  std::mt19937_64 rng(20260527);
  std::vector<double> values;
  for (int round = 0; round < 300; ++round) {
    const int count = 1 + static_cast<int>(rng() % 40);
    const std::string reference = random_listing(rng, count, values);
    const int call = static_cast<int>(rng() % count);
    const int arg = static_cast<int>(rng() % 2);
    std::vector<double> changed = values;
    const bool beyond = rng() % 2 == 0;
    // Within: at most one unit in the last printed digit. Beyond: at least two.
    const double delta = (beyond ? 2 + static_cast<int>(rng() % 50) : static_cast<int>(rng() % 2)) * 1e-4 *
                         ((rng() % 2) ? 1 : -1);
    changed[2 * call + arg] += delta;
    const auto ref_calls = parse_listing(reference);
    std::string text;
    for (int i = 0; i < count; ++i) {
      text += fmt::format("{:5d} N..... {}({:.4f}, {:.4f})\n", i + 1, ref_calls[i].name, changed[2 * i], changed[2 * i + 1]);
    }
    const auto actual = parse_listing(text);
    const auto cmp = compare_calls(ref_calls, actual, 1e-4, "rs274", "opencnc");
    EXPECT_EQ(cmp.equal, !beyond) << "round " << round << " delta " << delta << "\n" << cmp.report;
    if (beyond) {
      EXPECT_NE(cmp.report.find(fmt::format("call #{} ", call + 1)), std::string::npos) << cmp.report;
      EXPECT_NE(cmp.report.find(fmt::format("listing line {})", call + 1)), std::string::npos) << cmp.report;
      EXPECT_NE(cmp.report.find(fmt::format("first different argument: #{}", arg + 1)), std::string::npos) << cmp.report;
    }
  }
}

TEST(Listing, ComparisonReportsMissingAndExtraCalls) {
  const auto full = parse_listing("    1 N..... STRAIGHT_FEED(1.0000)\n    2 N..... PROGRAM_END()\n");
  const auto shorter = parse_listing("    1 N..... STRAIGHT_FEED(1.0000)\n");
  const auto a = compare_calls(full, shorter, 1e-4, "rs274", "opencnc");
  EXPECT_FALSE(a.equal);
  EXPECT_NE(a.report.find("opencnc stops after 1 motion calls; rs274 goes on with call #2"), std::string::npos) << a.report;
  EXPECT_NE(a.report.find("PROGRAM_END()"), std::string::npos) << a.report;
  const auto b = compare_calls(shorter, full, 1e-4, "rs274", "opencnc");
  EXPECT_FALSE(b.equal);
  EXPECT_NE(b.report.find("rs274 stops after 1 motion calls; opencnc goes on"), std::string::npos) << b.report;
  const auto renamed = parse_listing("    1 N..... STRAIGHT_TRAVERSE(1.0000)\n    2 N..... PROGRAM_END()\n");
  EXPECT_FALSE(compare_calls(full, renamed, 1e-4, "a", "b").equal);
  EXPECT_TRUE(compare_calls(full, full, 1e-4, "a", "b").equal);
}

TEST(Golden, ParsesHeaderAndListing) {
  const auto g = parse_golden(
      "# command: rs274 -g x.ngc\n# exit: 1\n# stderr: Cannot do g1 with zero feed rate\n# stderr: G1 X1\n# ---\n"
      "    1 N..... ON_RESET()\n");
  EXPECT_EQ(g.exit_status, 1);
  EXPECT_EQ(g.message(), "Cannot do g1 with zero feed rate");
  EXPECT_EQ(g.stderr_lines.size(), 2u);
  EXPECT_EQ(g.listing, "    1 N..... ON_RESET()\n");
  EXPECT_THROW(parse_golden("# exit: 0\nno separator\n"), std::runtime_error);
  EXPECT_THROW(parse_golden("# command: x\n# ---\n"), std::runtime_error);
}

TEST(Golden, ReadsXzCompressedFiles) {
  const std::string text = "# exit: 0\n# ---\n" + std::string(100000, 'x') + "\n";
  std::string packed(text.size() + 1024, '\0');
  std::size_t packed_size = 0;
  ASSERT_EQ(lzma_easy_buffer_encode(6, LZMA_CHECK_CRC64, nullptr, reinterpret_cast<const std::uint8_t*>(text.data()),
                                    text.size(), reinterpret_cast<std::uint8_t*>(packed.data()), &packed_size,
                                    packed.size()),
            LZMA_OK);
  const auto path = fs::temp_directory_path() / fmt::format("opencnc-golden-{}.golden.xz", ::getpid());
  std::ofstream(path, std::ios::binary).write(packed.data(), static_cast<std::streamsize>(packed_size));
  EXPECT_EQ(read_file(path), text);
  std::ofstream(path, std::ios::binary) << "not xz at all";
  EXPECT_THROW(read_file(path), std::runtime_error);
  fs::remove(path);
}

TEST(ErrorCodes, TableMapsMessagesToCodes) {
  const auto table = ErrorCodeTable::load(fs::path(OPENCNC_SOURCE_DIR) / "tests/conformance/error-codes.tsv");
  EXPECT_EQ(table.code_for("Cannot do g1 with zero feed rate"), "gcode.feed-zero");
  EXPECT_EQ(table.code_for("Bad character 'u' used"), "gcode.axis-not-available");
  EXPECT_EQ(table.code_for("Bad character '?' used"), "gcode.bad-character");
  EXPECT_EQ(table.code_for("Bad character '%' used"), "gcode.percent-misplaced");
  EXPECT_EQ(table.code_for("4: undefined O-word label: 'o1 break'"), "gcode.oword-unmatched");
  EXPECT_EQ(table.code_for("Arc radius too small to reach end point"), "gcode.arc-radius-too-small");
  EXPECT_EQ(table.code_for("Cannot do g1 with zero feed rate, really"), "");  // whole-line match only
  EXPECT_EQ(table.code_for("a message nobody wrote"), "");
  for (const auto& row : table.rows()) EXPECT_TRUE(is_problem_code(row.code)) << row.code;
}

TEST(ErrorCodes, CodeFormAndMentions) {
  EXPECT_TRUE(is_problem_code("gcode.feed-zero"));
  EXPECT_TRUE(is_problem_code("fanuc.goto-target-missing"));
  EXPECT_FALSE(is_problem_code("feed-zero"));
  EXPECT_FALSE(is_problem_code("gcode.Feed"));
  EXPECT_FALSE(is_problem_code("gcode.feed--zero"));
  EXPECT_TRUE(mentions_code("a.ngc:3:4: error: no feed rate [gcode.feed-zero]", "gcode.feed-zero"));
  EXPECT_TRUE(mentions_code("error (gcode.feed-zero).", "gcode.feed-zero"));
  EXPECT_FALSE(mentions_code("error [gcode.feed-zero-x]", "gcode.feed-zero"));
  EXPECT_FALSE(mentions_code("error [xgcode.feed-zero]", "gcode.feed-zero"));
  EXPECT_FALSE(mentions_code("error [gcode.feed-zero.more]", "gcode.feed-zero"));
}

TEST(Process, CapturesOutputExitStatusAndFolder) {
  const auto r = run_process({"sh", "-c", "pwd; echo oops >&2; exit 3"}, "/tmp", 10);
  EXPECT_EQ(r.exit_status, 3);
  EXPECT_EQ(r.out, "/tmp\n");
  EXPECT_EQ(r.err, "oops\n");
  EXPECT_FALSE(r.timed_out);
}

TEST(Process, DrainsLargeOutputOnBothStreams) {
  const auto r = run_process({"sh", "-c", "head -c 3000000 /dev/zero; head -c 2000000 /dev/zero >&2"}, "/", 30);
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(r.out.size(), 3000000u);
  EXPECT_EQ(r.err.size(), 2000000u);
}

TEST(Process, EnvironmentChangesReachTheChild) {
  const auto r = run_process({"sh", "-c", "echo $HOME:$OPENCNC_TEST_VAR"}, "/", 10, {"HOME=/x/y", "OPENCNC_TEST_VAR=1"});
  EXPECT_EQ(r.out, "/x/y:1\n");
  ::setenv("OPENCNC_TEST_KEPT", "kept", 1);
  EXPECT_EQ(run_process({"sh", "-c", "echo $OPENCNC_TEST_KEPT"}, "/", 10, {"HOME=/x"}).out, "kept\n");
}

TEST(Process, StandardInputIsEmptyAndTimeoutsKill) {
  EXPECT_EQ(run_process({"cat"}, "/", 10).out, "");  // rs274 reads stdin after the program
  const auto r = run_process({"sleep", "20"}, "/", 0.2);
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.exit_status, 128 + 9);
  EXPECT_EQ(run_process({"/no/such/program"}, "/", 10).exit_status, 127);
}

Case sample_case() {
  Case c;
  c.name = "own_subfiles_x";
  c.set = "own";
  c.program = "subfiles/x.ngc";
  c.dialect = "linuxcnc";
  c.tool_table = "@conf/tools/standard.tbl";
  c.subpath = "lib:../lib";
  c.args = "-";
  c.golden = "own/subfiles/x.golden";
  return c;
}

TEST(Runner, OpencncCommandLine) {
  const Roots roots{"/src/tests/conformance", "/nc", "/corpus"};
  auto c = sample_case();
  const auto inv = opencnc_invocation(c, roots, "/b/opencnc", "canon");
  EXPECT_EQ(inv.cwd, fs::path("/src/tests/conformance/programs/subfiles"));
  EXPECT_EQ(inv.argv, (std::vector<std::string>{"/b/opencnc", "canon", "x.ngc", "--tool-table",
                                                "/src/tests/conformance/tools/standard.tbl", "--subroutine-path",
                                                "/src/tests/conformance/programs/subfiles", "--subroutine-path",
                                                "/src/tests/conformance/programs/subfiles/lib", "--subroutine-path",
                                                "/src/tests/conformance/programs/lib"}));
  c.dialect = "fanuc";
  c.tool_table = "-";
  c.subpath = "-";
  c.args = "--axis-map X=Y,Y=X";
  EXPECT_EQ(opencnc_invocation(c, roots, "opencnc", "check").argv,
            (std::vector<std::string>{"opencnc", "check", "x.ngc", "--dialect", "fanuc", "--subroutine-path",
                                      "/src/tests/conformance/programs/subfiles", "--axis-map", "X=Y,Y=X"}));
}

TEST(Runner, Rs274CommandLineAndTwins) {
  const Roots roots{"/src/tests/conformance", "/nc", "/corpus"};
  const auto scratch = fs::temp_directory_path();
  auto c = sample_case();
  const auto inv = rs274_invocation(c, roots, "rs274", scratch);
  ASSERT_EQ(inv.argv.size(), 7u);
  EXPECT_EQ(inv.argv[1], "-t");
  EXPECT_EQ(inv.argv[3], "-i");
  std::ifstream ini(inv.argv[4]);
  std::string text((std::istreambuf_iterator<char>(ini)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "[RS274NGC]\nSUBROUTINE_PATH = lib:../lib\n");
  fs::remove(inv.argv[4]);
  EXPECT_EQ(inv.argv[6], "x.ngc");
  EXPECT_EQ(inv.env, (std::vector<std::string>{"HOME=" + scratch.string()}));
  c.dialect = "fanuc";
  c.program = "fanuc/m98.nc";
  const auto twin = rs274_invocation(c, roots, "rs274", scratch);
  EXPECT_EQ(twin.cwd, fs::path("/src/tests/conformance/twins/fanuc"));
  EXPECT_EQ(twin.argv.back(), "m98.ngc");
  EXPECT_TRUE(rs274_can_run(c));
  c.set = "corpus";
  c.program = "fanuc-style.nc";
  EXPECT_EQ(rs274_invocation(c, roots, "rs274", scratch).argv.back(), "fanuc-style.nc");  // no twin
  EXPECT_TRUE(rs274_can_run(c));
  c.golden = "-";
  EXPECT_FALSE(rs274_can_run(c));
}

TEST(Runner, Rs274ErrorLinesAreNormalised) {
  const Roots roots{fs::path(OPENCNC_SOURCE_DIR) / "tests/conformance", "/nc", "/corpus"};
  const auto programs = fs::canonical(roots.conf / "programs").string();
  const auto lines = rs274_error_lines("executing\nEOF in file:" + programs + "/lib/a.ngc seeking\n\n", roots);
  EXPECT_EQ(lines, (std::vector<std::string>{"EOF in file:@programs/lib/a.ngc seeking", ""}));
}

}  // namespace
