// SPDX-License-Identifier: GPL-3.0-or-later
// Electrode setting through the whole controller on a simulated machine whose probe input is an
// electrode touching a reference sphere: the offsets measured to the micrometre and stored in the
// tool table; a missing sphere, a sphere elsewhere and touches off a sphere refused with nothing
// stored; a worn electrode replaced in the middle of a job, which then goes on where it stopped.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/edm/b_axis_fit.hpp"
#include "opencnc/edm/electrode_setting.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

config::MachineProfile edm_profile(const std::vector<std::string>& sets = {}) {
  const config::ProfileLoad load =
      config::load_profile(OPENCNC_SOURCE_DIR "/tests/scenario/edm-setting.toml", sets);
  for (const Diagnostic& d : load.diagnostics.items()) ADD_FAILURE() << d.format();
  EXPECT_TRUE(load.profile.has_value());
  return *load.profile;
}

/// Tool 1: a 50 mm electrode with a point tip; tool 2: 40 mm with a 3 mm ball (diameter 6).
std::shared_ptr<tools::MemoryToolTable> electrode_table() {
  tools::ToolTable t;
  tools::ToolEntry e1;
  e1.tool = 1;
  e1.pocket = 1;
  e1.offset[2] = 50;
  t.add(e1);
  tools::ToolEntry e2;
  e2.tool = 2;
  e2.pocket = 2;
  e2.offset[2] = 40;
  e2.diameter = 6;
  t.add(e2);
  return std::make_shared<tools::MemoryToolTable>(std::move(t));
}

/// The whole controller with the electrode feature, on `sim` (the simulated machine's profile)
/// while the feature and the program source use `profile`.
struct Rig {
  /// The features `profile` calls for (as every front end sets them up) on the test's tool table,
  /// on the simulated machine of `sim` (the truth the profile may not know).
  explicit Rig(const config::MachineProfile& profile, const config::MachineProfile& sim)
      : tools(electrode_table()), machine(set_up(profile, tools)), scenario(sim, machine->source()) {
    feature = std::dynamic_pointer_cast<edm::ElectrodeSetting>(machine->feature("electrode"));
    EXPECT_TRUE(feature);
    machine->install(scenario.rig().controller());
    scenario.must(Request::simple(control::CommandKind::MachineOn));
  }
  explicit Rig(const config::MachineProfile& profile) : Rig(profile, profile) {}

  static std::unique_ptr<MachineSetup> set_up(const config::MachineProfile& p,
                                              std::shared_ptr<tools::MemoryToolTable> t) {
    Diagnostics d;
    auto m = features::machine_setup(p, d, controller::MachineSetup::Options::with_tools(std::move(t)));
    EXPECT_TRUE(m) << (d.items().empty() ? "" : d.items()[0].format());
    return m;
  }
  /// Measures `tool`; the result once the feature is idle again.
  edm::ElectrodeResult measure(int tool) {
    scenario.must(Request::feature("electrode", "measure", edm::ElectrodeMeasure{tool}));
    EXPECT_TRUE(scenario.until([&] { return feature->phase() == edm::ElectrodePhase::Idle; }, 60000));
    EXPECT_TRUE(feature->last().has_value());
    return feature->last().value_or(edm::ElectrodeResult{});
  }
  Vec3 table_offset(int tool) const {
    const tools::ToolEntry* e = tools->snapshot()->tool(tool);
    return {e->offset[0], e->offset[1], e->offset[2]};
  }

  std::shared_ptr<tools::MemoryToolTable> tools;
  std::unique_ptr<MachineSetup> machine;
  Scenario scenario;
  std::shared_ptr<edm::ElectrodeSetting> feature;
};

