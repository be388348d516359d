// SPDX-License-Identifier: GPL-3.0-or-later
// Load protection through the whole controller on the broach: sharp cuts pass, a worn cutter holds
// the feed on the helix, an overload stops the run on the helix and lifts the cutter in X.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

namespace opencnc::controller::test {
namespace {

config::MachineProfile broach() {
  return control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml"));
}

std::string write_program(const std::string& text) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-broach-load-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  return path;
}

/// Every period: the load, and C's command against the constant law (engaged at Z −10, C 0).
class LoadWatch final : public ControllerObserver {
 public:
  void on_status(const ControllerStatus& s) override {
    max_kn = std::max(max_kn, s.servo.load_kn);
    if (s.servo.coupling.kind == motion::CouplingKind::Off) return;
    const double law = s.servo.coupling.slave_origin +
                       360.0 * (s.servo.commanded[Axis::Z] - s.servo.coupling.master_origin) / kPitch;
    helix_error_deg = std::max(helix_error_deg, std::fabs(s.servo.commanded[Axis::C] - law));
  }
  static constexpr double kPitch = 600;
  double max_kn = -1e9, helix_error_deg = 0;
};

/// Strokes through the first 120 mm of the bore at 50 mm/s, X fed to each depth before the stroke.
std::string strokes(std::initializer_list<double> depths) {
  std::string p = "G21 G90 G94 G64 P0.005\nG0 X-0.5\nG0 Z-10 C0\nM171 P600\n";
  for (const double d : depths) {
    p += "G1 X" + std::to_string(d) + " F60\nG1 Z120 F3000\nG1 X" + std::to_string(d - 0.5) + "\nG0 Z-10\n";
  }
  return p + "M175\nM2\n";
}

struct LoadRun {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<LoadWatch> watch = std::make_shared<LoadWatch>();
  std::unique_ptr<EventCursor> events;

  explicit LoadRun(const std::string& program, double dull = 1.0) {
    const config::MachineProfile p = broach();
    Diagnostics d;
    rig = std::make_unique<SimRig>(p, *features::machine_setup(p, d));
    rig->controller().attach(watch, ObserverOptions{0.001, false});
    events = std::make_unique<EventCursor>(rig->controller().events());
    rig->machine().set_tool_dull(dull);
    rig->step();
    EXPECT_TRUE(rig->request(Request::simple(control::CommandKind::MachineOn)).accepted);
    EXPECT_TRUE(rig->request(Request::set_mode(control::Mode::Auto)).accepted);
    EXPECT_TRUE(rig->request(Request::open(write_program(program)), 100000).accepted);
    EXPECT_TRUE(rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  }
  /// The load guard's actions and notes seen since the last call.
  std::vector<control::LoadAction> actions(std::vector<std::string>* notes = nullptr) {
    std::vector<control::LoadAction> out;
    for (const ControllerEvent& e : events->next()) {
      if (e.kind == ControllerEventKind::Servo && e.servo.kind == control::EventKind::LoadGuard)
        out.push_back(static_cast<control::LoadAction>(e.servo.action));
      if (notes != nullptr && e.kind == ControllerEventKind::Note && e.code == "control.load")
        notes->push_back(e.text);
    }
    return out;
  }
  bool idle() const { return !rig->status().run_active && rig->status().servo.state == control::State::Idle; }
};

TEST(BroachLoad, SharpCutsPassUntouched) {
  LoadRun r(strokes({0.1, 0.2}));
  ASSERT_TRUE(r.rig->run_until([&] { return r.idle(); }, 30000));
  EXPECT_TRUE(r.actions().empty());
  // 0.1 mm at 3 m/min: 2500 × 10 × 0.1 × 1.15 N, the cell's noise on top.
  EXPECT_NEAR(r.watch->max_kn, 2.875, 0.05);
  EXPECT_EQ(r.rig->status().servo.load_action, control::LoadAction::None);
}

TEST(BroachLoad, AWornCutterHoldsTheFeedOnTheHelix) {
  LoadRun r(strokes({0.1}), 1.8);  // 5.2 kN: above the hold level (4), below the retract (6)
  std::vector<std::string> notes;
  ASSERT_TRUE(r.rig->run_until([&] { return r.rig->status().servo.state == control::State::Held; }, 10000));
  ASSERT_TRUE(r.rig->run_until([&] { return r.rig->status().servo.path_velocity == 0; }, 1000));
  r.rig->run(20);
  const control::ServoStatus s = r.rig->status().servo;
  EXPECT_EQ(r.actions(&notes), std::vector<control::LoadAction>{control::LoadAction::Hold});
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("above the hold level 4 kN: feed hold"), std::string::npos) << notes[0];
  EXPECT_EQ(s.load_action, control::LoadAction::Hold);
  EXPECT_TRUE(s.run_active);
  EXPECT_NE(s.coupling.kind, motion::CouplingKind::Off);  // the coupling holds through the stop
  EXPECT_GT(s.commanded[Axis::Z], 0.0);                   // stopped inside the bore
  EXPECT_LT(r.watch->helix_error_deg, 1e-9);
  EXPECT_NEAR(s.commanded[Axis::X], 0.1, 1e-9);  // the cutter stays where it was
  // The operator changes nothing and resumes: the worn cutter holds the feed again.
  ASSERT_TRUE(r.rig->request(Request::simple(control::CommandKind::Resume)).accepted);
  ASSERT_TRUE(r.rig->run_until(
      [&] { return r.actions() == std::vector<control::LoadAction>{control::LoadAction::Hold}; }, 5000));
  ASSERT_TRUE(r.rig->request(Request::simple(control::CommandKind::Abort)).accepted);
  ASSERT_TRUE(r.rig->run_until([&] { return r.idle(); }, 5000));
}

TEST(BroachLoad, AnOverloadStopsOnTheHelixAndLiftsTheCutter) {
  LoadRun r(strokes({0.3}));  // 0.3 mm at once: 8.6 kN, above the retract level (6)
  std::vector<std::string> notes;
  std::vector<control::LoadAction> seen;
  ASSERT_TRUE(r.rig->run_until(
      [&] {
        for (const control::LoadAction a : r.actions(&notes)) seen.push_back(a);
        return !seen.empty() && seen.back() == control::LoadAction::Lifted;
      },
      10000));
  EXPECT_EQ(seen,
            (std::vector<control::LoadAction>{control::LoadAction::Retract, control::LoadAction::Lifted}));
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("above the retract level 6 kN"), std::string::npos) << notes[0];
  r.rig->run(5);
  const control::ServoStatus s = r.rig->status().servo;
  EXPECT_FALSE(r.rig->status().run_active);  // the run was stopped
  EXPECT_EQ(s.state, control::State::Idle);
  EXPECT_EQ(s.load_action, control::LoadAction::Lifted);
  EXPECT_NEAR(s.commanded[Axis::X], 0.3 - 0.5, 1e-9);  // lifted off the wall by retract_lift
  EXPECT_GT(s.commanded[Axis::Z], 0.0);
  EXPECT_LT(r.watch->helix_error_deg, 1e-9);  // C on the law until the path rested
  // The lift moved neither Z nor C: the cutter is still on the helix, in the groove's angle.
  const double z = s.commanded[Axis::Z];
  EXPECT_NEAR(s.commanded[Axis::C], 360.0 * (z + 10) / 600, 1e-9);
}

}  // namespace
}  // namespace opencnc::controller::test
