// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated EDM's cavity through the whole controller on configs/edm-5axis.toml: a finishing
// pass with a circle orbit widens the cavity by the orbit's radius (measured from the trace) plus
// the condition's side gap; the electrode's wear leaves the cavity shallower than the program; the
// true electrode a tool change mounts burns where it really is: off by its error unmeasured, where
// the program says once electrode setting has measured it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "edm_rig.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/edm/electrode_setting.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::controller::test {
namespace {

config::MachineProfile edm_machine() {
  return edm_profile();
}

/// Positions from the simulated steppers are whole steps (0.625 µm) and the machine's zero, homed
/// on its switches, lies within a step of the switch: two steps is as close as a centre or an
/// offset measured on the machine can be asked to come.
constexpr double kTwoSteps = 2 * 0.000625 + 1e-9;

struct Burnt {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<Samples> samples;
  bool finished = false;
  double oversize_before_orbit_mm = -1;  ///< the cavity when condition 2 came on
};

/// Runs `text` to its end on `profile`.
Burnt run(const std::string& text, const config::MachineProfile& profile) {
  Burnt r;
  const std::string path = write_program(text, "opencnc-edm-cavity");
  Diagnostics d;
  r.rig = std::make_unique<SimRig>(profile, *features::machine_setup(profile, d));
  r.samples = std::make_shared<Samples>();
  r.rig->controller().attach(r.samples, ObserverOptions{0, true});
  r.rig->step();
  EXPECT_TRUE(on_and_homed(*r.rig));
  EXPECT_TRUE(r.rig->request(Request::set_mode(control::Mode::Auto)).accepted);
  const Outcome opened = r.rig->request(Request::open(path), 100000);
  EXPECT_TRUE(opened.accepted) << opened.message;
  if (!opened.accepted) return r;
  EXPECT_TRUE(r.rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  r.finished = r.rig->run_until(
      [&] {
        const control::EdmStatus& e = r.rig->status().servo.edm;
        const machine::SimEdmProcess& sim = r.rig->machine().edm();
        if (e.condition == 2 && r.oversize_before_orbit_mm < 0)
          r.oversize_before_orbit_mm = sim.cavity_oversize_mm();
        return !r.rig->status().run_active && r.rig->status().servo.state == control::State::Idle;
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
  for (const control::TraceSample& s : r.samples->all)
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

/// The EDM with its electrode feature and a tool table in memory (tool 1: D1.6 as the profile's
/// table, offsets `table`), the program source reading it: the operator's way, an electrode
/// mounted by MDI, measured on the reference sphere, then the burn.
struct ElectrodeRig {
  ElectrodeRig(const config::MachineProfile& profile, const Vec3& table) {
    tools::ToolTable t;
    tools::ToolEntry e;
    e.tool = 1;
    e.pocket = 1;
    e.diameter = 1.6;
    for (int i = 0; i < 3; ++i) e.offset[i] = table[static_cast<std::size_t>(i)];
    t.add(e);
    tools = std::make_shared<tools::MemoryToolTable>(std::move(t));
    Diagnostics d;
    auto machine = features::machine_setup(
        profile, d, controller::MachineSetup::Options::with_tools(tools));  // the test's tool table
    EXPECT_TRUE(machine);
    rig = std::make_unique<SimRig>(profile, *machine);
    feature = std::dynamic_pointer_cast<edm::ElectrodeSetting>(machine->feature("electrode"));
    EXPECT_TRUE(feature);
    rig->step();
    EXPECT_TRUE(on_and_homed(*rig));
  }
  bool idle() {
    return rig->run_until(
        [&] { return !rig->status().run_active && rig->status().servo.state == control::State::Idle; },
        100000);
  }
  void mdi(const std::string& line) {
    EXPECT_TRUE(rig->request(Request::set_mode(control::Mode::Mdi)).accepted);
    const Outcome o = rig->request(Request::mdi(line), 100000);
    EXPECT_TRUE(o.accepted) << o.message;
    EXPECT_TRUE(idle());
  }
  edm::ElectrodeResult measure(int tool) {
    const Outcome o = rig->request(Request::feature("electrode", "measure", edm::ElectrodeMeasure{tool}));
    EXPECT_TRUE(o.accepted) << o.message;
    EXPECT_TRUE(rig->run_until([&] { return feature->phase() == edm::ElectrodePhase::Idle; }, 100000));
    return feature->last().value_or(edm::ElectrodeResult{});
  }
  /// Opens `text` (written to a file for the test) and starts it.
  void start(const std::string& text, const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("opencnc-edm-electrode-" + name);
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "p.ngc").string();
    std::ofstream(path) << text;
    EXPECT_TRUE(rig->request(Request::set_mode(control::Mode::Auto)).accepted);
    const Outcome opened = rig->request(Request::open(path), 100000);
    EXPECT_TRUE(opened.accepted) << opened.message;
    EXPECT_TRUE(rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  }
  /// … and runs it to its end.
  bool run(const std::string& text, const std::string& name) {
    start(text, name);
    return idle() && rig->status().runs_finished > 0;
  }
  const machine::SimEdmProcess& sim() { return rig->machine().edm(); }

  std::shared_ptr<tools::MemoryToolTable> tools;
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<edm::ElectrodeSetting> feature;
};

/// Tool 1 burns 60 µm below the surface at X0 Y0 with its table offsets (G43).
constexpr const char* kBurnWithG43 =
    "G21 G90\nG43 H1\nG0 X0 Y0 Z-19.8\nM180 P1\nG1 Z-20.06 F60\nM181\nG0 Z0\nM2\n";

TEST(EdmElectrode, AnUnmeasuredElectrodeBurnsOffByItsErrorAMeasuredOneWhereProgrammed) {
  config::MachineProfile p = edm_machine();
  p.edm.sim.conditions[0].electrode_wear_ratio = 0;  // the depth is the electrode's position alone
  // The reference: tool 1's electrode exactly as its table entry (all offsets 0).
  ElectrodeRig exact(p, {0, 0, 0});
  exact.mdi("T1 M6");
  EXPECT_EQ(exact.rig->machine().mounted_tool(), 1);
  ASSERT_TRUE(exact.run(kBurnWithG43, "exact"));
  // The electrode in pocket 1 is really 30 µm off in X, −20 µm in Y and 50 µm longer (a 0.8 mm
  // ball tip, as the table's D1.6 says): unknown to the controller until measured.
  const Vec3 truth{0.03, -0.02, 0.05};
  p.sim_electrodes = {machine::SimElectrode{1, truth, 0.8}};
  ElectrodeRig unmeasured(p, {0, 0, 0});
  unmeasured.mdi("T1 M6");
  EXPECT_EQ(unmeasured.rig->machine().electrode().offset, truth) << "the change mounted tool 1's electrode";
  ASSERT_TRUE(unmeasured.run(kBurnWithG43, "unmeasured"));
  ElectrodeRig measured(p, {0, 0, 0});
  measured.mdi("T1 M6");
  const edm::ElectrodeResult m = measured.measure(1);
  ASSERT_TRUE(m.ok) << m.message;
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(m.offset[i], truth[i], kTwoSteps) << "axis " << i;
  ASSERT_TRUE(measured.run(kBurnWithG43, "measured"));

  const double depth = exact.sim().depth_mm();
  EXPECT_GT(depth, 0.05);
  // Unmeasured: the longer electrode burns 50 µm deeper (within the gap's spread at the end of the
  // servo's two runs), the cavity 30 µm toward −X and 20 µm toward +Y of where the program put it.
  EXPECT_NEAR(unmeasured.sim().depth_mm() - depth, truth[2], 0.002);
  EXPECT_NEAR(unmeasured.sim().cavity_centre_mm(0), -truth[0], kTwoSteps);
  EXPECT_NEAR(unmeasured.sim().cavity_centre_mm(1), -truth[1], kTwoSteps);
  // Measured and stored: G43 moves the holder by the measured offsets, the cavity is the program's.
  EXPECT_NEAR(measured.sim().depth_mm(), depth, 0.002);
  EXPECT_NEAR(measured.sim().cavity_centre_mm(0), 0, kTwoSteps);
  EXPECT_NEAR(measured.sim().cavity_centre_mm(1), 0, kTwoSteps);
  EXPECT_NEAR(exact.sim().cavity_centre_mm(0), 0, kTwoSteps);
}

TEST(EdmElectrode, AWornElectrodeReplacedMidJobFinishesTheCavityAsAnUninterruptedJob) {
  config::MachineProfile p = edm_machine();
  p.sim_electrodes = {machine::SimElectrode{1, {0.02, -0.01, 0.04}, 0.8}};
  // The uninterrupted job: the electrode measured, the burn to its end.
  ElectrodeRig whole(p, {0, 0, 0});
  whole.mdi("T1 M6");
  ASSERT_TRUE(whole.measure(1).ok);
  ASSERT_TRUE(whole.run(kBurnWithG43, "whole"));

  // The same job stopped by the operator half way down (feed hold, abort), the electrode lifted
  // out of the cavity (MDI), a new one put in (other offsets: 50 µm off in X and Z), measured on
  // the sphere and stored, and the job resumed where it stopped.
  ElectrodeRig changed(p, {0, 0, 0});
  changed.mdi("T1 M6");
  ASSERT_TRUE(changed.measure(1).ok);
  changed.start(kBurnWithG43, "changed");
  ASSERT_TRUE(changed.rig->run_until([&] { return changed.sim().depth_mm() > 0.035; }, 100000));
  ASSERT_TRUE(changed.rig->request(Request::simple(control::CommandKind::FeedHold)).accepted);
  ASSERT_TRUE(changed.rig->run_until(
      [&] {
        return changed.rig->status().servo.state == control::State::Held &&
               changed.rig->status().servo.path_velocity == 0;
      },
      5000));
  ASSERT_TRUE(changed.rig->request(Request::simple(control::CommandKind::Abort)).accepted);
  ASSERT_TRUE(changed.idle());
  ASSERT_TRUE(changed.feature->stop().has_value());
  const double worn_mm = changed.sim().electrode_wear_mm();
  EXPECT_GT(worn_mm, 0.0);
  changed.mdi("G53 G0 Z-10");  // out of the cavity
  const Vec3 fresh{0.07, -0.01, 0.09};
  changed.rig->machine().replace_electrode(1, fresh, 0.8);
  const edm::ElectrodeResult m = changed.measure(1);
  ASSERT_TRUE(m.ok) << m.message;
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(m.offset[i], fresh[i], kTwoSteps) << "axis " << i;
  const std::uint64_t finished = changed.rig->status().runs_finished;
  const Outcome resumed = changed.rig->request(Request::feature("electrode", "resume"));
  ASSERT_TRUE(resumed.accepted) << resumed.message;
  ASSERT_TRUE(changed.rig->run_until([&] { return changed.rig->status().runs_finished > finished; }, 200000));
  ASSERT_TRUE(changed.idle());
  EXPECT_FALSE(changed.feature->stop().has_value()) << "the job reached its end";

  // The cavity (the simulated work's ground truth, the report's cavity_depth_mm): as deep as the
  // uninterrupted job's within 2 µm (the servo's gap at the end and the two electrodes' wear, 1 %
  // of their depths), centred where the program put it, its walls where the uninterrupted ones are.
  const double depth = whole.sim().depth_max_mm();
  EXPECT_GT(depth, 0.07);
  EXPECT_NEAR(changed.sim().depth_max_mm(), depth, 0.002);
  EXPECT_NEAR(changed.sim().cavity_centre_mm(0), whole.sim().cavity_centre_mm(0), kTwoSteps);
  EXPECT_NEAR(changed.sim().cavity_centre_mm(1), whole.sim().cavity_centre_mm(1), kTwoSteps);
  for (int k = 0; k < machine::SimEdmProcess::kSides; ++k)
    EXPECT_NEAR(changed.sim().side_wall_mm(k), whole.sim().side_wall_mm(k), 0.002) << "direction " << k;
  // A fresh electrode burnt the rest: it lost less than the uninterrupted job's one electrode.
  EXPECT_LT(changed.sim().electrode_wear_mm(), whole.sim().electrode_wear_mm());
}

}  // namespace
}  // namespace opencnc::controller::test
