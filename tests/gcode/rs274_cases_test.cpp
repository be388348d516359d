// SPDX-License-Identifier: GPL-3.0-or-later
// The programs in tests/gcode/cases/ against the output LinuxCNC's rs274 printed for them
// (NAME.rs274, made by cases/regen.py): every line must match, and rejected programs must
// fail with the problem code the case names, on the line rs274 stopped at.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "gcode_test_util.hpp"
#include "opencnc/gcode/rs274_driver.hpp"

namespace fs = std::filesystem;
using namespace opencnc;
using namespace opencnc::gcode;

namespace {

const fs::path kCases = OPENCNC_GCODE_CASES_DIR;

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Lines without the driver's trailing resets: rs274 prints one or two depending on whether
// it was given an INI file (regen.py gives one only to cases that need a subroutine path).
std::vector<std::string> lines_without_final_resets(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  while (!out.empty() && out.back().ends_with("ON_RESET()")) out.pop_back();
  return out;
}

struct Case {
  std::string name;
  bool tools = false;
  std::string subroutine_path;
  std::string error;   // expected problem code, empty for success
};

Case read_case(const fs::path& ngc) {
  Case c;
  c.name = ngc.stem().string();
  static const std::regex directive(R"(^;\s*opencnc-test:\s*(.*)$)");
  std::ifstream in(ngc);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, directive)) continue;
    std::istringstream items(m[1].str());
    for (std::string item; items >> item;) {
      if (item == "tools") c.tools = true;
      else if (item.starts_with("subroutine-path=")) c.subroutine_path = item.substr(16);
      else if (item.starts_with("error=")) c.error = item.substr(6);
    }
  }
  return c;
}

std::vector<fs::path> case_files() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(kCases)) {
    if (e.path().extension() == ".ngc") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

TEST(Rs274Cases, EveryCaseMatchesRs274) {
  const auto files = case_files();
  ASSERT_GE(files.size(), 20u);
  Diagnostics table_diags;
  auto table = tools::ToolTable::load((kCases / "tools.tbl").string(), table_diags);
  ASSERT_TRUE(table.has_value());
  const auto tools = std::make_shared<tools::ToolTable>(std::move(*table));
  for (const fs::path& ngc : files) {
    SCOPED_TRACE(ngc.filename().string());
    const Case c = read_case(ngc);
    Options options;
    if (c.tools) options.tool_table = tools;
    options.subroutine_path = {(kCases / (c.subroutine_path.empty() ? "." : c.subroutine_path)).string()};
    Interpreter interp(options);
    ASSERT_TRUE(interp.open(ngc.string()));
    test::MemoryStream out;
    RunStatus status;
    {
      canon::Rs274Printer printer(out.file(), out.file());
      status = run_like_rs274(interp, printer);
    }
    const auto got = lines_without_final_resets(out.text());
    const auto want = lines_without_final_resets(read_file(kCases / (c.name + ".rs274")));
    EXPECT_EQ(got, want);
    if (c.error.empty()) {
      EXPECT_EQ(status, RunStatus::Finished);
      EXPECT_FALSE(interp.diagnostics().has_errors());
    } else {
      EXPECT_EQ(status, RunStatus::Error);
      std::string got_code;
      for (const auto& d : interp.diagnostics().items()) {
        if (d.severity == Severity::Error && got_code.empty()) got_code = d.code;
      }
      EXPECT_EQ(got_code, c.error);
    }
  }
}
