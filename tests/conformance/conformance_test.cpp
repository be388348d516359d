// SPDX-License-Identifier: GPL-3.0-or-later
// The conformance harness: every program of cases.tsv through opencnc, compared with rs274.
//
// Environment:
//   OPENCNC_CONFORMANCE_IUT=rs274   use rs274 as the implementation under test (validates the harness)
//   OPENCNC_CONFORMANCE_LIVE=0      do not run rs274 live even when it is on PATH
//   OPENCNC_CONFORMANCE_BINARY      the opencnc binary (default: the one this build made)
//   OPENCNC_NCFILES, OPENCNC_CORPUS the external program folders
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "harness/cases.hpp"
#include "harness/golden.hpp"
#include "harness/listing.hpp"
#include "harness/process.hpp"
#include "harness/runner.hpp"

namespace fs = std::filesystem;
using namespace opencnc::conformance;

namespace opencnc::conformance {
// Names the case in gtest's messages instead of dumping its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }
}  // namespace opencnc::conformance

namespace {

constexpr double kTolerance = 1e-4;
constexpr double kOpencncTimeout_s = 120;  // the largest corpus program under ASan, with margin
constexpr double kRs274Timeout_s = 60;

// --- the suite, loaded once per process ------------------------------------------------------

// A scratch folder for rs274's INI files, removed when the process ends.
struct Scratch {
  fs::path dir;
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "opencnc-conformance-XXXXXX").string();
    if (::mkdtemp(pattern.data()) != nullptr) dir = pattern;
  }
  ~Scratch() {
    std::error_code ec;
    if (!dir.empty()) fs::remove_all(dir, ec);
  }
};

struct Suite {
  Roots roots = roots_from_environment(OPENCNC_SOURCE_DIR, OPENCNC_SHARED_DIR);
  std::vector<Case> cases;
  std::string load_error;
  Scratch scratch;

  Suite() {
    try {
      cases = load_cases(roots.conf / "cases.tsv");
    } catch (const std::exception& e) {
      load_error = e.what();
    }
  }
  const ErrorCodeTable& codes() const {
    static const ErrorCodeTable table = ErrorCodeTable::load(roots.conf / "error-codes.tsv");
    return table;
  }
};

const Suite& suite() {
  static const Suite s;
  return s;
}

std::vector<Case> cases_of(const std::string& set) {
  std::vector<Case> out;
  for (const auto& c : suite().cases) {
    if (c.set == set && c.expect != Expect::Excluded) out.push_back(c);
  }
  return out;
}

// --- the implementation under test and the oracle ------------------------------------------

bool iut_is_rs274() {
  const char* v = std::getenv("OPENCNC_CONFORMANCE_IUT");
  return v != nullptr && std::string_view(v) == "rs274";
}

fs::path rs274_binary() {
  static const fs::path p = find_on_path("rs274");
  return p;
}

// rs274 runs live (to flag stale goldens and to be the reference) when it is installed.
bool live_rs274() {
  const char* v = std::getenv("OPENCNC_CONFORMANCE_LIVE");
  return !rs274_binary().empty() && !(v != nullptr && std::string_view(v) == "0");
}

fs::path opencnc_binary() {
  const char* v = std::getenv("OPENCNC_CONFORMANCE_BINARY");
  return v != nullptr && *v != '\0' ? fs::path(v) : fs::path(OPENCNC_BINARY);
}

// What the opencnc binary offers, from its --help texts.
struct Capabilities {
  std::string canon_help;
  std::string check_help;
  bool canon = false;
  bool check = false;
};

// `opencnc SUB --help`, and whether SUB exists: CLI11 answers `opencnc nosuch --help` with the
// top-level help, so the subcommand must appear as a word of the "Usage:" line.
std::string subcommand_help(const char* sub, bool& present) {
  const auto r = run_process({opencnc_binary().string(), sub, "--help"}, fs::current_path(), 30);
  present = false;
  std::istringstream lines(r.out);
  for (std::string line; r.exit_status == 0 && std::getline(lines, line);) {
    if (line.rfind("Usage:", 0) != 0) continue;
    std::istringstream words(line);
    for (std::string w; words >> w;) present = present || w == sub;
    break;
  }
  return r.out;
}

