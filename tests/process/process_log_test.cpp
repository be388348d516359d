// SPDX-License-Identifier: GPL-3.0-or-later
// The process-data log through the whole controller on the broach: a stroke's rows at the
// profile's rate, to CSV and to SQLite, with the load, the positions, the feed and the helix error.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/process/process_log.hpp"
#include "opencnc/store/database.hpp"

namespace opencnc::process {
namespace {

using namespace control;
using namespace controller;

std::filesystem::path folder() {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-process-log-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// One 0.1 mm stroke through the first 100 mm of the bore and back, logged to `path`.
std::uint64_t run_logged(const std::string& path, LogFormat format) {
  const config::MachineProfile p =
      test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml"));
  const std::string program = (std::filesystem::path(path).parent_path() / "p.ngc").string();
  std::ofstream(program) << "G21 G90 G94\nG0 X-0.5\nG0 Z-10 C0\nM171 P600\nG1 X0.1 F60\nG1 Z100 F3000\n"
                            "G1 X-0.4\nG0 Z-10\nM175\nM2\n";
  std::string error;
  auto out = OutputFile::open({"--process-log", path}, &error);
  EXPECT_NE(out, nullptr) << error;
  ProcessLogSetup setup{
      p.axis_mask(), p.broaching.log_rate_hz, p.servo_period_s, p.coupling.radius_mm, program, p.name};
  auto log = std::make_shared<ProcessLog>(setup, format, *out);
  Diagnostics d;
  SimRig rig(p, *features::machine_setup(p, d));
  rig.controller().attach(log, ObserverOptions{0, true});
  rig.step();
  EXPECT_TRUE(rig.request(Request::simple(CommandKind::MachineOn)).accepted);
  EXPECT_TRUE(rig.request(Request::set_mode(Mode::Auto)).accepted);
  EXPECT_TRUE(rig.request(Request::open(program), 100000).accepted);
  EXPECT_TRUE(rig.request(Request::simple(CommandKind::CycleStart)).accepted);
  EXPECT_TRUE(rig.run_until(
      [&] { return !rig.status().run_active && rig.status().servo.state == State::Idle; }, 20000));
  EXPECT_TRUE(log->finish(&error)) << error;
  EXPECT_TRUE(out->commit(&error)) << error;
  return log->rows();
}

TEST(ProcessLog, CsvRowsAtTheProfilesRate) {
  const std::string path = (folder() / "log.csv").string();
  const std::uint64_t rows = run_logged(path, LogFormat::Csv);
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header,
            "t_s,line,load_kn,feed_mm_min,x_cmd,x_act,z_cmd,z_act,c_cmd,c_act,coupled,coupling_error_deg,"
            "helix_error_um");
  std::vector<std::vector<double>> table;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    ASSERT_EQ(row.size(), 13u) << line;
    table.push_back(row);
  }
  ASSERT_EQ(table.size(), rows);
  // 100 rows a second of servo time: 110 mm at 50 mm/s and the return, about 3.5 s.
  EXPECT_GT(rows, 300u);
  EXPECT_LT(rows, 500u);
  double max_load = 0, max_feed = 0;
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (i > 0) {
      EXPECT_NEAR(table[i][0] - table[i - 1][0], 0.01, 1e-9);
    }
    max_load = std::max(max_load, table[i][2]);
    if (table[i][2] > 1) max_feed = std::max(max_feed, table[i][3]);  // while it cuts
    if (table[i][10] == 1) {
      EXPECT_NEAR(table[i][8], 360.0 * (table[i][6] + 10) / 600, 1e-5);  // C on the law
    }
  }
  EXPECT_NEAR(max_load, 2.875, 0.05);  // the 0.1 mm stroke at 3 m/min
  EXPECT_NEAR(max_feed, 3000, 1);      // F3000 along Z (C's degrees not counted)
}

TEST(ProcessLog, SqliteHoldsTheRunAndItsRows) {
  const std::string path = (folder() / "log.sqlite").string();
  const std::uint64_t rows = run_logged(path, LogFormat::Sqlite);
  store::Database db(path, store::OpenOptions{false, true});
  EXPECT_EQ(db.query_integer("SELECT count(*) FROM process_data"), static_cast<std::int64_t>(rows));
  EXPECT_EQ(db.query_integer("SELECT count(*) FROM run WHERE machine = 'broach-zc' AND rate_hz = 100"), 1);
  store::Statement q = db.prepare(
      "SELECT max(load_kn), max(feed_mm_min), max(z_cmd), max(feed_mm_min) FILTER (WHERE load_kn > 1) "
      "FROM process_data");
  ASSERT_TRUE(q.step());
  EXPECT_NEAR(q.real(0), 2.875, 0.05);
  EXPECT_NEAR(q.real(1), 9000, 1);  // the rapid return: Z at 150 mm/s
  EXPECT_NEAR(q.real(2), 100, 1e-9);
  EXPECT_NEAR(q.real(3), 3000, 1);  // the cut
}

TEST(ProcessLog, FormatFromTheName) {
  EXPECT_EQ(log_format("a.csv"), LogFormat::Csv);
  EXPECT_EQ(log_format("a.SQLite"), LogFormat::Sqlite);
  EXPECT_EQ(log_format("a.db"), LogFormat::Sqlite);
  EXPECT_FALSE(log_format("a.txt").has_value());
  EXPECT_FALSE(log_format("a").has_value());
}

}  // namespace
}  // namespace opencnc::process