TEST(ElectrodeSetting, MeasuresAnOffsetElectrodeWithinAMicrometreAndStoresIt) {
  Rig r(edm_profile());
  const Vec3 truth{0.2, -0.1, 50.5};  // tool 1 is off its table entry by (0.2, −0.1, 0.5)
  r.scenario.sim().set_electrode(truth, 0);
  const edm::ElectrodeResult m = r.measure(1);
  ASSERT_TRUE(m.ok) << m.message;
  ASSERT_EQ(m.touched.size(), 5u) << "four around and one from above";
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(m.offset[i], truth[i], 0.001) << "axis " << i;
    EXPECT_EQ(r.table_offset(1)[i], m.offset[i]) << "stored in the tool table";
  }
  EXPECT_LT(m.max_residual_mm, 0.001);
  EXPECT_EQ(r.scenario.status().servo.commanded[Axis::Z], -60.0) << "left at the safe height";
}

TEST(ElectrodeSetting, ABallTippedElectrodeIsMeasuredToItsLowestPoint) {
  Rig r(edm_profile({"probe.reference_sphere.touches_around=6"}));
  const Vec3 truth{-0.3, 0.15, 39.8};
  r.scenario.sim().set_electrode(truth, 3.0);
  const edm::ElectrodeResult m = r.measure(2);
  ASSERT_TRUE(m.ok) << m.message;
  ASSERT_EQ(m.touched.size(), 7u);
  EXPECT_EQ(m.names[1], "60°");
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(m.offset[i], truth[i], 0.001) << "axis " << i;
}

/// Fast-then-slow touches (10 mm/s, back 50 µm, then 0.5 µm a period) on a sphere without noise.
std::vector<std::string> fast_then_slow(std::vector<std::string> more = {}) {
  more.insert(more.begin(), {"probe.reference_sphere.fast_feed=600", "probe.reference_sphere.back_off=0.05",
                             "probe.reference_sphere.probe_feed=30", "probe.reference_sphere.sim.noise=0"});
  return more;
}

TEST(ElectrodeSetting, FastThenSlowTouchesMeasureToATenthOfAMicrometre) {
  Rig r(edm_profile(fast_then_slow()));
  const Vec3 truth{0.2, -0.1, 50.5};
  r.scenario.sim().set_electrode(truth, 0);
  const edm::ElectrodeResult m = r.measure(1);
  ASSERT_TRUE(m.ok) << m.message;
  ASSERT_EQ(m.touched.size(), 5u);
  ASSERT_EQ(m.fast_touched.size(), 5u) << "each direction touched fast first";
  for (std::size_t k = 0; k < 5; ++k) {
    // The slow touch closed near the fast one, on the same line, and is the one fitted.
    const double apart =
        std::hypot(m.touched[k][0] - m.fast_touched[k][0], m.touched[k][1] - m.fast_touched[k][1],
                   m.touched[k][2] - m.fast_touched[k][2]);
    EXPECT_LT(apart, 0.005) << m.names[k];
  }
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(m.offset[i], truth[i], 1e-4) << "axis " << i;
    EXPECT_EQ(r.table_offset(1)[i], m.offset[i]);
  }
  const edm::ElectrodeResult refit =
      edm::evaluate_touches(r.feature->profile_sphere(), 1, m.previous, 0, m.names, m.touched);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ(refit.offset[i], m.offset[i]) << "the slow touches are fitted";
  EXPECT_EQ(r.scenario.status().servo.commanded[Axis::Z], -60.0) << "left at the safe height";
}

