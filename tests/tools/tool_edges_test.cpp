// SPDX-License-Identifier: GPL-3.0-or-later
// Tools with edges: the check against a backup (per-kind tolerances, the wear band), the
// LinuxCNC numbering of edges, the 840D subprogram round trip and its errors, .tbl import.
#include <gtest/gtest.h>

#include "opencnc/tools/edge_mapping.hpp"
#include "opencnc/tools/tool_check.hpp"
#include "opencnc/tools/tool_text.hpp"

namespace opencnc::tools {
namespace {

ToolSet sample() {
  ToolSet s;
  Tool& t = s.tool_or_add(53);
  t.pocket = 12;
  t.comment = "D16 end mill; roughing";
  Edge& e = s.edge_or_add(53, 1);
  e.set(Param::Type, 120);
  e.set(Param::Length1, 193.225);
  e.set(Param::Radius, 8);
  e.set(Param::WearLength1, -0.02);
  e.set(Param::WearRadius, 0.1 + 0.2);  // 0.30000000000000004: must survive exactly
  e.set(Param::BaseLength1, 1e-7);
  Edge& e2 = s.edge_or_add(53, 2);
  e2.set(Param::Length1, 150.5);
  Tool& lathe = s.tool_or_add(7);
  lathe.pocket = 0;
  Edge& le = s.edge_or_add(7, 1);
  le.set(Param::Type, 500);
  le.set(Param::CuttingDirection, 3);
  le.set(Param::Length3, 40.125);
  le.set(Param::Radius, 0.4);
  return s;
}

TEST(ToolCheck, CatchesTheTypoNamingToolEdgeAndValues) {
  const ToolSet backup = sample();
  ToolSet live = backup;
  live.edge_or_add(53, 1).set(Param::Length1, 139.225);
  const auto diffs = check(backup, live, {});
  ASSERT_EQ(diffs.size(), 1u);
  EXPECT_EQ(diffs[0].text(),
            "T53 D1 length1: backup 193.225, live 139.225 (-54 mm; geometry tolerance 0.001 mm)");
}

TEST(ToolCheck, WearWithinTheBandPassesGeometryDoesNot) {
  const ToolSet backup = sample();
  ToolSet live = backup;
  live.edge_or_add(53, 1).set(Param::WearLength1, -0.02 - 0.1);  // exactly the band
  live.edge_or_add(53, 1).set(Param::WearRadius, 0.25);
  EXPECT_TRUE(check(backup, live, {}).empty());
  EXPECT_EQ(compare(backup, live, {}).size(), 2u);  // listed by diff, tolerated
  live.edge_or_add(53, 1).set(Param::WearLength1, -0.2);
  const auto d = check(backup, live, {});
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NE(d[0].text().find("wear band 0.1 mm"), std::string::npos) << d[0].text();
  live = backup;
  live.edge_or_add(53, 1).set(Param::Radius, 8.0005);  // within the geometry tolerance
  EXPECT_TRUE(check(backup, live, {}).empty());
  live.edge_or_add(53, 1).set(Param::Radius, 8.002);
  EXPECT_EQ(check(backup, live, {}).size(), 1u);
  live = backup;
  live.edge_or_add(7, 1).set(Param::CuttingDirection, 4);  // identities: no tolerance
  EXPECT_EQ(check(backup, live, {}).size(), 1u);
}

TEST(ToolCheck, NamesEdgesAddedAndRemovedAndLimitsToOneTool) {
  const ToolSet backup = sample();
  ToolSet live = backup;
  live.edge_or_add(9, 1).set(Param::Length1, 80);
  live.tool(53)->edges.pop_back();
  const auto all = check(backup, live, {});
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].text(), "T9 D1: live, not in the backup (a new edge: accept it to back it up)");
  EXPECT_EQ(all[1].text(), "T53 D2: in the backup, missing from the live table");
  EXPECT_EQ(check(backup, live, {}, 9).size(), 1u);
  EXPECT_TRUE(check(backup, live, {}, 7).empty());
}

