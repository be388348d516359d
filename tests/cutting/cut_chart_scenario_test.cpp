// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart through the controller on the simulated plasma table (configs/plasma-table.toml
// with a [cut_chart]): M194 P<n> puts the material's pierce height and delay, cut height and arc
// voltage on the torch (seen in the trace) and its kerf into G42's path; a feed or G41.1 diameter
// off the chart warns at its line and column; an unknown material is an error at its line before
// anything moves; the material selected before the program is used when it selects none.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/store/cut_chart_store.hpp"

namespace opencnc::controller::test {
namespace {

/// A folder of the test's own with the chart imported from configs/plasma-cutchart.csv.
class Bench {
 public:
  Bench() {
    dir_ = std::filesystem::temp_directory_path() /
           ("opencnc-cutchart-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    std::string csv, error;
    EXPECT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/plasma-cutchart.csv", csv, &error)) << error;
    Diagnostics d;
    const auto chart = store::parse_cut_chart_csv(csv, "plasma-cutchart.csv", d);
    EXPECT_TRUE(chart.has_value());
    auto s = store::CutChartStore::open(db(), &error);
    EXPECT_TRUE(s && s->write(*chart, "test", "import", &error)) << error;
  }
  ~Bench() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string db() const { return (dir_ / "chart.db").string(); }
  std::string program(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  /// configs/plasma-table.toml with a [cut_chart] naming the test's store.
  config::MachineProfile table(int material = 0) const {
    std::string text, error;
    EXPECT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/plasma-table.toml", text, &error)) << error;
    text += "\n[cut_chart]\nstore = \"chart.db\"\nmaterial = " + std::to_string(material) + "\n";
    const std::string path = (dir_ / "plasma-table.toml").string();
    std::ofstream(path) << text;
    return control::test::loaded(config::load_profile(path, {}));
  }

 private:
  std::filesystem::path dir_;
};

class Samples final : public ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const TraceContext&) override { samples.push_back(s); }
  std::vector<control::TraceSample> samples;
};

struct ChartRun {
  Outcome opened;
  bool finished = false;
  std::vector<control::TraceSample> trace;
};

ChartRun run(const config::MachineProfile& profile, const std::string& file) {
  ChartRun r;
  Diagnostics d;
  auto setup = features::machine_setup(profile, d);
  EXPECT_TRUE(setup) << (d.items().empty() ? "" : d.items()[0].format());
  if (!setup) return r;
  SimRig rig(profile, *setup);
  auto samples = std::make_shared<Samples>();
  rig.controller().attach(samples, ObserverOptions{0, true});
  rig.step();
  EXPECT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  EXPECT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  r.opened = rig.request(Request::open(file), 100000);
  if (!r.opened.accepted) return r;
  EXPECT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  r.finished = rig.run_until(
      [&] { return !rig.status().run_active && rig.status().servo.state == control::State::Idle; }, 200000);
  r.trace = std::move(samples->samples);
  return r;
}

/// The torch's height above the plate it found, per sample.
double height(const control::TraceSample& s) {
  return s.commanded[2] - s.torch.plate_z_mm;
}

TEST(CutChartScenario, TheMaterialDrivesTheTorchAndItsKerfTheCompensation) {
  const Bench b;
  // Material 10: pierce 4.5 mm for 0.8 s, a puddle jump to 6 mm for 0.3 s, cut at 1.5 mm holding
  // 114 V (no auto-volts sample), kerf 1.8 mm, 1300 mm/min.
  const std::string prog =
      b.program("part.ngc",
                "G21 G90 G17 G40 G64 P0.1\nG0 Z15\nM194 P10\nG0 X90 Y90\nM190\nG42\n"
                "G1 X100 Y100 F#<_cut_feed>\nX300\nY220\nX100\nY100\nG40\nM191\nG0 X0 Y0\nM2\n");
  const ChartRun r = run(b.table(), prog);
  ASSERT_TRUE(r.opened.accepted) << r.opened.message;
  EXPECT_EQ(r.opened.diagnostics.warning_count(), 0u);
  ASSERT_TRUE(r.finished);
  std::size_t piercing = 0, puddle = 0;
  double pierce_h = 0, puddle_h = 0, most_y = -1e9, least_y = 1e9, most_x = -1e9;
  bool first_cut = true, sampled = false;
  double cut_h = 0, target = 0;
  for (const control::TraceSample& s : r.trace) {
    const control::TorchPhase ph = s.torch.phase;
    if (ph == control::TorchPhase::Piercing) ++piercing, pierce_h = height(s);
    if (ph == control::TorchPhase::Puddle) ++puddle, puddle_h = std::max(puddle_h, height(s));
    if (s.torch.thc == control::ThcState::Sampling) sampled = true;
    if (ph != control::TorchPhase::Cutting) continue;
    if (first_cut) cut_h = height(s), first_cut = false;
    target = s.torch.target_voltage_v;
    const double x = s.commanded[0], y = s.commanded[1];
    if (x > 150 && x < 250 && y < 150) least_y = std::min(least_y, y);  // the bottom edge
    if (x > 150 && x < 250 && y > 150) most_y = std::max(most_y, y);    // the top edge
    if (y > 130 && y < 190) most_x = std::max(most_x, x);               // the right edge
  }
  EXPECT_NEAR(piercing * 0.001, 0.8, 0.003) << "the chart's pierce delay";
  EXPECT_NEAR(pierce_h, 4.5, 0.01) << "the chart's pierce height";
  EXPECT_GE(puddle * 0.001, 0.3) << "the chart's puddle delay (and the rise to it)";
  EXPECT_LE(puddle * 0.001, 0.4);
  EXPECT_NEAR(puddle_h, 6.0, 0.01);
  EXPECT_NEAR(cut_h, 1.5, 0.01) << "the chart's cut height";
  EXPECT_DOUBLE_EQ(target, 114) << "the chart's arc voltage, not a sample";
  EXPECT_FALSE(sampled);
  // G42 outside the part by half of the chart's 1.8 mm kerf (tool 1 has no diameter here).
  EXPECT_NEAR(least_y, 100 - 0.9, 0.01);
  EXPECT_NEAR(most_y, 220 + 0.9, 0.01);
  EXPECT_NEAR(most_x, 300 + 0.9, 0.01);
}

TEST(CutChartScenario, FeedAndKerfOffTheChartWarnAtTheirLineAndColumn) {
  const Bench b;
  const std::string prog = b.program("warn.ngc",
                                     "G21 G90 G17 G40 G64 P0.1\nG0 Z15\nM194 P6\nG0 X90 Y90\nM190\n"
                                     "G42.1 D2.5\nG1 X100 Y100 F2400\nX300 F3000\nY220\n  X100 F2500\nY100\n"
                                     "G40\nM191\nM2\n");
  const ChartRun r = run(b.table(), prog);
  ASSERT_TRUE(r.opened.accepted) << r.opened.message;
  std::vector<std::string> warnings;
  for (const Diagnostic& d : r.opened.diagnostics.items())
    if (d.severity == Severity::Warning) warnings.push_back(d.format());
  ASSERT_EQ(warnings.size(), 3u) << (warnings.empty() ? "" : warnings[0]);
  // The kerf at the D word; the feed 25 % above 2400 at the F word, and on the next line (F3000 is
  // modal) at the line's start; F2500 (4 %) is within 10 %.
  EXPECT_EQ(warnings[0],
            prog +
                ":6:7: warning: G42.1 D2.5 is not the kerf of cut chart material 6 (Mild steel 6 mm "
                "45 A): 1.5 (more than 0.05 apart)");
  EXPECT_EQ(warnings[1], prog +
                             ":8:6: warning: the feed 3000 mm/min is faster than cut chart material 6's 2400 "
                             "mm/min by more than 10 %");
  EXPECT_EQ(warnings[2].substr(0, prog.size() + 15), prog + ":9:1: warning: ");
  for (const Diagnostic& d : r.opened.diagnostics.items())
    if (d.severity == Severity::Warning) {
      EXPECT_TRUE(d.code == "cutchart.kerf" || d.code == "cutchart.feed");
    }
  EXPECT_TRUE(r.finished) << "warnings do not stop the run";
}

TEST(CutChartScenario, AnUnknownMaterialIsAnErrorAtItsLineBeforeAnythingMoves) {
  const Bench b;
  const std::string prog =
      b.program("bad.ngc", "G21 G90\nG0 Z15 X50\nM194 P99\nG0 X90 Y90\nM190\nG1 X100 F2400\nM191\nM2\n");
  const ChartRun r = run(b.table(), prog);
  ASSERT_FALSE(r.opened.accepted);
  ASSERT_FALSE(r.opened.diagnostics.items().empty());
  const Diagnostic& d = r.opened.diagnostics.items().front();
  EXPECT_EQ(d.code, "cutchart.material");
  EXPECT_EQ(d.line, 3u);
  EXPECT_EQ(d.col, 1u);
  EXPECT_NE(d.message.find("material 99 is not in the cut chart"), std::string::npos) << d.message;
  EXPECT_NE(d.message.find("3, 6, 10, 40"), std::string::npos) << d.message;
  EXPECT_TRUE(r.trace.empty() ||
              std::all_of(r.trace.begin(), r.trace.end(), [](const control::TraceSample& s) {
                return s.commanded[0] == 0 && s.commanded[2] == 0;
              }));
}

/// The pierce height and the lowest Y of the bottom edge while cutting.
std::pair<double, double> pierce_and_bottom(const ChartRun& r) {
  double least_y = 1e9, pierce_h = 0;
  for (const control::TraceSample& s : r.trace) {
    if (s.torch.phase == control::TorchPhase::Piercing) pierce_h = height(s);
    if (s.torch.phase == control::TorchPhase::Cutting && s.commanded[0] > 150 && s.commanded[0] < 250 &&
        s.commanded[1] < 150)
      least_y = std::min(least_y, s.commanded[1]);
  }
  return {pierce_h, least_y};
}

TEST(CutChartScenario, TheSelectedMaterialIsUsedWhenTheProgramSelectsNone) {
  const Bench b;
  const std::string prog = b.program("plain.ngc",
                                     "G21 G90 G17 G40 G64 P0.1\nG0 Z15\nG0 X90 Y90\nM190\nG42\n"
                                     "G1 X100 Y100 F3500\nX300\nY220\nX100\nY100\nG40\nM191\nM2\n");
  const ChartRun r = run(b.table(3), prog);  // [cut_chart] material = 3
  ASSERT_TRUE(r.opened.accepted) << r.opened.message;
  ASSERT_TRUE(r.finished);
  EXPECT_NEAR(pierce_and_bottom(r).first, 3.2, 0.01);
  EXPECT_NEAR(pierce_and_bottom(r).second, 100 - 0.6, 0.01);
  // The HMI's selection (kept in the store) comes before the profile's.
  std::string error;
  ASSERT_TRUE(store::CutChartStore::open(b.db(), &error)->select(10, "hmi", &error)) << error;
  const ChartRun s = run(b.table(3), prog);
  ASSERT_TRUE(s.opened.accepted) << s.opened.message;
  ASSERT_TRUE(s.finished);
  EXPECT_NEAR(pierce_and_bottom(s).first, 4.5, 0.01);
  EXPECT_NEAR(pierce_and_bottom(s).second, 100 - 0.9, 0.01);
}

}  // namespace
}  // namespace opencnc::controller::test
