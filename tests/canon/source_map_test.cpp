// SPDX-License-Identifier: GPL-3.0-or-later
// Call stacks are interned: the same call site reuses one context.
#include <gtest/gtest.h>

#include "opencnc/canon/source_map.hpp"

using opencnc::canon::SourceMap;

TEST(SourceMap, InternsFilesAndContexts) {
  SourceMap m;
  auto main_file = m.add_file("main.ngc");
  auto sub_file = m.add_file("sub.ngc");
  EXPECT_EQ(m.add_file("main.ngc"), main_file);
  auto c1 = m.context(0, {main_file, 10, 1}, sub_file, "o<sub>");
  auto c2 = m.context(0, {main_file, 10, 1}, sub_file, "o<sub>");
  auto c3 = m.context(c1, {sub_file, 4, 1}, sub_file, "o<sub>");
  EXPECT_EQ(c1, c2);
  EXPECT_NE(c1, c3);
  EXPECT_EQ(m.stack(c3), (std::vector<std::uint32_t>{c1, c3}));
  EXPECT_EQ(m.describe(c3, sub_file, 7), "main.ngc:10 (o<sub>) > sub.ngc:4 (o<sub>) > sub.ngc:7");
}