const Capabilities& capabilities() {
  static const Capabilities caps = [] {
    Capabilities c;
    c.canon_help = subcommand_help("canon", c.canon);
    c.check_help = subcommand_help("check", c.check);
    return c;
  }();
  return caps;
}

// Why opencnc cannot be asked about this case yet, if it cannot: a missing subcommand, or an
// option of the case's command line that the subcommand's --help does not mention.
std::optional<std::string> opencnc_missing(const Case& c, const char* subcommand) {
  const auto& caps = capabilities();
  const bool check = std::string_view(subcommand) == "check";
  if (!caps.canon) {
    return fmt::format("{} has no `canon` subcommand yet (the interpreter is not merged); "
                       "OPENCNC_CONFORMANCE_IUT=rs274 runs the harness against rs274 instead",
                       opencnc_binary().string());
  }
  if (check && !caps.check) return std::string("opencnc has no `check` subcommand yet");
  const std::string& help = check ? caps.check_help : caps.canon_help;
  for (const auto& arg : opencnc_invocation(c, suite().roots, opencnc_binary(), subcommand).argv) {
    if (arg.rfind("--", 0) == 0 && help.find(arg) == std::string::npos) {
      return fmt::format("opencnc {} has no {} option yet", subcommand, arg);
    }
  }
  return std::nullopt;
}

std::optional<std::string> missing_root(const Case& c) {
  const auto& roots = suite().roots;
  if (c.set == "ncfiles" && !fs::is_directory(roots.ncfiles)) {
    return fmt::format("LinuxCNC's sample programs are not installed at {} (set OPENCNC_NCFILES)", roots.ncfiles.string());
  }
  if (c.set == "corpus" && !fs::is_directory(roots.corpus)) {
    return fmt::format("the real-world corpus is not at {} (set OPENCNC_CORPUS)", roots.corpus.string());
  }
  if (!fs::exists(roots.program(c))) return "program not found: " + roots.program(c).string();
  for (const auto& dir : search_path(c, roots, roots.program(c).parent_path())) {
    if (!fs::is_directory(dir)) return "subprogram folder not found: " + dir.string();
  }
  return std::nullopt;
}

std::string command_text(const Invocation& inv) {
  std::string s;
  for (const auto& a : inv.argv) s += (s.empty() ? "" : " ") + a;
  return fmt::format("(cd {} && {})", inv.cwd.string(), s);
}

ProcessResult run(const Invocation& inv, double timeout_s) {
  auto r = run_process(inv.argv, inv.cwd, timeout_s, inv.env);
  if (!r.error.empty()) ADD_FAILURE() << "cannot run " << command_text(inv) << ": " << r.error;
  if (r.timed_out) ADD_FAILURE() << "timed out after " << timeout_s << " s: " << command_text(inv);
  return r;
}

ProcessResult run_rs274(const Case& c) {
  return run(rs274_invocation(c, suite().roots, rs274_binary(), suite().scratch.dir), kRs274Timeout_s);
}

Golden golden_of(const Case& c) { return load_golden(suite().roots.conf / "golden" / c.golden); }

// Compares live rs274 with the golden file; a difference means the golden is stale.
void expect_fresh(const Case& c, const Golden& g, const ProcessResult& live) {
  const auto live_err = rs274_error_lines(live.err, suite().roots);
  const char* regen = "regenerate with tests/conformance/regen-golden.sh";
  EXPECT_EQ(live.exit_status, g.exit_status) << "stale golden " << c.golden << ": rs274 exit status changed; " << regen;
  EXPECT_EQ(live_err, g.stderr_lines) << "stale golden " << c.golden << ": rs274's messages changed; " << regen;
  if (live.out != g.listing) {
    const auto a = parse_listing(g.listing);
    const auto b = parse_listing(live.out);
    const auto cmp = compare_calls(a, b, 0.0, "golden", "rs274");
    ADD_FAILURE() << "stale golden " << c.golden << " (" << regen << "):\n"
                  << (cmp.equal ? std::string("the listings differ outside the canonical calls (PRINT output)\n")
                                : cmp.report);
  }
}

// What rs274 did with a case: the golden file, and the live run when rs274 is installed.
struct Reference {
  Golden golden;
  std::optional<ProcessResult> live;

  // The listing opencnc must match (live rs274's when it ran: it is the oracle) and its name.
  const std::string& listing() const { return live ? live->out : golden.listing; }
  const char* source() const { return live ? "rs274" : "rs274 (golden)"; }
};

