// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart: rows checked, CSV read with errors at line:col and written back equal, the store
// keeping the chart across opens with an audit of every change, refusing bad changes whole.
#include "opencnc/store/cut_chart_store.hpp"

#include <gtest/gtest.h>

#include "opencnc/store/database.hpp"
#include "temp_db.hpp"

namespace opencnc::store {
namespace {

using test::TempDb;

const char* kCsv =
    "# opencnc cut chart\n"
    "number,name,thickness_mm,process,kerf_width_mm,feed_mm_min,pierce_height_mm,pierce_delay_s,"
    "cut_height_mm,arc_voltage_v,amperage_a,puddle_height_mm,puddle_delay_s\n"
    "6,\"Mild steel 6 mm, 45 A\",6,plasma,1.5,2400,3.8,0.5,1.5,118,45,0,0\n"
    "\n"
    "3,Mild steel 3 mm,3,plasma,1.2,3500,3.2,0.3,1.2,112,45,4.5,0.2\n"
    "20,Mild steel 20 mm oxy,20,oxy-fuel,2.5,450,8,30,6,0,0,0,0\n";

Material mild6() {
  Material m;
  m.number = 6;
  m.name = "Mild steel 6 mm, 45 A";
  m.thickness_mm = 6;
  m.kerf_width_mm = 1.5;
  m.feed_mm_min = 2400;
  m.pierce_height_mm = 3.8;
  m.pierce_delay_s = 0.5;
  m.cut_height_mm = 1.5;
  m.arc_voltage_v = 118;
  m.amperage_a = 45;
  return m;
}

std::vector<Material> parse_ok(std::string_view text) {
  Diagnostics d;
  auto chart = parse_cut_chart_csv(text, "chart.csv", d);
  EXPECT_TRUE(chart.has_value());
  for (const Diagnostic& x : d.items()) ADD_FAILURE() << x.format();
  return chart.value_or(std::vector<Material>{});
}

std::string first_error(std::string_view text) {
  Diagnostics d;
  EXPECT_FALSE(parse_cut_chart_csv(text, "chart.csv", d).has_value());
  return d.items().empty() ? std::string() : d.items().front().format();
}

std::shared_ptr<CutChartStore> open_store(const std::string& path) {
  std::string error;
  auto s = CutChartStore::open(path, &error);
  EXPECT_NE(s, nullptr) << error;
  int n = 0;
  if (s) s->set_clock([n]() mutable { return "2026-12-07T16:00:" + std::to_string(10 + n++) + "Z"; });
  return s;
}

TEST(CutChartCsv, ReadsEveryFieldInNumberOrder) {
  const auto chart = parse_ok(kCsv);
  ASSERT_EQ(chart.size(), 3u);
  EXPECT_EQ(chart[0].number, 3);
  EXPECT_EQ(chart[0].puddle_height_mm, 4.5);
  EXPECT_EQ(chart[0].puddle_delay_s, 0.2);
  EXPECT_EQ(chart[1], mild6());
  EXPECT_EQ(chart[2].process, CutProcess::OxyFuel);
  EXPECT_EQ(chart[2].pierce_delay_s, 30);
}

TEST(CutChartCsv, WritesWhatItReadsBackEqual) {
  const auto chart = parse_ok(kCsv);
  const std::string text = format_cut_chart_csv(chart);
  EXPECT_EQ(parse_ok(text), chart);
  EXPECT_NE(text.find("\"Mild steel 6 mm, 45 A\""), std::string::npos);
  EXPECT_EQ(format_cut_chart_csv(parse_ok(text)), text);
}

TEST(CutChartCsv, ColumnsInAnyOrderAndPuddleLeftOut) {
  const auto chart = parse_ok(
      "name,number,process,thickness_mm,kerf_width_mm,feed_mm_min,pierce_height_mm,pierce_delay_s,"
      "cut_height_mm,arc_voltage_v,amperage_a\r\n"
      "Aluminium 4,40,plasma,4,1.6,3000,3.5,0.2,1.5,0,65\r\n");
  ASSERT_EQ(chart.size(), 1u);
  EXPECT_EQ(chart[0].number, 40);
  EXPECT_EQ(chart[0].name, "Aluminium 4");
  EXPECT_EQ(chart[0].puddle_height_mm, 0);
}

TEST(CutChartCsv, ErrorsAtLineAndColumn) {
  const std::string header =
      "number,name,thickness_mm,process,kerf_width_mm,feed_mm_min,pierce_height_mm,pierce_delay_s,"
      "cut_height_mm,arc_voltage_v,amperage_a\n";
  // A feed that is not a number: line 2, the feed's column (after "1,A,6,plasma,1.5,").
  EXPECT_EQ(first_error(header + "1,A,6,plasma,1.5,fast,3.8,0.5,1.5,0,45\n"),
            "chart.csv:2:18: error: feed_mm_min: \"fast\" is not a number");
  // The cut height above the pierce height: at the cut height's column.
  EXPECT_EQ(first_error(header + "1,A,6,plasma,1.5,2400,3.8,0.5,4,0,45\n"),
            "chart.csv:2:31: error: cut_height_mm: 4 is above the pierce height 3.8");
  EXPECT_EQ(first_error(header + "1,A,6,laser,1.5,2400,3.8,0.5,1.5,0,45\n"),
            "chart.csv:2:7: error: process: \"laser\" is not a process (plasma or oxy-fuel)");
  EXPECT_EQ(first_error(header + "1,A,6,plasma,1.5,2400,3.8,0.5,1.5,0\n"),
            "chart.csv:2:36: error: 10 fields where the header has 11 columns");
  EXPECT_EQ(first_error(header +
                        "1,A,6,plasma,1.5,2400,3.8,0.5,1.5,0,45\n\n1,B,6,plasma,1.5,2400,3.8,0.5,1.5,0,45\n"),
            "chart.csv:4:1: error: material 1 is already on line 2");
  EXPECT_EQ(first_error(header + "1,\"A,6,plasma\n"), "chart.csv:2:3: error: a quoted field is not closed");
  EXPECT_EQ(first_error(header + "0,A,6,plasma,1.5,2400,3.8,0.5,1.5,0,45\n"),
            "chart.csv:2:1: error: number: \"0\" is not a material number (a whole number from 1 to 99999)");
  EXPECT_EQ(first_error("number,name,thickness,process\n"),
            "chart.csv:1:13: error: unknown column \"thickness\"");
  EXPECT_EQ(first_error(""), "chart.csv:1:1: error: no header line (number,name,…)");
}

TEST(CutChartCsv, EveryBadLineIsReported) {
  Diagnostics d;
  EXPECT_FALSE(
      parse_cut_chart_csv(
          "number,name,thickness_mm,process,kerf_width_mm,feed_mm_min,pierce_height_mm,pierce_delay_s,"
          "cut_height_mm,arc_voltage_v,amperage_a\n"
          "1,A,6,plasma,-1,2400,3.8,0.5,1.5,0,45\n"
          "2,B,6,plasma,1.5,2400,3.8,0.5,1.5,0,45\n"
          "3,C,6,plasma,1.5,0,3.8,0.5,1.5,0,45\n",
          "c.csv", d)
          .has_value());
  ASSERT_EQ(d.error_count(), 2u);
  EXPECT_EQ(d.items()[0].line, 2u);
  EXPECT_EQ(d.items()[1].line, 4u);
  EXPECT_EQ(d.items()[1].code, "cutchart.csv-value");
}

TEST(CutChartStore, KeepsTheChartAcrossOpensAndAuditsEveryValue) {
  TempDb dir;
  const std::string path = dir.path("chart.db");
  {
    auto s = open_store(path);
    std::string e;
    ASSERT_TRUE(s->write(parse_ok(kCsv), "command line", "import chart.csv", &e)) << e;
    Material m = mild6();
    m.feed_mm_min = 2600;
    m.kerf_width_mm = 1.6;
    ASSERT_TRUE(s->put(m, "hmi", &e)) << e;
  }
  auto s = open_store(path);
  const auto chart = s->chart();
  ASSERT_TRUE(chart);
  ASSERT_EQ(chart->size(), 3u);
  EXPECT_EQ(find(*chart, 6)->feed_mm_min, 2600);
  const auto audit = s->audit();
  ASSERT_EQ(audit.size(), 5u);  // three materials added, then two values of one changed
  EXPECT_EQ(audit[0].what, "material 3");
  EXPECT_EQ(audit[0].old_value, "");
  EXPECT_EQ(audit[0].reason, "import chart.csv");
  EXPECT_EQ(audit[0].interface, "command line");
  EXPECT_NE(audit[0].new_value.find("kerf_width_mm=1.2"), std::string::npos);
  EXPECT_EQ(audit[3].what, "material 6 kerf_width_mm");
  EXPECT_EQ(audit[3].old_value, "1.5");
  EXPECT_EQ(audit[3].new_value, "1.6");
  EXPECT_EQ(audit[3].interface, "hmi");
  EXPECT_EQ(audit[4].what, "material 6 feed_mm_min");
  EXPECT_EQ(audit[4].at_utc, "2026-12-07T16:00:11Z");
  EXPECT_EQ(s->audit(1).size(), 1u);
  EXPECT_EQ(s->audit(1)[0].what, "material 6 feed_mm_min");
}

TEST(CutChartStore, RemovesAndAuditsTheWholeRow) {
  TempDb dir;
  auto s = open_store(dir.path("chart.db"));
  std::string e;
  ASSERT_TRUE(s->write(parse_ok(kCsv), "test", "import", &e)) << e;
  ASSERT_TRUE(s->remove(20, "hmi", &e)) << e;
  EXPECT_FALSE(s->material(20));
  const auto a = s->audit(1);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].what, "material 20");
  EXPECT_EQ(a[0].new_value, "");
  EXPECT_NE(a[0].old_value.find("process=oxy-fuel"), std::string::npos);
  EXPECT_FALSE(s->remove(20, "hmi", &e));
  EXPECT_EQ(e, "material 20 is not in the cut chart");
}

