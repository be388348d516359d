// SPDX-License-Identifier: GPL-3.0-or-later
// Tool tables: LinuxCNC .tbl parsing with precise errors, lookup by tool number.
#include <gtest/gtest.h>

#include <random>

#include "opencnc/tools/tool_table.hpp"

using namespace opencnc;
using opencnc::tools::ToolEntry;
using opencnc::tools::ToolTable;

TEST(ToolTable, ParsesEveryWordAndTheComment) {
  Diagnostics d;
  const ToolTable t = ToolTable::parse(
      "T5 P3 X0.5 Y-1 Z1.25 A2 B3 C4 U5 V6 W7 D0.25 I10 J20 Q3 ;five flute\n"
      "t7 p1 z-2\n", "t.tbl", d);
  ASSERT_TRUE(d.empty()) << d.items().front().format();
  ASSERT_EQ(t.size(), 2u);
  const ToolEntry& e = t.at_index(1);
  EXPECT_EQ(e.tool, 5);
  EXPECT_EQ(e.pocket, 3);
  EXPECT_DOUBLE_EQ(e.offset[Axis::X], 0.5);
  EXPECT_DOUBLE_EQ(e.offset[Axis::Y], -1);
  EXPECT_DOUBLE_EQ(e.offset[Axis::Z], 1.25);
  EXPECT_DOUBLE_EQ(e.offset[Axis::W], 7);
  EXPECT_DOUBLE_EQ(e.diameter, 0.25);
  EXPECT_DOUBLE_EQ(e.front_angle, 10);
  EXPECT_DOUBLE_EQ(e.back_angle, 20);
  EXPECT_EQ(e.orientation, 3);
  EXPECT_EQ(e.comment, "five flute");
  EXPECT_EQ(t.find(7), 2u);
  EXPECT_EQ(t.find(5), 1u);
  EXPECT_FALSE(t.find(6).has_value());
  EXPECT_DOUBLE_EQ(t.tool(7)->offset[Axis::Z], -2);
}

TEST(ToolTable, ReportsBadLinesWithPositionAndCodeAndKeepsTheRest) {
  Diagnostics d;
  const ToolTable t = ToolTable::parse("T1 P1 Z1\nT2 P2 Zabc\nP3 Z1\nT1 P4\nT4 K3\nT5 Q12\n\n; only a comment\n", "x.tbl", d);
  ASSERT_EQ(d.error_count(), 5u);
  EXPECT_EQ(d.items()[0].code, "tools.bad-number");
  EXPECT_EQ(d.items()[0].line, 2u);
  EXPECT_EQ(d.items()[0].col, 7u);
  EXPECT_EQ(d.items()[1].code, "tools.missing-tool");
  EXPECT_EQ(d.items()[2].code, "tools.duplicate-tool");
  EXPECT_EQ(d.items()[3].code, "tools.unknown-word");
  EXPECT_EQ(d.items()[4].code, "tools.bad-orientation");
  EXPECT_EQ(d.items()[0].format(), "x.tbl:2:7: error: Z needs a number, found 'abc'");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t.at_index(1).tool, 1);
}

TEST(ToolTable, MissingFileIsAnError) {
  Diagnostics d;
  EXPECT_FALSE(ToolTable::load("/nonexistent/tools.tbl", d).has_value());
  ASSERT_EQ(d.error_count(), 1u);
  EXPECT_EQ(d.items()[0].code, "tools.cannot-open");
  EXPECT_EQ(d.items()[0].message, "cannot read the tool table: No such file or directory");
}

TEST(ToolTable, AFolderIsNotAnEmptyTable) {
  Diagnostics d;
  EXPECT_FALSE(ToolTable::load("/", d).has_value());
  ASSERT_EQ(d.error_count(), 1u);
  EXPECT_EQ(d.items()[0].message, "cannot read the tool table: it is a folder, not a file");
}

TEST(ToolTable, LookupAgreesWithLinearSearchOnRandomTables) {
  std::mt19937 rng(12345);
  for (int round = 0; round < 200; ++round) {
    ToolTable t;
    std::vector<int> numbers;
    const int n = static_cast<int>(rng() % 60);
    for (int i = 0; i < n; ++i) {
      ToolEntry e;
      e.tool = static_cast<int>(rng() % 100);
      const bool fresh = std::find(numbers.begin(), numbers.end(), e.tool) == numbers.end();
      EXPECT_EQ(t.add(e), fresh);
      if (fresh) numbers.push_back(e.tool);
    }
    for (int tool = 0; tool < 100; ++tool) {
      const auto it = std::find(numbers.begin(), numbers.end(), tool);
      const auto found = t.find(tool);
      if (it == numbers.end()) {
        EXPECT_FALSE(found.has_value());
      } else {
        ASSERT_TRUE(found.has_value());
        EXPECT_EQ(*found, static_cast<std::size_t>(it - numbers.begin()) + 1);
        EXPECT_EQ(t.at_index(*found).tool, tool);
      }
    }
  }
}