TEST(EdgeMapping, NumbersEdgesAsLinuxcncTools) {
  EXPECT_EQ(linuxcnc_number(3, 1), 3);
  EXPECT_EQ(linuxcnc_number(3, 2), 20003);
  EXPECT_EQ(tool_and_edge(20003), (std::pair{3, 2}));
  EXPECT_EQ(tool_and_edge(3), (std::pair{3, 1}));
  EXPECT_FALSE(tool_and_edge(10003));  // "D1" is written as T alone
  EXPECT_FALSE(tool_and_edge(0));
  EXPECT_FALSE(tool_and_edge(100000));
  const ToolTable t = linuxcnc_table(sample());
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t.tool(7)->offset[Axis::X], 40.125);
  EXPECT_EQ(t.tool(7)->orientation, 3);
  EXPECT_DOUBLE_EQ(t.tool(53)->diameter, 2 * 8.3);
  EXPECT_EQ(t.tool(20053)->comment, "D16 end mill; roughing D2");
}

TEST(Format840d, RoundTripsExactly) {
  const ToolSet s = sample();
  const SnapshotHeader h{4, "2026-11-26T03:10:56Z"};
  const std::string text = format_840d(s, h);
  EXPECT_NE(text.find("IF (R90==53) AND (R91==1)\n  R1=120 R2=0 R3=193.225 "), std::string::npos) << text;
  EXPECT_NE(text.find("R6=8 "), std::string::npos);
  EXPECT_NE(text.find("R15=0.30000000000000004"), std::string::npos);
  EXPECT_NE(text.find("R21=0.0000001"), std::string::npos);  // no exponent
  EXPECT_EQ(text.substr(text.size() - 4), "M17\n");
  EXPECT_EQ(text.substr(0, text.find('\n')), "; opencnc tool data: backup 4 taken 2026-11-26T03:10:56Z");
  Diagnostics d;
  SnapshotHeader back;
  const auto parsed = parse_840d(text, "b.spf", d, &back);
  ASSERT_TRUE(parsed) << (d.items().empty() ? "" : d.items()[0].format());
  EXPECT_EQ(*parsed, s);
  EXPECT_EQ(back, h);
  EXPECT_EQ(format_840d(*parsed, back), text);
  EXPECT_TRUE(looks_like_840d(text));
}

TEST(Format840d, ErrorsNameFileLineAndColumn) {
  auto first_error = [](std::string_view text) {
    Diagnostics d;
    EXPECT_FALSE(parse_840d(text, "b.spf", d));
    return d.items().empty() ? std::string() : d.items()[0].format();
  };
  EXPECT_NE(
      first_error("; T1 pocket 1\nIF (R90==1) AND (R91==1)\n  R3=1 R7=2\nENDIF\nM17\n").find("b.spf:3:8"),
      std::string::npos);
  EXPECT_NE(first_error("; T1 pocket 1\nIF (R90==1) AND (R91==1)\n  R3=1\nM17\n")
                .find("M17 inside the IF of line 2"),
            std::string::npos);
  EXPECT_NE(first_error("; T1 pocket 1\nIF (R90==1) AND (R91==1)\nENDIF\n").find("without M17"),
            std::string::npos);
  EXPECT_NE(first_error("IF (R90==2) AND (R91==1)\nENDIF\nM17\n").find("'; T2 pocket"), std::string::npos);
  EXPECT_NE(
      first_error("; T1 pocket 1\nIF (R90==1) AND (R91==1)\n R3=abc\nENDIF\nM17\n").find("not a number"),
      std::string::npos);
  EXPECT_NE(first_error("M17\nR3=1\n").find("nothing may follow M17"), std::string::npos);
}

TEST(LinuxcncImport, ReadsEdgesFromTblAndRefusesWhatItCannotKeep) {
  Diagnostics d;
  const ToolTable t = ToolTable::parse("T3 P3 Z120.5 D10 ;drill\nT20003 P3 Z80 D6\n", "t.tbl", d);
  const auto s = from_linuxcnc(t, "t.tbl", d);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->edge(3, 1)->get(Param::Length1), 120.5);
  EXPECT_EQ(s->edge(3, 1)->get(Param::Radius), 5);
  EXPECT_EQ(s->edge(3, 2)->get(Param::Length1), 80);
  EXPECT_EQ(s->tool(3)->comment, "drill");
  EXPECT_EQ(linuxcnc_table(*s).format(), ToolTable::parse(linuxcnc_table(*s).format(), "x", d).format());
  Diagnostics bad;
  const ToolTable u = ToolTable::parse("T4 P4 Z10 A5\n", "u.tbl", bad);
  EXPECT_FALSE(from_linuxcnc(u, "u.tbl", bad));
  ASSERT_FALSE(bad.items().empty());
  EXPECT_NE(bad.items()[0].message.find("T4"), std::string::npos);
}

}  // namespace
}  // namespace opencnc::tools
