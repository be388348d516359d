// SPDX-License-Identifier: GPL-3.0-or-later
// The tool guard on the simulated hmc-toolcheck: the typo is caught before the first cut (at
// the start, and at a tool change when it is typed while the program runs), wear within the
// band passes, accept and restore both let the program go on, M160 checks on demand.
#include <gtest/gtest.h>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/toolguard/tool_guard.hpp"
#include "opencnc/tools/tool_text.hpp"
#include "scenario.hpp"
#include "temp_db.hpp"

namespace opencnc::controller::test {
namespace {

using tools::Param;

// Three tools; the changer quick so the runs stay short in virtual time.
const char* kProgram =
    "G21 G90\n"
    "T1 M6\n"
    "G43 H1\n"
    "G0 X0 Y0 Z10\n"
    "G1 Z0 F3000\n"
    "T3 M6\n"
    "G43 H3\n"
    "G0 Z10\n"
    "G1 Z0 F3000\n"
    "M2\n";

class Guarded {
 public:
  explicit Guarded(std::vector<std::string> extra = {}) {
    std::vector<std::string> sets = {"tool_guard.store=\"" + db_.path() + "\"",
                                     "tool_changer.sim.prepare_time_s=0.05",
                                     "tool_changer.sim.change_time_s=0.1"};
    sets.insert(sets.end(), extra.begin(), extra.end());
    std::string error;
    store_ = store::ToolStore::open(db_.path(), &error);
    EXPECT_NE(store_, nullptr) << error;
    Diagnostics d;
    std::string text;
    read_file(std::string(OPENCNC_SOURCE_DIR) + "/configs/hmc-toolcheck.tbl", text, nullptr);
    const auto set = tools::from_linuxcnc(tools::ToolTable::parse(text, "hmc-toolcheck.tbl", d), "hmc", d);
    EXPECT_TRUE(set && store_->write(*set, "test", "import", &error)) << error;
    EXPECT_TRUE(store_->backup("test", "backup", &error)) << error;
    const config::ProfileLoad load =
        config::load_profile(std::string(OPENCNC_SOURCE_DIR) + "/configs/hmc-toolcheck.toml", sets);
    for (const auto& x : load.diagnostics.items()) ADD_FAILURE() << x.format();
    profile_ = *load.profile;
    scenario_ = std::make_unique<Scenario>(profile_);  // the guard as every front end sets it up
    cursor_ = std::make_unique<EventCursor>(scenario_->rig().controller().events(), true);
    scenario_->on(control::Mode::Auto);
  }
  Scenario& s() { return *scenario_; }
  store::ToolStore& store() { return *store_; }
  void set(int t, int d, Param p, double v) {
    std::string error;
    ASSERT_TRUE(store_->set(t, d, p, v, "hmi", &error)) << error;
  }
  /// The notes logged so far with `code`.
  std::vector<std::string> notes(const std::string& code) {
    std::vector<std::string> out;
    for (const ControllerEvent& e : cursor_->next()) {
      if (e.kind == ControllerEventKind::Note && e.code == code) out.push_back(e.text);
    }
    return out;
  }