TEST(ElectrodeSetting, TheSphereTurnsWithBAndIsMeasuredAtItsAngle) {
  // B's axis crosses X 100, Z −170, 20 mm below the sphere's centre at B 0 (X 100, Z −150). The
  // routine measures at B 30, where the sphere's centre is at X 100 + 20·sin 30° = 110,
  // Z −170 + 20·cos 30°.
  const double z30 = -170 + 20 * std::cos(std::numbers::pi / 6);
  const std::string position =
      "probe.reference_sphere.position=[110.0, 50.0, " + fmt::format("{:.12f}", z30) + "]";
  Rig r(edm_profile(fast_then_slow(
      {"probe.reference_sphere.b=30", position, "probe.reference_sphere.sim.b_axis=[100.0, -170.0]"})));
  const machine::SimSphereProbe& sphere = r.scenario.sim().sphere_probe();
  EXPECT_NEAR(sphere.centre()[0], 100.0, 1e-9) << "at B 0 the sphere is where it was mounted";
  EXPECT_NEAR(sphere.centre()[2], -150.0, 1e-9);
  const Vec3 truth{-0.15, 0.25, 49.7};
  r.scenario.sim().set_electrode(truth, 0);
  const edm::ElectrodeResult m = r.measure(1);
  ASSERT_TRUE(m.ok) << m.message;
  EXPECT_EQ(r.scenario.status().servo.commanded[Axis::B], 30.0);
  // Turned with the B table (where its steps put it: within 0.1 µm at 20 mm from the axis).
  EXPECT_NEAR(sphere.centre()[0], 110.0, 1e-4);
  EXPECT_NEAR(sphere.centre()[2], z30, 1e-4);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(m.offset[i], truth[i], 1e-4) << "axis " << i;
}

/// B's axis as the drawing gives it (X 100, Z −170 at Y 50, along Y) and as the simulated table
/// really turns: 12 µm and −15 µm off at the sphere, tilted by 0.2 and −0.1 mrad.
std::vector<std::string> b_axis_off_nominal() {
  return fast_then_slow({"probe.reference_sphere.b_axis=[100.0, -170.0]",
                         "probe.reference_sphere.sim.b_axis=[100.012, -170.015]",
                         "probe.reference_sphere.sim.b_axis_direction=[0.0002, 1.0, -0.0001]"});
}

edm::BAxisResult calibrate_b(Rig& r, std::vector<double> angles) {
  r.scenario.must(Request::feature("electrode", "calibrate-b", edm::BAxisCalibrate{1, std::move(angles)}));
  EXPECT_TRUE(r.scenario.until([&] { return r.feature->phase() == edm::ElectrodePhase::Idle; }, 200000));
  EXPECT_TRUE(r.feature->last_b_axis().has_value());
  return r.feature->last_b_axis().value_or(edm::BAxisResult{});
}

TEST(ElectrodeSetting, CalibrateBFindsTheTrueAxisWithinAMicrometre) {
  Rig r(edm_profile(b_axis_off_nominal()));
  // An electrode 0.2, −0.1, 0.5 mm off its table entry: it moves every centre alike, not the axis.
  r.scenario.sim().set_electrode({0.2, -0.1, 50.5}, 0);
  const edm::BAxisResult c = calibrate_b(r, {-40, 0, 40});
  ASSERT_TRUE(c.ok) << c.message;
  ASSERT_EQ(c.centres.size(), 3u);
  EXPECT_NEAR(c.fit.axis.crossing[0], 100.012, 0.001);
  EXPECT_NEAR(c.fit.axis.crossing[1], -170.015, 0.001);
  const double n = std::hypot(0.0002, 1.0, 0.0001);
  EXPECT_NEAR(c.fit.axis.direction[0], 0.0002 / n, 2e-5) << "the tilt, over a 26 mm chord";
  EXPECT_NEAR(c.fit.axis.direction[2], -0.0001 / n, 2e-5);
  EXPECT_NEAR(c.fit.radius_mm, std::hypot(0.012, 20.015), 0.001);
  EXPECT_LT(c.fit.max_residual_mm, 0.001);
  EXPECT_EQ(r.table_offset(1), (Vec3{0, 0, 50})) << "the tool table is not touched";
  const config::ReferenceSphereProfile now = r.feature->sphere();
  EXPECT_TRUE(now.has_b_axis);
  EXPECT_EQ(now.b_axis, c.fit.axis.crossing) << "kept for the measurements that follow";
  EXPECT_EQ(r.feature->profile_sphere().b_axis, (std::array<double, 2>{100.0, -170.0}));
}

