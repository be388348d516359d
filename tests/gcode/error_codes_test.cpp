// SPDX-License-Identifier: GPL-3.0-or-later
// The problem-code vocabulary: well-formed unique ids, each documented in docs/error-codes.md,
// and every code the conformance table maps rs274's messages to either raised by the core or
// left to a feature module.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <string_view>

#include "opencnc/gcode/error_codes.hpp"

namespace fs = std::filesystem;
using namespace opencnc::gcode;

namespace {

const fs::path kSource = OPENCNC_SOURCE_DIR;

std::set<std::string> core_ids() {
  std::set<std::string> ids;
  for (ErrorCode c : kAllErrorCodes) ids.emplace(error_id(c));
  return ids;
}

// Codes in the tables of docs/error-codes.md (rows start with "| `code` |").
std::set<std::string> documented_ids() {
  std::ifstream in(kSource / "docs" / "error-codes.md");
  std::set<std::string> ids;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| `", 0) == 0) ids.insert(line.substr(3, line.find('`', 3) - 3));
  }
  return ids;
}

// The codes column of tests/conformance/error-codes.tsv.
std::set<std::string> mapped_ids() {
  std::ifstream in(kSource / "tests" / "conformance" / "error-codes.tsv");
  std::set<std::string> ids;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t a = line.find('\t');
    const std::size_t b = line.find('\t', a + 1);
    if (a != std::string::npos && b != std::string::npos) ids.insert(line.substr(a + 1, b - a - 1));
  }
  return ids;
}

// Feature modules own the codes of their area until they raise them from the core's enum.
bool feature_code(std::string_view id) {
  constexpr std::array<std::string_view, 6> kAreas = {"gcode.comp-",   "gcode.cycle-",
                                                      "gcode.thread-", "gcode.probe-",
                                                      "gcode.lathe-",  "gcode.spindle-stopped"};
  for (std::string_view area : kAreas) {
    if (id.substr(0, area.size()) == area) return true;
  }
  return false;
}

}  // namespace

TEST(ErrorCodeIds, AreUniqueAndWellFormed) {
  static const std::regex form("[a-z]+(\\.[a-z0-9]+(-[a-z0-9]+)*)+");
  std::set<std::string_view> seen;
  for (ErrorCode c : kAllErrorCodes) {
    const std::string_view id = error_id(c);
    EXPECT_TRUE(std::regex_match(id.begin(), id.end(), form)) << id;
    EXPECT_TRUE(seen.insert(id).second) << "two errors share the id " << id;
  }
  EXPECT_EQ(seen.size(), std::size(kAllErrorCodes));
}

TEST(ErrorCodeIds, EveryCoreCodeIsDocumented) {
  const auto documented = documented_ids();
  ASSERT_FALSE(documented.empty()) << "docs/error-codes.md has no code table";
  for (const auto& id : core_ids())
    EXPECT_TRUE(documented.count(id)) << id << " is missing from docs/error-codes.md";
}

TEST(ErrorCodeIds, DocumentedCodesAreRaisedOrMapped) {
  const auto core = core_ids();
  const auto mapped = mapped_ids();
  for (const auto& id : documented_ids()) {
    if (id.rfind("gcode.", 0) != 0) continue;  // fanuc.* and dialect.* have no rs274 message
    EXPECT_TRUE(core.count(id) || mapped.count(id)) << id << " is documented but neither raised nor mapped";
  }
}

TEST(ErrorCodeIds, TheConformanceTableMapsOnlyKnownCodes) {
  const auto core = core_ids();
  const auto mapped = mapped_ids();
  ASSERT_GT(mapped.size(), 50u);
  for (const auto& id : mapped) {
    EXPECT_TRUE(core.count(id) || feature_code(id))
        << id << " is mapped in error-codes.tsv but the interpreter has no such code";
  }
}