// Loads the golden file of `c` and, with rs274 installed, runs it live and flags a stale golden.
std::optional<Reference> reference_of(const Case& c) {
  if (c.golden == "-") return std::nullopt;
  Reference ref{golden_of(c), std::nullopt};
  if (live_rs274() && rs274_can_run(c)) {
    ref.live = run_rs274(c);
    expect_fresh(c, ref.golden, *ref.live);
  }
  return ref;
}

// The expected problem code of a rejected case: given in cases.tsv, or mapped from rs274's message.
std::string expected_code(const Case& c, const std::optional<Reference>& ref) {
  if (c.code != "-") return c.code;
  return ref ? suite().codes().code_for(ref->golden.message()) : std::string{};
}

// The error lines an implementation printed (stdout and stderr).
std::vector<std::string> error_lines(const ProcessResult& r) {
  std::vector<std::string> lines;
  for (const std::string* stream : {&r.err, &r.out}) {
    std::istringstream in(*stream);
    for (std::string line; std::getline(in, line);) {
      if (line.find("error") != std::string::npos) lines.push_back(line);
    }
  }
  return lines;
}

// What rs274 as the implementation under test "reports": its message mapped through the table.
ProcessResult rs274_as_checker(const Case& c) {
  auto r = run_rs274(c);
  if (r.exit_status != 0) {
    const auto lines = rs274_error_lines(r.err, suite().roots);
    const std::string message = lines.empty() ? std::string{} : lines.front();
    std::string text;
    for (const auto& l : lines) text += " | " + l;
    r.err = fmt::format("{}: error: {}{} [{}]\n", c.program, message, text, suite().codes().code_for(message));
  }
  return r;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += "  " + l + "\n";
  return s.empty() ? "  (none)\n" : s;
}

// --- the checks for each kind of case ---------------------------------------------------------

void check_accepted(const Case& c, const Reference& ref) {
  const auto inv = iut_is_rs274() ? rs274_invocation(c, suite().roots, rs274_binary(), suite().scratch.dir)
                                  : opencnc_invocation(c, suite().roots, opencnc_binary(), "canon");
  const auto r = run(inv, iut_is_rs274() ? kRs274Timeout_s : kOpencncTimeout_s);
  const std::string who = iut_is_rs274() ? "rs274 under test" : "opencnc";
  EXPECT_EQ(r.exit_status, 0) << who << " rejected the program: " << command_text(inv) << "\n" << r.err;
  const auto expected_calls = parse_listing(ref.listing());
  const auto actual_calls = parse_listing(r.out);
  const auto cmp = compare_calls(motion_subset(expected_calls), motion_subset(actual_calls), kTolerance, ref.source(), who);
  EXPECT_TRUE(cmp.equal) << c.program << " (" << c.note << ")\n" << cmp.report << "command: " << command_text(inv);
}

void check_rejected(const Case& c, const std::string& code, const std::string& construct) {
  ASSERT_FALSE(code.empty()) << "no problem code for " << c.name << ": add a row to error-codes.tsv";
  const auto inv = opencnc_invocation(c, suite().roots, opencnc_binary(), "check");
  const auto r = iut_is_rs274() ? rs274_as_checker(c) : run(inv, kOpencncTimeout_s);
  const auto errors = error_lines(r);
  EXPECT_EQ(r.exit_status, 1) << "the program must be rejected (exit 1): " << command_text(inv) << "\n" << r.err;
  const bool has_code = std::any_of(errors.begin(), errors.end(), [&](const auto& l) { return mentions_code(l, code); });
  EXPECT_TRUE(has_code) << c.program << ": expected an error with code " << code << "; error lines:\n" << joined(errors);
  if (!construct.empty()) {
    const bool named = std::any_of(errors.begin(), errors.end(),
                                   [&](const auto& l) { return l.find(construct) != std::string::npos; });
    EXPECT_TRUE(named) << c.program << ": the error must name the construct '" << construct << "'; error lines:\n"
                       << joined(errors);
  }
}