TEST(ElectrodeSetting, WithBTurnedTheElectrodeIsRightOnlyAboutTheMeasuredAxis) {
  Rig r(edm_profile(b_axis_off_nominal()));
  const Vec3 truth{0.2, -0.1, 50.5};
  r.scenario.sim().set_electrode(truth, 0);
  const machine::SimSphereProbe& sphere = r.scenario.sim().sphere_probe();
  // About the drawing's axis, with B at 40°: the sphere is not where the touches are aimed, and
  // the offsets come out wrong by as much (the sphere's true centre less the expected one).
  const auto measure_at_40 = [&] {
    r.scenario.must(Request::feature("electrode", "measure", edm::ElectrodeMeasure{1, true, 40.0}));
    EXPECT_TRUE(r.scenario.until([&] { return r.feature->phase() == edm::ElectrodePhase::Idle; }, 60000));
    return r.feature->last().value_or(edm::ElectrodeResult{});
  };
  const edm::ElectrodeResult nominal = measure_at_40();
  ASSERT_TRUE(nominal.ok) << nominal.message;
  EXPECT_EQ(r.scenario.status().servo.commanded[Axis::B], 40.0);
  const Vec3 expected = edm::sphere_centre_at(r.feature->sphere(), 40);
  double off = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const double error = sphere.centre()[i] - expected[i];
    EXPECT_NEAR(nominal.offset[i] - truth[i], error, 0.001) << "axis " << i;
    off = std::hypot(off, error);
  }
  // 2·sin 20° of the 19 µm between the axes, and the tilt: 13.5 µm.
  EXPECT_GT(off, 0.010) << "the drawing's axis puts the turned sphere this far off";
  // B's axis measured: the same measurement at 40° lands on the sphere where it really is.
  r.scenario.sim().set_electrode(truth, 0);
  ASSERT_TRUE(calibrate_b(r, {-40, 0, 40}).ok);
  const edm::ElectrodeResult measured = measure_at_40();
  ASSERT_TRUE(measured.ok) << measured.message;
  const Vec3 now = edm::sphere_centre_at(r.feature->sphere(), 40);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(now[i], sphere.centre()[i], 0.001)
        << "the sphere where the measured axis turns it, axis " << i;
    EXPECT_NEAR(measured.offset[i], truth[i], 0.001) << "axis " << i;
  }
}

TEST(ElectrodeSetting, CalibrateBWithTheSphereNotWhereTheDrawingsAxisTurnsItChangesNothing) {
  // The drawing's axis 5 mm off the true one: at 40° the sphere is 3.4 mm from where it is looked
  // for, and that angle's touch fails; the calibration ends with its reason and the angle.
  Rig r(edm_profile(fast_then_slow({"probe.reference_sphere.b_axis=[100.0, -165.0]",
                                    "probe.reference_sphere.sim.b_axis=[100.0, -170.0]"})));
  r.scenario.sim().set_electrode({0, 0, 50}, 0);
  EventCursor log(r.scenario.rig().controller().events());
  const edm::BAxisResult c = calibrate_b(r, {0, 40, -40});
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.centres.size(), 1u) << "B at 0 is where the profile's position holds";
  EXPECT_EQ(c.code.rfind("electrode.", 0), 0u) << c.code;
  EXPECT_EQ(c.message.rfind("with B at 40°: ", 0), 0u) << c.message;
  EXPECT_EQ(r.feature->sphere().b_axis, (std::array<double, 2>{100.0, -165.0})) << "the axis unchanged";
  EXPECT_EQ(r.feature->phase(), edm::ElectrodePhase::Idle);
  bool noted = false;
  for (const ControllerEvent& e : log.next(1 << 16))
    noted |= e.kind == ControllerEventKind::Note && e.code == c.code &&
             e.text.find("calibrate-b") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(ElectrodeSetting, CalibrateBRefusesWhatItCannotMeasure) {
  Rig r(edm_profile(b_axis_off_nominal()));
  const auto refused = [&](std::vector<double> angles) {
    return !r.scenario
                .ask(Request::feature("electrode", "calibrate-b", edm::BAxisCalibrate{1, std::move(angles)}))
                .accepted;
  };
  EXPECT_TRUE(refused({0, 40})) << "two angles fix no circle";
  EXPECT_TRUE(refused({0, 40, 40})) << "nor three with two alike";
  Rig without(edm_profile(fast_then_slow()));  // no nominal axis to look for the sphere about
  const Outcome o = without.scenario.ask(
      Request::feature("electrode", "calibrate-b", edm::BAxisCalibrate{1, {-40, 0, 40}}));
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("b_axis"), std::string::npos) << o.message;
  const Outcome at =
      without.scenario.ask(Request::feature("electrode", "measure", edm::ElectrodeMeasure{1, true, 30.0}));
  EXPECT_FALSE(at.accepted) << "B's axis unknown: only at b";
  EXPECT_EQ(r.feature->phase(), edm::ElectrodePhase::Idle);
}

