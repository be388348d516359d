// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart's calls on the plasma table with a [cut_chart]: the chart as JSON, an operator's
// selection, an admin's set and remove (audited as "hmi"), an operator's change refused (403), a bad
// material refused naming its field (422) with nothing changed, a machine without a chart (404).
#include "opencnc/hmi/api_cutchart.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/store/cut_chart_store.hpp"

namespace opencnc::hmi {
namespace {

using nlohmann::json;

class ChartTable : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("opencnc-hmi-cutchart-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    std::string csv, text, error;
    ASSERT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/plasma-cutchart.csv", csv, &error)) << error;
    Diagnostics d;
    auto s = store::CutChartStore::open((dir_ / "chart.db").string(), &error);
    ASSERT_TRUE(s && s->write(*store::parse_cut_chart_csv(csv, "c.csv", d), "test", "import", &error))
        << error;
    ASSERT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/plasma-table.toml", text, &error)) << error;
    std::ofstream(dir_ / "table.toml") << text << "\n[cut_chart]\nstore = \"chart.db\"\n";
    auto load = config::load_profile(dir_ / "table.toml", {});
    ASSERT_TRUE(load.ok());
    profile_ = *load.profile;
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::filesystem::path dir_;
  config::MachineProfile profile_;
};

TEST_F(ChartTable, ListsTheMaterialsFieldsAndSelection) {
  const CutChartAnswer a = cut_chart_get(profile_);
  ASSERT_EQ(a.status, 200) << a.body.dump();
  ASSERT_EQ(a.body["materials"].size(), 4u);
  EXPECT_EQ(a.body["materials"][1]["number"], 6);
  EXPECT_EQ(a.body["materials"][1]["kerf_width_mm"], 1.5);
  EXPECT_EQ(a.body["materials"][1]["process"], "plasma");
  EXPECT_EQ(a.body["selected"], 0);
  EXPECT_EQ(a.body["fields"][0]["name"], "number");
  EXPECT_EQ(a.body["audit"].size(), 4u);
}

TEST_F(ChartTable, AnOperatorSelectsAnAdminChanges) {
  CutChartAnswer a = cut_chart_post(profile_, {{"action", "select"}, {"material", 10}}, Role::Operator);
  ASSERT_EQ(a.status, 200) << a.body.dump();
  EXPECT_EQ(a.body["selected"], 10);
  EXPECT_EQ(a.body["audit"].back()["interface"], "hmi");
  json m = a.body["materials"][1];
  m["feed_mm_min"] = 2600;
  a = cut_chart_post(profile_, {{"action", "set"}, {"material", m}}, Role::Operator);
  EXPECT_EQ(a.status, 403);
  a = cut_chart_post(profile_, {{"action", "set"}, {"material", m}}, Role::Admin);
  ASSERT_EQ(a.status, 200) << a.body.dump();
  EXPECT_EQ(a.body["materials"][1]["feed_mm_min"], 2600);
  EXPECT_EQ(a.body["audit"].back()["what"], "material 6 feed_mm_min");
  EXPECT_EQ(a.body["audit"].back()["old"], "2400");
  a = cut_chart_post(profile_, {{"action", "remove"}, {"material", 40}}, Role::Admin);
  ASSERT_EQ(a.status, 200) << a.body.dump();
  EXPECT_EQ(a.body["materials"].size(), 3u);
}

TEST_F(ChartTable, ABadMaterialIsRefusedNamingItsFieldAndChangesNothing) {
  const json before = cut_chart_get(profile_).body["materials"];
  json m = before[1];
  m["cut_height_mm"] = 5;
  CutChartAnswer a = cut_chart_post(profile_, {{"action", "set"}, {"material", m}}, Role::Admin);
  EXPECT_EQ(a.status, 422);
  EXPECT_EQ(a.body["error"], "cut_height_mm: 5 is above the pierce height 3.8");
  m = before[1];
  m["kerf_width_mm"] = "wide";
  EXPECT_EQ(cut_chart_post(profile_, {{"action", "set"}, {"material", m}}, Role::Admin).status, 400);
  EXPECT_EQ(cut_chart_post(profile_, {{"action", "select"}, {"material", 7}}, Role::Operator).body["error"],
            "material 7 is not in the cut chart");
  EXPECT_EQ(cut_chart_post(profile_, {{"action", "select"}, {"material", 2.5}}, Role::Operator).status, 422);
  EXPECT_EQ(cut_chart_post(profile_, {{"action", "burn"}, {"material", 6}}, Role::Admin).status, 400);
  EXPECT_EQ(cut_chart_get(profile_).body["materials"], before);
}

TEST(CutChartApi, AMachineWithoutAChartHasNone) {
  auto load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/plasma-table.toml", {});
  ASSERT_TRUE(load.ok());
  EXPECT_EQ(cut_chart_get(*load.profile).status, 404);
}

}  // namespace
}  // namespace opencnc::hmi