TEST(CutChartStore, ABadChangeChangesNothing) {
  TempDb dir;
  auto s = open_store(dir.path("chart.db"));
  std::string e;
  ASSERT_TRUE(s->write(parse_ok(kCsv), "test", "import", &e)) << e;
  const auto before = s->chart();
  const std::size_t audited = s->audit().size();
  Material m = mild6();
  m.cut_height_mm = 5;
  EXPECT_FALSE(s->put(m, "hmi", &e));
  EXPECT_EQ(e, "cut_height_mm: 5 is above the pierce height 3.8");
  std::vector<Material> twice = *before;
  twice.push_back(twice.front());
  EXPECT_FALSE(s->write(twice, "test", "import", &e));
  EXPECT_EQ(e, "material 3 is in the chart twice");
  EXPECT_EQ(s->chart(), before);
  EXPECT_EQ(s->audit().size(), audited);
}

TEST(CutChartStore, TheSelectionIsKeptAuditedAndFollowsTheChart) {
  TempDb dir;
  auto s = open_store(dir.path("chart.db"));
  std::string e;
  ASSERT_TRUE(s->write(parse_ok(kCsv), "test", "import", &e)) << e;
  EXPECT_EQ(s->selected(), 0);
  EXPECT_FALSE(s->select(7, "hmi", &e));
  EXPECT_EQ(e, "material 7 is not in the cut chart");
  ASSERT_TRUE(s->select(20, "hmi", &e)) << e;
  EXPECT_EQ(open_store(dir.path("chart.db"))->selected(), 20);
  auto a = s->audit(1);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].what, "selected material");
  EXPECT_EQ(a[0].old_value, "0");
  EXPECT_EQ(a[0].new_value, "20");
  EXPECT_EQ(a[0].interface, "hmi");
  // Removing the selected material selects none, in the same transaction and audit.
  ASSERT_TRUE(s->remove(20, "command line", &e)) << e;
  EXPECT_EQ(s->selected(), 0);
  a = s->audit(2);
  EXPECT_EQ(a[0].what, "material 20");
  EXPECT_EQ(a[1].what, "selected material");
  EXPECT_EQ(a[1].new_value, "0");
}

