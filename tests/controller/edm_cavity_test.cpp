// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated EDM's cavity through the whole controller on configs/edm-5axis.toml: a finishing
// pass with a circle orbit widens the cavity by the orbit's radius (measured from the trace) plus
// the condition's side gap; the electrode's wear leaves the cavity shallower than the program.
#include <gtest/gtest.h>

#include <algorithm>
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

namespace opencnc::control::test {
namespace {

/// The EDM with a smaller electrode (5 mm²: four times the depth per discharge) so that a burn of
/// a few hundredths takes seconds of virtual time.
config::MachineProfile edm_machine() {
  const std::vector<std::string> sets = {"edm.sim.electrode_area_mm2=5"};
  return loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml", sets));
}

/// Machine on and every axis homed on its switches (the EDM's steppers know nothing at power-up).
bool on_and_homed(SimRig& rig) {
  if (!rig.request(Request::simple(CommandKind::MachineOn)).accepted) return false;
  if (!rig.request(Request::set_mode(Mode::Manual)).accepted || !rig.request(Request::home()).accepted)
    return false;
  return rig.run_until(
      [&] { return rig.status().servo.state == State::Idle && rig.status().servo.all_homed; }, 60000);
}

/// Every trace sample of the run.
class Samples final : public ControllerObserver {
 public:
  void on_trace(const TraceSample& s, const TraceContext&) override { all.push_back(s); }
  std::vector<TraceSample> all;
};

struct Burnt {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<Samples> samples;
  bool finished = false;
  double oversize_before_orbit_mm = -1;  ///< the cavity when condition 2 came on
};

/// Runs `text` to its end on `profile`.
Burnt run(const std::string& text, const config::MachineProfile& profile) {
  Burnt r;
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-edm-cavity-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  Diagnostics d;
  r.rig = std::make_unique<SimRig>(profile, GcodeProgramSource::create(profile, d));
  r.samples = std::make_shared<Samples>();
  r.rig->controller().attach(r.samples, ObserverOptions{0, true});
  r.rig->step();
  EXPECT_TRUE(on_and_homed(*r.rig));
  EXPECT_TRUE(r.rig->request(Request::set_mode(Mode::Auto)).accepted);
  const Outcome opened = r.rig->request(Request::open(path), 100000);
  EXPECT_TRUE(opened.accepted) << opened.message;
  if (!opened.accepted) return r;
  EXPECT_TRUE(r.rig->request(Request::simple(CommandKind::CycleStart)).accepted);
  r.finished = r.rig->run_until(
      [&] {
        const EdmStatus& e = r.rig->status().servo.edm;
        const machine::SimEdmProcess& sim = r.rig->machine().edm();
        if (e.condition == 2 && r.oversize_before_orbit_mm < 0)
          r.oversize_before_orbit_mm = sim.cavity_oversize_mm();
        return !r.rig->status().run_active && r.rig->status().servo.state == State::Idle;
      },
      60000);
  return r;
}

TEST(EdmCavity, AFinishingOrbitWidensTheCavityByItsRadiusPlusTheSideGap) {
  // Roughing without an orbit (condition 1, side gap 40 µm), then condition 2's circle growing
  // to 50 µm in five turns (side gap 25 µm) on 5 mm² of electrode: the finish burns a few turns
  // at full size.
  const Burnt r =
      run("G21 G90\nG0 Z-19.97\nM180 P1\nG1 Z-20.03 F60\nM180 P2\nG1 Z-20.15 F30\nM181\nG0 Z0\nM2\n",
          edm_machine());
  ASSERT_TRUE(r.finished);
  // The orbit's radius from the trace: the commanded X, Y's farthest from the burn's centre (0, 0)
  // while condition 2 burnt.
  double radius = 0;
  for (const TraceSample& s : r.samples->all)
    if (s.edm.condition == 2 && s.edm.generator)
      radius = std::max(radius, std::hypot(s.commanded[Axis::X], s.commanded[Axis::Y]));
  EXPECT_NEAR(radius, 0.05, 1e-6);
  const machine::SimEdmProcess& sim = r.rig->machine().edm();
  EXPECT_NEAR(r.oversize_before_orbit_mm, 0.040, 1e-12);  // the roughing's side gap alone
  // Finished: the orbit plus the finishing side gap in every direction, within the steppers'
  // 0.625 µm steps and the orbit's sampling.
  EXPECT_NEAR(sim.cavity_oversize_mm(), radius + 0.025, 0.002);
  for (int k = 0; k < machine::SimEdmProcess::kSides; ++k)
    EXPECT_NEAR(sim.side_wall_mm(k), radius + 0.025, 0.002) << "direction " << k;
  EXPECT_EQ(sim.cavity_oversize_max_mm(), sim.cavity_oversize_mm());
}

TEST(EdmCavity, TheElectrodesWearLeavesTheCavityShallowerThanTheProgram) {
  // The same burn, 60 µm below the surface, with an electrode that does not wear and with one that
  // loses a fifth of the depth (condition 1's ratio raised to 0.2).
  const std::string program = "G21 G90\nG0 Z-19.97\nM180 P1\nG1 Z-20.06 F60\nM181\nG0 Z0\nM2\n";
  config::MachineProfile p = edm_machine();
  p.edm.sim.conditions[0].electrode_wear_ratio = 0;
  const Burnt sharp = run(program, p);
  p.edm.sim.conditions[0].electrode_wear_ratio = 0.2;
  const Burnt worn = run(program, p);
  ASSERT_TRUE(sharp.finished);
  ASSERT_TRUE(worn.finished);
  EXPECT_EQ(sharp.rig->machine().edm().electrode_wear_mm(), 0.0);
  const double depth = worn.rig->machine().edm().depth_mm(),
               wear = worn.rig->machine().edm().electrode_wear_mm();
  EXPECT_NEAR(wear, 0.2 * depth, 1e-9);  // each discharge's depth wears a fifth of it off the electrode
  EXPECT_GT(wear, 0.01);
  // The holder went to the program's depth both times: the worn electrode's cavity is its lost
  // length shallower (within the gap's spread at the end: the servo holds it to a few µm).
  EXPECT_NEAR(sharp.rig->machine().edm().depth_mm() - depth, wear, 0.001);
}

}  // namespace
}  // namespace opencnc::control::test