void check_runs_in_fanuc_dialect(const Case& c) {
  const auto inv = opencnc_invocation(c, suite().roots, opencnc_binary(), "canon");
  const auto r = run(inv, kOpencncTimeout_s);
  ASSERT_EQ(r.exit_status, 0) << "must run in the Fanuc dialect: " << command_text(inv) << "\n" << r.err;
  const auto calls = motion_subset(parse_listing(r.out));
  const auto feeds = std::count_if(calls.begin(), calls.end(), [](const CanonCall& k) {
    return k.name == "STRAIGHT_FEED" || k.name == "ARC_FEED";
  });
  EXPECT_GT(feeds, 0) << "no feed moves in the output of " << command_text(inv);
  EXPECT_TRUE(!calls.empty() && calls.back().name == "PROGRAM_END") << "the output does not end with PROGRAM_END";
}

class Conformance : public testing::TestWithParam<Case> {};

TEST_P(Conformance, Program) {
  const Case& c = GetParam();
  if (auto why = missing_root(c)) GTEST_SKIP() << *why;
  // Checked first, so that stale goldens show even before the interpreter lands.
  const auto ref = reference_of(c);
  const bool needs_check = c.expect == Expect::Reject || c.expect == Expect::Unsupported;
  const char* subcommand = needs_check ? "check" : "canon";
  if (iut_is_rs274()) {
    if (c.dialect != "linuxcnc") GTEST_SKIP() << "rs274 has no Fanuc dialect";
    if (c.expect == Expect::Unsupported && c.code.rfind("dialect.", 0) == 0) {
      GTEST_SKIP() << "rs274 does not recognise other controllers' syntax (" << c.code << ")";
    }
  } else if (auto why = opencnc_missing(c, subcommand)) {
    GTEST_SKIP() << *why;
  }
  switch (c.expect) {
    case Expect::Accept:
      ASSERT_TRUE(ref) << "accepted case without a golden file";
      check_accepted(c, *ref);
      break;
    case Expect::Reject: check_rejected(c, expected_code(c, ref), ""); break;
    case Expect::Unsupported: check_rejected(c, c.code, c.construct); break;
    case Expect::Run: check_runs_in_fanuc_dialect(c); break;
    case Expect::Excluded: break;
  }
}

std::string param_name(const testing::TestParamInfo<Case>& info) {
  const std::string& n = info.param.name;
  const std::string prefix = info.param.set + "_";
  return n.rfind(prefix, 0) == 0 ? n.substr(prefix.size()) : n;
}

INSTANTIATE_TEST_SUITE_P(Own, Conformance, testing::ValuesIn(cases_of("own")), param_name);
INSTANTIATE_TEST_SUITE_P(Ncfiles, Conformance, testing::ValuesIn(cases_of("ncfiles")), param_name);
INSTANTIATE_TEST_SUITE_P(Corpus, Conformance, testing::ValuesIn(cases_of("corpus")), param_name);

}  // namespace

// --- the suite's own data ------------------------------------------------------------------------