 private:
  store::test::TempDb db_;
  std::shared_ptr<store::ToolStore> store_;
  config::MachineProfile profile_;
  std::unique_ptr<Scenario> scenario_;
  std::unique_ptr<EventCursor> cursor_;
};

TEST(ToolGuardScenario, TheTypoIsCaughtBeforeTheFirstCutNamingToolAndEdge) {
  Guarded g;
  TempProgram p("demo.ngc", kProgram);
  g.set(3, 1, Param::Length1, 105.25);  // 150.25 typed as 105.25
  g.s().must(Request::open(p.path()));
  const Pose before = g.s().status().servo.commanded;
  const Outcome o = g.s().ask(Request::simple(control::CommandKind::CycleStart));
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.refusal, control::Refusal::FeatureCheck);
  EXPECT_NE(o.message.find("T3 D1 length1: backup 150.25, live 105.25"), std::string::npos) << o.message;
  g.s().ticks(200);
  EXPECT_FALSE(g.s().status().run_active);
  EXPECT_EQ(g.s().status().servo.commanded, before);  // nothing moved
}

TEST(ToolGuardScenario, WearWithinTheBandPasses) {
  Guarded g;
  TempProgram p("demo.ngc", kProgram);
  g.set(3, 1, Param::WearLength1, -0.08);
  ASSERT_TRUE(g.s().run_file(p.path(), 60000)) << g.s().message();
  EXPECT_NEAR(g.s().status().servo.commanded[Axis::Z], 150.25 - 0.08, 1e-9);  // effective length
}

// Typed while the program runs: the program holds at T3's change, before T3 cuts.
void hold_at_tool_change(Guarded& g, const std::string& choice, double expected_z) {
  TempProgram p("demo.ngc", kProgram);
  g.s().must(Request::open(p.path()));
  g.s().must(Request::simple(control::CommandKind::CycleStart));
  g.set(3, 1, Param::Length1, 105.25);
  ASSERT_TRUE(
      g.s().until([&] { return g.s().status().wait_text.find("tool-guard") != std::string::npos; }, 40000))
      << g.s().status().wait_text;
  const auto held = g.notes("tools.guard-hold");
  ASSERT_EQ(held.size(), 1u);
  EXPECT_NE(held[0].find("held before T3 cuts"), std::string::npos) << held[0];
  EXPECT_NE(held[0].find("T3 D1 length1: backup 150.25, live 105.25"), std::string::npos) << held[0];
  const Pose at = g.s().status().servo.commanded;
  g.s().ticks(500);
  EXPECT_EQ(g.s().status().servo.commanded, at);     // it stands there
  EXPECT_TRUE(g.notes("tools.guard-hold").empty());  // said once
  g.s().must(Request::feature("tool-guard", choice));
  ASSERT_TRUE(g.s().until([&] { return !g.s().status().run_active; }, 40000));
  EXPECT_EQ(g.s().status().runs_finished, 1u);
  EXPECT_NEAR(g.s().status().servo.commanded[Axis::Z], expected_z, 1e-9);
}

TEST(ToolGuardScenario, AHoldAtTheToolChangeEndsWithAccept) {
  Guarded g;
  hold_at_tool_change(g, "accept", 105.25);
  EXPECT_EQ(g.store().backups().size(), 2u);  // the live values are the new backup
  EXPECT_EQ(g.store().backup_set(2)->edge(3, 1)->get(Param::Length1), 105.25);
}

TEST(ToolGuardScenario, AHoldAtTheToolChangeEndsWithRestore) {
  Guarded g;
  hold_at_tool_change(g, "restore", 150.25);
  EXPECT_EQ(g.store().live()->edge(3, 1)->get(Param::Length1), 150.25);
  EXPECT_EQ(g.store().backups().size(), 1u);
}

TEST(ToolGuardScenario, RestoreAfterARefusedStartLetsTheProgramRun) {
  Guarded g;
  TempProgram p("demo.ngc", kProgram);
  g.set(5, 2, Param::Radius, 0.8);
  g.s().must(Request::open(p.path()));
  EXPECT_FALSE(g.s().ask(Request::simple(control::CommandKind::CycleStart)).accepted);
  g.s().must(Request::feature("tool-guard", "restore"));
  EXPECT_EQ(*g.store().live(), *g.store().backup_set(1));
  ASSERT_TRUE(g.s().start_and_finish(60000)) << g.s().message();
}

TEST(ToolGuardScenario, M160ChecksOnDemand) {
  Guarded g({"tool_guard.check=\"off\""});
  TempProgram p("m160.ngc", "G21 G90\nG0 X1\nM160\nG0 X2\nM2\n");
  ASSERT_TRUE(g.s().run_file(p.path(), 20000)) << g.s().message();
  g.set(1, 1, Param::Radius, 30);
  const Outcome o = g.s().ask(Request::open(p.path()));  // the preflight runs M160 too
  EXPECT_FALSE(o.accepted);
  ASSERT_FALSE(o.diagnostics.items().empty());
  EXPECT_EQ(o.diagnostics.items()[0].code, "gcode.tool-guard-check");
  EXPECT_NE(g.s().message().find("m160.ngc:3:1: error: M160: the live tool table differs"), std::string::npos)
      << g.s().message();
  EXPECT_NE(g.s().message().find("T1 D1 radius: backup 31.5, live 30"), std::string::npos) << g.s().message();
}

TEST(ToolGuardScenario, TheProfileSaysWhenToCheck) {
  Guarded g({"tool_guard.check=\"tool-change\""});
  TempProgram p("demo.ngc", kProgram);
  g.set(5, 1, Param::Length1, 139.225);  // T5 is not used: the program runs
  ASSERT_TRUE(g.s().run_file(p.path(), 60000)) << g.s().message();
}

}  // namespace
}  // namespace opencnc::controller::test