TEST(ElectrodeSetting, AMissingSphereIsRefusedAndNothingStored) {
  // The simulated sphere is 30 mm from where the profile says: the first touch meets nothing.
  Rig r(edm_profile(), edm_profile({"probe.reference_sphere.position=[130.0, 50.0, -150.0]"}));
  r.scenario.sim().set_electrode({0, 0, 50}, 0);
  EventCursor log(r.scenario.rig().controller().events());
  const edm::ElectrodeResult m = r.measure(1);
  EXPECT_FALSE(m.ok);
  EXPECT_EQ(m.code, "electrode.missing-touch");
  EXPECT_NE(m.message.find("touch from +X met nothing"), std::string::npos) << m.message;
  EXPECT_EQ(r.table_offset(1), (Vec3{0, 0, 50}));
  bool noted = false;
  for (const ControllerEvent& e : log.next(1 << 16))
    noted |= e.kind == ControllerEventKind::Note && e.code == "electrode.missing-touch";
  EXPECT_TRUE(noted);
}

TEST(ElectrodeSetting, AContactClosedBeforeTheTouchIsNotATouch) {
  // 3 mm off in X: the electrode goes down into the sphere beside it and is in contact at the start.
  Rig r(edm_profile());
  r.scenario.sim().set_electrode({3, 0, 50}, 0);
  const edm::ElectrodeResult m = r.measure(1);
  EXPECT_FALSE(m.ok);
  EXPECT_EQ(m.code, "electrode.contact-at-start") << m.message;
  EXPECT_EQ(r.table_offset(1), (Vec3{0, 0, 50}));
}

TEST(ElectrodeSetting, ASphereFartherThanAllowedIsRefused) {
  Rig r(edm_profile({"probe.reference_sphere.max_deviation=0.5"}));
  r.scenario.sim().set_electrode({0.7, 0, 50}, 0);
  const edm::ElectrodeResult m = r.measure(1);
  EXPECT_FALSE(m.ok);
  EXPECT_EQ(m.code, "electrode.far") << m.message;
  EXPECT_NEAR(m.offset[0], 0.7, 0.001) << "what was found is reported";
  EXPECT_EQ(r.table_offset(1), (Vec3{0, 0, 50}));
}

TEST(ElectrodeSetting, TouchesOffTheSphereExceedTheTolerance) {
  // A sphere 0.04 mm larger than the profile's (dirt, the wrong sphere): no centre fits.
  Rig r(edm_profile(), edm_profile({"probe.reference_sphere.diameter=10.04"}));
  r.scenario.sim().set_electrode({0, 0, 50}, 0);
  const edm::ElectrodeResult m = r.measure(1);
  EXPECT_FALSE(m.ok);
  EXPECT_EQ(m.code, "electrode.fit") << m.message;
  EXPECT_GT(m.max_residual_mm, 0.002);
  EXPECT_EQ(r.table_offset(1), (Vec3{0, 0, 50}));
}

TEST(ElectrodeSetting, RefusesWhatItCannotMeasure) {
  Rig r(edm_profile());
  EXPECT_FALSE(r.scenario.ask(Request::feature("electrode", "measure", edm::ElectrodeMeasure{9})).accepted);
  EXPECT_NE(r.scenario.message().find("tool 9 is not in the tool table"), std::string::npos);
  EXPECT_FALSE(r.scenario.ask(Request::feature("electrode", "resume")).accepted);
  EXPECT_FALSE(r.scenario.ask(Request::feature("electrode", "measure")).accepted);
  Rig low(edm_profile({"probe.reference_sphere.safe_z=-100"}));
  EXPECT_FALSE(low.scenario.ask(Request::feature("electrode", "measure", edm::ElectrodeMeasure{1})).accepted);
  EXPECT_NE(low.scenario.message().find("safe_z"), std::string::npos) << low.scenario.message();
}