TEST(CutChartStore, AnotherProcessesCommitIsSeenAndCounted) {
  TempDb dir;
  auto a = open_store(dir.path("chart.db"));
  auto b = open_store(dir.path("chart.db"));
  const std::uint64_t seen = a->changes();
  std::string e;
  ASSERT_TRUE(b->put(mild6(), "command line", &e)) << e;
  EXPECT_GT(a->changes(), seen);
  ASSERT_TRUE(a->material(6));
  EXPECT_EQ(*a->material(6), mild6());
}

TEST(CutChartStore, RefusesAToolStoreOrAnyOtherDatabase) {
  TempDb dir;
  std::string e;
  ASSERT_TRUE(ToolStore::open(dir.path("tools.db"), &e)) << e;
  EXPECT_FALSE(CutChartStore::open(dir.path("tools.db"), &e));
  EXPECT_NE(e.find("not an opencnc cut chart"), std::string::npos) << e;
  EXPECT_FALSE(CutChartStore::open(dir.path("missing.db"), &e, /*create=*/false));
}

}  // namespace
}  // namespace opencnc::store

namespace opencnc::store {
namespace {

TEST(CutChartCsv, AnOxyFuelRowsPreheatIsReadAndAPlasmaRowHasNone) {
  const std::string header =
      "number,name,thickness_mm,process,kerf_width_mm,feed_mm_min,pierce_height_mm,pierce_delay_s,"
      "cut_height_mm,arc_voltage_v,amperage_a,preheat_s\n";
  const auto chart = parse_ok(header + "20,Mild steel 20 mm oxy,20,oxy-fuel,2.5,450,12,1.5,7,0,0,6.5\n");
  ASSERT_EQ(chart.size(), 1u);
  EXPECT_EQ(chart[0].preheat_s, 6.5);
  EXPECT_NE(format_cut_chart_csv(chart).find("preheat_s"), std::string::npos);
  EXPECT_EQ(parse_ok(format_cut_chart_csv(chart)), chart);
  EXPECT_EQ(first_error(header + "6,A,6,plasma,1.5,2400,3.8,0.5,1.5,0,45,3\n"),
            "chart.csv:2:40: error: preheat_s: a plasma material has no preheat (oxy-fuel only)");
  EXPECT_EQ(first_error(header + "20,B,20,oxy-fuel,2.5,450,12,1.5,7,0,0,-1\n"),
            "chart.csv:2:39: error: preheat_s: -1 is not from 0 to 600");
  EXPECT_EQ(parse_ok(kCsv)[2].preheat_s, 0);  // the column left out: 0, the profile's preheat
}

/// A chart as opencnc wrote it before preheat_s (schema 1), with one oxy-fuel and one plasma row.
void write_schema_1(const std::string& path) {
  Database db(path, OpenOptions{true, false});
  db.exec(R"(
CREATE TABLE materials(number INTEGER PRIMARY KEY, name TEXT NOT NULL, thickness_mm REAL NOT NULL,
  process TEXT NOT NULL, kerf_width_mm REAL NOT NULL, feed_mm_min REAL NOT NULL,
  pierce_height_mm REAL NOT NULL, pierce_delay_s REAL NOT NULL, cut_height_mm REAL NOT NULL,
  arc_voltage_v REAL NOT NULL, amperage_a REAL NOT NULL, puddle_height_mm REAL NOT NULL,
  puddle_delay_s REAL NOT NULL);
CREATE TABLE selection(id INTEGER PRIMARY KEY CHECK (id = 1), material INTEGER NOT NULL);
INSERT INTO selection(id, material) VALUES(1, 20);
CREATE TABLE audit(id INTEGER PRIMARY KEY, at_utc TEXT NOT NULL, interface TEXT NOT NULL,
  reason TEXT NOT NULL, what TEXT NOT NULL, old_value TEXT NOT NULL, new_value TEXT NOT NULL);
INSERT INTO materials VALUES(6, 'Mild steel 6 mm', 6, 'plasma', 1.5, 2400, 3.8, 0.5, 1.5, 118, 45, 0, 0);
INSERT INTO materials VALUES(20, 'Mild steel 20 mm oxy', 20, 'oxy-fuel', 2.5, 450, 12, 1.5, 7, 0, 0, 0, 0);
INSERT INTO audit VALUES(1, '2026-01-01T00:00:00Z', 'command line', 'import', 'material 6', '', 'x');
PRAGMA application_id=1329808195; PRAGMA user_version=1;
)");
}

TEST(CutChartStore, AChartOfSchemaOneKeepsItsRowsAndLearnsThePreheat) {
  TempDb dir;
  const std::string path = dir.path("chart.db");
  write_schema_1(path);
  {  // read-only: read as it is, not changed
    std::string e;
    auto r = CutChartStore::open(path, &e, false, true);
    ASSERT_NE(r, nullptr) << e;
    const auto chart = r->chart();
    ASSERT_TRUE(chart);
    ASSERT_EQ(chart->size(), 2u);
    EXPECT_EQ(find(*chart, 20)->preheat_s, 0);
  }
  EXPECT_EQ(Database(path, OpenOptions{false, true}).query_integer("PRAGMA user_version"), 1);
  auto s = open_store(path);  // writable: migrated
  const auto chart = s->chart();
  ASSERT_TRUE(chart);
  ASSERT_EQ(chart->size(), 2u);
  EXPECT_EQ(find(*chart, 6)->arc_voltage_v, 118);
  EXPECT_EQ(find(*chart, 6)->name, "Mild steel 6 mm");
  EXPECT_EQ(find(*chart, 20)->pierce_height_mm, 12);
  EXPECT_EQ(find(*chart, 20)->preheat_s, 0);
  EXPECT_EQ(s->selected().value_or(-1), 20);
  EXPECT_EQ(s->audit().size(), 1u);  // the old audit kept
  Material m = *find(*chart, 20);
  m.preheat_s = 6.5;
  std::string e;
  ASSERT_TRUE(s->put(m, "hmi", &e)) << e;
  EXPECT_EQ(s->audit().back().what, "material 20 preheat_s");
  s.reset();
  auto again = open_store(path);
  EXPECT_EQ(find(*again->chart(), 20)->preheat_s, 6.5);
  EXPECT_EQ(Database(path, OpenOptions{false, true}).query_integer("PRAGMA user_version"), 2);
}

}  // namespace
}  // namespace opencnc::store