namespace {

std::set<std::string> documented_codes() {
  std::ifstream in(fs::path(OPENCNC_SOURCE_DIR) / "docs" / "error-codes.md");
  std::set<std::string> codes;
  for (std::string line; std::getline(in, line);) {
    // Table rows start with "| `code` |".
    if (line.rfind("| `", 0) == 0) codes.insert(line.substr(3, line.find('`', 3) - 3));
  }
  return codes;
}

TEST(ConformanceData, CasesLoadWithUniqueNamesAndValidCodes) {
  ASSERT_EQ(suite().load_error, "");
  ASSERT_FALSE(suite().cases.empty());
  std::set<std::string> names;
  for (const auto& c : suite().cases) {
    EXPECT_TRUE(names.insert(c.name).second) << "duplicate case name " << c.name;
    if (c.code != "-") {
      EXPECT_TRUE(is_problem_code(c.code)) << c.name << ": bad code " << c.code;
    }
  }
}

TEST(ConformanceData, OwnSuiteHasAtLeast150Programs) {
  EXPECT_GE(cases_of("own").size(), 150u);
}

TEST(ConformanceData, EveryGoldenMatchesItsCase) {
  for (const auto& c : suite().cases) {
    if (c.golden == "-") {
      EXPECT_TRUE(c.expect == Expect::Excluded || (c.expect == Expect::Reject && c.code != "-"))
          << c.name << " has neither a golden file nor an explicit code";
      continue;
    }
    Golden g;
    ASSERT_NO_THROW(g = golden_of(c)) << c.name;
    if (c.expect == Expect::Accept) {
      EXPECT_EQ(g.exit_status, 0) << c.golden;
      EXPECT_FALSE(motion_subset(parse_listing(g.listing)).empty()) << c.golden << " has no motion calls";
    } else {
      EXPECT_NE(g.exit_status, 0) << c.golden;
      EXPECT_FALSE(g.message().empty()) << c.golden << " has no error message";
    }
    if (c.expect == Expect::Reject) {
      EXPECT_NE(expected_code(c, Reference{g, std::nullopt}), "")
          << c.golden << ": no error-codes.tsv row matches: " << g.message();
    }
  }
}

// cases.tsv carries corpus-dialects.tsv's classes (regen-golden.sh copies them); they must agree.
TEST(ConformanceData, CorpusCasesFollowTheirDialectClass) {
  std::map<std::string, const Case*> corpus;
  for (const auto& c : suite().cases) {
    if (c.set == "corpus") corpus[c.program] = &c;
  }
  std::ifstream in(suite().roots.conf / "corpus-dialects.tsv");
  int rows = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto f = split_tabs(line);
    ASSERT_EQ(f.size(), 5u) << line;
    ++rows;
    const auto it = corpus.find(f[0]);
    ASSERT_NE(it, corpus.end()) << f[0] << " is classified but has no case";
    const Case& c = *it->second;
    if (f[1] == "fanuc") {
      EXPECT_TRUE(c.expect == Expect::Run && c.dialect == "fanuc") << c.name;
    } else if (f[1] == "unsupported") {
      EXPECT_TRUE(c.expect == Expect::Unsupported && c.code == f[3] && c.construct == f[2]) << c.name;
    } else {
      EXPECT_EQ(f[1], "error") << line;
      EXPECT_TRUE(c.expect == Expect::Reject && c.dialect == "linuxcnc") << c.name;
    }
  }
  const auto rejected = std::count_if(corpus.begin(), corpus.end(), [](const auto& kv) {
    return kv.second->expect != Expect::Accept;
  });
  EXPECT_EQ(rows, rejected) << "every corpus program rs274 rejects needs a class in corpus-dialects.tsv";
}

TEST(ConformanceData, EveryItemHasProgramsAndErrorCases) {
  const auto items = load_items(suite().roots.conf / "items.tsv");
  std::map<std::string, std::pair<int, int>> uses;  // item -> (accepted programs, rejected programs)
  for (const auto& c : cases_of("own")) {
    const auto program = suite().roots.program(c);
    const auto named = program_items(program);
    EXPECT_FALSE(named.empty()) << c.program << " names no items";
    for (const auto& item : named) {
      auto& u = uses[item];
      (c.expect == Expect::Accept ? u.first : u.second)++;
    }
  }
  std::set<std::string> known;
  for (const auto& item : items) {
    known.insert(item.id);
    EXPECT_GT(uses[item.id].first, 0) << "no accepted program exercises " << item.id << " (" << item.description << ")";
    if (item.needs_error_case) {
      EXPECT_GT(uses[item.id].second, 0) << "no rejected program for " << item.id << " (" << item.description << ")";
    }
  }
  for (const auto& [item, count] : uses) EXPECT_TRUE(known.count(item)) << "item not in items.tsv: " << item;
}

TEST(ConformanceData, OwnProgramsOpenWithAComment) {
  for (const auto& c : cases_of("own")) {
    std::ifstream in(suite().roots.program(c));
    std::string first;
    std::getline(in, first);
    if (first.rfind('%', 0) == 0) std::getline(in, first);  // a percent line must come first
    EXPECT_TRUE(!first.empty() && (first[0] == ';' || first[0] == '(')) << c.program << " does not open with a comment";
  }
}

TEST(ConformanceData, EveryCodeIsDocumented) {
  const auto documented = documented_codes();
  ASSERT_FALSE(documented.empty()) << "docs/error-codes.md has no code table";
  for (const auto& row : suite().codes().rows()) {
    EXPECT_TRUE(documented.count(row.code)) << row.code << " is missing from docs/error-codes.md";
  }
  for (const auto& c : suite().cases) {
    if (c.code != "-") {
      EXPECT_TRUE(documented.count(c.code)) << c.code << " is missing from docs/error-codes.md";
    }
  }
}

}  // namespace