constexpr const char* kJob =
    "G21 G90 G17 G40\n"
    "G43 H1\n"
    "G0 X0 Y0 Z10\n"
    "G1 Z-20 F600\n"
    "G1 X40\n"  // the electrode wears out half way along here
    "G1 Y40\n"
    "G0 Z10\n"
    "M2\n";

TEST(ElectrodeSetting, AWornElectrodeIsReplacedMidJobAndTheJobGoesOnWhereItStopped) {
  Rig r(edm_profile());
  r.scenario.sim().set_electrode({0, 0, 50}, 0);
  TempProgram p("job.ngc", kJob);
  r.scenario.must(Request::set_mode(control::Mode::Auto));
  r.scenario.must(Request::open(p.path()));
  r.scenario.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(r.scenario.until([&] { return r.scenario.status().servo.commanded[Axis::X] > 20; }, 20000));
  r.scenario.must(Request::simple(control::CommandKind::FeedHold));
  ASSERT_TRUE(r.scenario.until(
      [&] {
        return r.scenario.status().servo.state == control::State::Held &&
               r.scenario.status().servo.path_velocity == 0;
      },
      5000));
  r.scenario.must(Request::simple(control::CommandKind::Abort));
  ASSERT_TRUE(r.scenario.idle());
  const std::optional<edm::ProgramStop> stop = r.feature->stop();
  ASSERT_TRUE(stop.has_value());
  EXPECT_GT(stop->position[0], 20);
  EXPECT_EQ(stop->position[2], 30.0) << "on the G1 X40 at Z-20 + 50";

  // The new electrode is 0.2, −0.1 and 0.5 mm off the worn one's offsets.
  const Vec3 truth{0.2, -0.1, 50.5};
  r.scenario.sim().set_electrode(truth, 0);
  const edm::ElectrodeResult m = r.measure(1);
  ASSERT_TRUE(m.ok) << m.message;
  EventCursor log(r.scenario.rig().controller().events());
  r.scenario.must(Request::feature("electrode", "resume"));
  const std::uint64_t finished = r.scenario.status().runs_finished;
  ASSERT_TRUE(r.scenario.until(
      [&] { return r.feature->phase() == edm::ElectrodePhase::Idle && r.scenario.status().run_active; },
      60000));
  // Where the resumed program started: the stop point moved by the measured change.
  const Pose at = r.scenario.status().servo.commanded;
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(at[i], stop->position[i] + m.offset[static_cast<std::size_t>(i)] - (i == 2 ? 50.0 : 0.0),
                1e-6);
  ASSERT_TRUE(r.scenario.until(
      [&] { return !r.scenario.status().run_active && r.scenario.status().runs_finished > finished; },
      60000));
  int ended = 0;
  for (const ControllerEvent& e : log.next(1 << 16)) {
    if (e.kind != ControllerEventKind::JobEnded || e.job != JobKind::Program) continue;
    EXPECT_EQ(e.end, JobEnd::Finished);
    ++ended;
  }
  EXPECT_EQ(ended, 1);
  // The rest of the job ran with the new offsets: it ends at X40 Y40 Z10 of the program.
  const Pose end = r.scenario.status().servo.commanded;
  EXPECT_NEAR(end[0], 40 + m.offset[0], 1e-9);
  EXPECT_NEAR(end[1], 40 + m.offset[1], 1e-9);
  EXPECT_NEAR(end[2], 10 + m.offset[2], 1e-9);
  EXPECT_FALSE(r.feature->stop().has_value()) << "the job reached its end";
}

}  // namespace
}  // namespace opencnc::controller::test
