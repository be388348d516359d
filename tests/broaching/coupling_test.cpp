// SPDX-License-Identifier: GPL-3.0-or-later
// The axis coupling through the whole controller on the broach: C follows Z by each law every
// period in both directions (from the command or the feedback), engaging and releasing move
// nothing, status shows it, and the preflight refuses at their line the programs whose coupled C
// would leave its limits or which move C themselves.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/broaching/power_fail_recorder.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/motion/coupling.hpp"

namespace opencnc::controller::test {
namespace {

config::MachineProfile broach(std::vector<std::string> sets = {}) {
  return control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml", sets));
}

/// Every coupled period: the tick's command of C against the law evaluated here from the status's
/// origin, and the helix error of the feedback.
class HelixWatch final : public ControllerObserver {
 public:
  explicit HelixWatch(motion::CouplingConfig c) : config_(c) {}
  void on_status(const ControllerStatus& s) override {
    waited_in_position = waited_in_position || s.servo.coupling_wait;
    const control::CouplingStatus& c = s.servo.coupling;
    if (c.kind == motion::CouplingKind::Off) return;
    ++coupled;
    kinds.push_back(c.kind);
    const motion::CouplingLaw law = law_of(c);
    const double master = s.servo.commanded[Axis::Z] - c.master_origin;
    command_error_deg = std::max(
        command_error_deg, std::fabs(s.servo.commanded[Axis::C] - (c.slave_origin + law.slave(master))));
    actual_error_deg = std::max(actual_error_deg, std::fabs(c.error_deg));
    if (previous_z_ > s.servo.commanded[Axis::Z] + 1e-6) backwards = true;
    previous_z_ = s.servo.commanded[Axis::Z];
  }
  motion::CouplingLaw law_of(const control::CouplingStatus& c) const {
    switch (c.kind) {
      case motion::CouplingKind::ConstantPitch:
        return motion::CouplingLaw::constant(c.pitch_mm);
      case motion::CouplingKind::LinearPitch:
        return motion::CouplingLaw::linear(c.pitch_mm, c.pitch_rate);
      default:
        return motion::CouplingLaw::tabulated(c.kind, config_.tables[static_cast<std::size_t>(c.table - 1)]);
    }
  }
  std::uint64_t coupled = 0;
  std::vector<motion::CouplingKind> kinds;
  double command_error_deg = 0, actual_error_deg = 0;
  bool backwards = false;
  bool waited_in_position = false;  ///< a coupling code waited for the drives (status coupling_wait)

 private:
  motion::CouplingConfig config_;
  double previous_z_ = -1e9;
};

/// A program file of its own for the test.
std::string write_program(const std::string& text) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-coupling-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  return path;
}

struct CoupledRun {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<HelixWatch> watch;
  Outcome opened;
};

/// Opens `text` on the broach and, if the preflight passes, runs it to its end.
CoupledRun run(const std::string& text, const config::MachineProfile& profile = broach()) {
  CoupledRun r;
  Diagnostics d;
  r.rig = std::make_unique<SimRig>(profile, *features::machine_setup(profile, d));
  r.watch = std::make_shared<HelixWatch>(control::coupling_config(profile.coupling));
  r.rig->controller().attach(r.watch, ObserverOptions{0.001, false});
  r.rig->step();
  EXPECT_TRUE(r.rig->request(Request::simple(control::CommandKind::MachineOn)).accepted);
  EXPECT_TRUE(r.rig->request(Request::set_mode(control::Mode::Auto)).accepted);
  r.opened = r.rig->request(Request::open(write_program(text)), 100000);
  if (!r.opened.accepted) return r;
  EXPECT_TRUE(r.rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  EXPECT_TRUE(r.rig->run_until(
      [&] { return !r.rig->status().run_active && r.rig->status().servo.state == control::State::Idle; },
      200000));
  return r;
}

std::string messages(const Outcome& o) {
  std::string m;
  for (const auto& d : o.diagnostics.items()) m += d.format() + "\n";
  return m + o.message;
}

TEST(Coupling, ConstantPitchHeldEveryPeriodBothWays) {
  const CoupledRun r =
      run("G21 G90 G0 X0 Z-10 C30\nM171 P60\nG1 X0.1 F60\nG1 Z80 F3000\nG1 X-0.2\nG0 Z-10\n"
          "M175\nG0 Z20\nM2\n");
  ASSERT_TRUE(r.opened.accepted) << messages(r.opened);
  EXPECT_GT(r.watch->coupled, 3000u);
  EXPECT_TRUE(r.watch->backwards);
  EXPECT_LT(r.watch->command_error_deg, 1e-9);
  // The feedback's helix error is the drives' tracking (Z and C lag differently while they
  // accelerate): 0.15° at this steep pitch (6°/mm), bounded here so that a change shows.
  EXPECT_LT(r.watch->actual_error_deg, 0.2);
  const control::ServoStatus s = r.rig->status().servo;
  EXPECT_EQ(s.coupling.kind, motion::CouplingKind::Off);  // released at M175 (and at the run's end)
  // Back at Z −10 the law gives C 30 again; after M175 C stays where the law left it.
  EXPECT_NEAR(s.commanded[Axis::C], 30.0, 1e-9);
  EXPECT_NEAR(s.commanded[Axis::Z], 20.0, 1e-9);
}

// With jerk limits on X, Z and C (100 times their accelerations) the law holds every period as
// without: the coupling acts on the jerk-limited commands.
TEST(Coupling, WithJerkLimitsTheLawIsHeldEveryPeriodBothWays) {
  const CoupledRun r =
      run("G21 G90 G0 X0 Z-10 C30\nM171 P60\nG1 X0.1 F60\nG1 Z80 F3000\nG1 X-0.2\nG0 Z-10\n"
          "M175\nG0 Z20\nM2\n",
          broach({"axis.x.max_jerk=10000", "axis.z.max_jerk=150000", "axis.c.max_jerk=360000"}));
  ASSERT_TRUE(r.opened.accepted) << messages(r.opened);
  EXPECT_GT(r.watch->coupled, 3000u);
  EXPECT_TRUE(r.watch->backwards);
  EXPECT_LT(r.watch->command_error_deg, 1e-9);
  const control::ServoStatus s = r.rig->status().servo;
  EXPECT_EQ(s.coupling.kind, motion::CouplingKind::Off);
  EXPECT_NEAR(s.commanded[Axis::C], 30.0, 1e-9);
  EXPECT_NEAR(s.commanded[Axis::Z], 20.0, 1e-9);
}

TEST(Coupling, EveryLawMeetsItsDefinitionInTheTick) {
  const CoupledRun r =
      run("G21 G90 G0 X0 Z0 C0\nM172 P600 Q-0.2\nG1 Z300 F6000\nM173 P1\nG1 Z700\nG1 Z650\n"
          "M174 P2\nG1 Z620 F1500\nG1 Z760\nM175\nM2\n");
  ASSERT_TRUE(r.opened.accepted) << messages(r.opened);
  EXPECT_LT(r.watch->command_error_deg, 1e-9);
  std::vector<motion::CouplingKind> seen;
  for (motion::CouplingKind k : r.watch->kinds) {
    if (seen.empty() || seen.back() != k) seen.push_back(k);
  }
  const std::vector<motion::CouplingKind> expected = {
      motion::CouplingKind::LinearPitch, motion::CouplingKind::PitchTable, motion::CouplingKind::Cam};
  EXPECT_EQ(seen, expected);
}

TEST(Coupling, FollowsTheMastersFeedbackWhenTheProfileSaysSo) {
  const CoupledRun r = run("G21 G90 G0 Z0 C0\nM171 P100\nG1 Z50 F6000\nG0 Z0\nM175\nM2\n",
                           broach({"coupling.source=\"actual\""}));
  ASSERT_TRUE(r.opened.accepted) << messages(r.opened);
  // C follows where Z is, so the law against the command of Z is off by Z's following error …
  EXPECT_GT(r.watch->command_error_deg, 1e-4);
  // … and the helix error of the feedback is C's own tracking only.
  EXPECT_LT(r.watch->actual_error_deg, 0.1);
}

TEST(Coupling, PreflightRefusesAtTheLine) {
  struct Case {
    const char* program;
    const char* line_and_text;
  };
  const Case cases[] = {
      {"G0 Z0\nM171 P60\nG1 Z10 C5 F600\nM2\n", ":3: error: C is coupled to Z"},
      {"G0 Z0\nM173 P5\nG1 Z10 F600\nM2\n", ":2: error: this machine has no pitch table 5"},
      {"G0 Z0\nM172 P600 Q-0.5\nG1 Z1000 F9000\nM2\n", ":3: error: the coupled C would turn at"},
      {"G0 Z0\nM172 P10 Q-0.02\nG1 Z600 F60\nM2\n", ":3: error: the pitch of M172 reaches 0"},
      {"G0 Z0\nM171\nM2\n", ":2:1: error: M171 needs the pitch"},
      {"G0 Z0\nM174 P9\nM2\n", ":2:1: error: M174 needs the number of a cam table"},
      {"G18 G0 X0 Z0\nG41\nG1 X1 F100\nM171 P10\nM2\n",
       ":4:1: error: M171 cannot change the axis coupling while cutter compensation is on"},
  };
  for (const Case& c : cases) {
    const CoupledRun r = run(c.program);
    EXPECT_FALSE(r.opened.accepted) << c.program;
    EXPECT_NE(messages(r.opened).find(c.line_and_text), std::string::npos) << messages(r.opened);
  }
  // A slave with soft limits: the law would take it past them.
  const CoupledRun limited =
      run("G0 Z0 C0\nM171 P10\nG1 Z100 F600\nM2\n",
          broach({"axis.c.wrapped=false", "axis.c.min_limit=-360", "axis.c.max_limit=360"}));
  EXPECT_FALSE(limited.opened.accepted);
  EXPECT_NE(messages(limited.opened).find(":3: error: the coupled C would reach 3600.000"), std::string::npos)
      << messages(limited.opened);
}

TEST(Coupling, TheDemoJobsPassTheBroachsPreflight) {
  for (const char* job : {"broach-constant.ngc", "broach-variable.ngc"}) {
    Diagnostics d;
    const config::MachineProfile p = broach();
    SimRig rig(p, *features::machine_setup(p, d));
    rig.step();
    ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
    ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
    const Outcome o = rig.request(Request::open(std::string(OPENCNC_SOURCE_DIR "/examples/") + job), 100000);
    EXPECT_TRUE(o.accepted) << job << "\n" << messages(o);
  }
}

/// The broach on the simulated machine with a power-fail recorder attached, `program` started
/// in Auto (with flood coolant on: a process running), ready for the mains to fail.
struct PowerFailRun {
  PowerFailRun(const config::MachineProfile& p, const std::string& program, bool flood)
      : rig(p, *features::machine_setup(p, diags)),
        recorder(std::make_shared<broaching::PowerFailRecorder>(control::coupling_config(p.coupling),
                                                                machine_limits(p), p.servo_period_s,
                                                                p.coupling.radius_mm)) {
    rig.controller().attach(recorder, ObserverOptions{p.servo_period_s, true});
    rig.step();
    EXPECT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
    if (flood) {
      EXPECT_TRUE(rig.request(Request::coolant(control::Coolant::Flood, true)).accepted);
    }
    EXPECT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
    EXPECT_TRUE(rig.request(Request::open(program), 100000).accepted);
    EXPECT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  }
  Diagnostics diags;
  SimRig rig;
  std::shared_ptr<broaching::PowerFailRecorder> recorder;
};

// Fault injection: the mains fail at instants through the constant-pitch demo job (cutting,
// lifting, returning at rapid). Within a period the spindle and the coolant are off; Z stops on the
// path with C held to the law (≤ 1 µm of helix error at the bore, feedback included), where each
// axis braking alone would tear the groove; then the machine faults with the drives off.
TEST(Coupling, PowerFailStopsOnTheHelix) {
  const config::MachineProfile p = broach();
  for (const double cut_s : {1.7, 3.2, 5.05, 9.4}) {
    PowerFailRun run(p, OPENCNC_SOURCE_DIR "/examples/broach-constant.ngc", true);  // the process runs
    ASSERT_FALSE(HasFailure()) << cut_s;
    SimRig& rig = run.rig;
    ASSERT_TRUE(rig.run_until([&] { return rig.status().servo.time_s >= cut_s; }, 20000));
    ASSERT_TRUE(rig.status().servo.flood);
    rig.machine().set_mains_ok(false);
    // The machine reports it after its next period, the servo acts in the period that reads it,
    // and the controller's status shows that period at its next service.
    rig.run(4);
    EXPECT_TRUE(rig.status().servo.aborting) << cut_s;  // the stop is under way …
    EXPECT_FALSE(rig.status().servo.flood) << cut_s;    // … with the process already off
    ASSERT_TRUE(rig.run_until([&] { return rig.status().servo.state == control::State::Faulted; }, 5000))
        << cut_s;
    EXPECT_EQ(rig.status().servo.fault.kind, control::FaultKind::PowerLoss);
    EXPECT_FALSE(rig.status().servo.drives_enabled);
    const broaching::PowerFailReport r = run.recorder->report();
    ASSERT_TRUE(r.happened && r.coupled) << cut_s;
    EXPECT_LE(r.coupled_error_um, 1.0) << cut_s;
    EXPECT_LT(r.coupled_command_error_um, 1e-3) << cut_s;
    EXPECT_GT(r.independent_error_um, 10 * std::max(r.coupled_error_um, 1.0)) << cut_s;
    EXPECT_GT(r.stop_distance_mm, 0.0) << cut_s;
  }
}

// The law engages on settled drives. Indexing C by 180° uncoupled (as between the demo jobs'
// grooves) leaves C overshooting by 0.05° when its command rests; a law that took C then would
// hold it to that command while the drive still settles: 35 µm of helix error at the bore during
// the X infeed after M171. The code waits until Z and C stand within [coupling]
// engage_tolerance_um (0.25 µm) of their commands: the error after it stays within 1 µm.
TEST(Coupling, TheLawEngagesOnSettledDrives) {
  const std::string program =
      "G21 G90 G94 G64 P0.005\nG0 X-0.5\nG0 Z-10 C180\nM171 P600\nG1 X0.1 F60\nM175\nM2\n";
  auto helix_um = [](const CoupledRun& r) {
    return r.watch->actual_error_deg * std::numbers::pi / 180 * 40e3;
  };
  const CoupledRun settled = run(program);
  ASSERT_TRUE(settled.opened.accepted) << messages(settled.opened);
  EXPECT_TRUE(settled.watch->waited_in_position);
  EXPECT_GT(settled.watch->coupled, 500u);
  EXPECT_LE(helix_um(settled), 1.0);
  const CoupledRun at_once = run(program, broach({"coupling.engage_tolerance_um=0"}));  // no wait
  EXPECT_FALSE(at_once.watch->waited_in_position);
  EXPECT_GT(helix_um(at_once), 10.0);
}

// The wait is bounded: a drive that does not settle within engage_timeout_s (here 10 ms, C needs
// about 80) stops the run with a fault that names it.
TEST(Coupling, ADriveThatDoesNotSettleStopsTheRunWithAFault) {
  const config::MachineProfile p = broach({"coupling.engage_timeout_s=0.01"});
  Diagnostics d;
  SimRig rig(p, *features::machine_setup(p, d));
  rig.step();
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(
      rig.request(Request::open(write_program("G21 G90\nG0 Z-10 C180\nM171 P600\nG1 Z50 F3000\nM2\n")),
                  100000)
          .accepted);
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  ASSERT_TRUE(rig.run_until([&] { return rig.status().servo.state == control::State::Faulted; }, 20000));
  const ControllerStatus s = rig.status();
  EXPECT_EQ(s.servo.fault.kind, control::FaultKind::CouplingPosition);
  EXPECT_EQ(s.servo.fault.axis, index(Axis::C));
  EXPECT_GT(s.servo.fault.value, s.servo.fault.limit);
  EXPECT_NE(s.fault_text.find("engage_tolerance_um"), std::string::npos) << s.fault_text;
  EXPECT_EQ(s.servo.coupling.kind, motion::CouplingKind::Off);  // the law never took the axes
  EXPECT_NEAR(s.servo.actual[Axis::Z], -10.0, 0.01);            // the stroke never started
}

// The stop shortened by the DC link's energy. The mains cut while a stroke cuts (3.2 s, Z at
// 3 m/min) and during a rapid return (14.2 s, 9 m/min), the UPS's battery empty so that the link
// alone feeds the drives. With broach-zc's 4.7 mF (361 J above 400 V) the stop is as planned;
// with 40 µF (2.9 J) the planned stop would drain the link before rest (the drives trip on
// undervoltage: an amplifier fault, the axes coasting), so the tick brakes harder — 1.87 times
// the planned deceleration on the stroke, the peak decelerations' bound of 4 on the return — and
// the axes rest on the helix with energy left.
TEST(Coupling, APowerFailOnANearlyEmptyDcLinkBrakesHarderAndStaysOnTheHelix) {
  const std::vector<std::string> empty_ups = {"power.sim.ups_runtime_s=0"};
  auto cut = [&](std::vector<std::string> sets, double cut_s) {
    PowerFailRun run(broach(sets), OPENCNC_SOURCE_DIR "/examples/broach-constant.ngc", false);
    SimRig& rig = run.rig;
    EXPECT_TRUE(rig.run_until([&] { return rig.status().servo.time_s >= cut_s; }, 20000));
    rig.machine().set_mains_ok(false);
    EXPECT_TRUE(rig.run_until([&] { return rig.status().servo.state == control::State::Faulted; }, 5000));
    return std::pair{run.recorder->report(), rig.status().servo.fault.kind};
  };
  std::vector<std::string> small = empty_ups;
  small.push_back("power.dc_link_capacitance_f=0.00004");
  std::vector<std::string> no_margin = small;
  no_margin.insert(no_margin.end(), {"axis.z.peak_deceleration=1500", "axis.c.peak_deceleration=3600"});
  for (const double cut_s : {3.2, 14.2}) {
    const auto [normal, normal_fault] = cut(empty_ups, cut_s);
    const auto [with_ups, ups_fault] = cut({}, cut_s);
    EXPECT_EQ(normal.decel_scale, 1.0) << cut_s;  // enough energy: the stop as planned, bit for bit
    EXPECT_EQ(normal.stop_distance_mm, with_ups.stop_distance_mm) << cut_s;
    EXPECT_EQ(normal.coupled_error_um, with_ups.coupled_error_um) << cut_s;
    EXPECT_GT(normal.energy_at_signal_j, 350.0) << cut_s;
    const auto [short_stop, short_fault] = cut(small, cut_s);
    EXPECT_EQ(short_fault, control::FaultKind::PowerLoss) << cut_s;  // at rest, the drives still powered
    EXPECT_GT(short_stop.decel_scale, 1.5) << cut_s;
    EXPECT_LE(short_stop.decel_scale, 4.0) << cut_s;  // Z 6000 / 1500, C 14400 / 3600
    EXPECT_LT(short_stop.stop_distance_mm, 0.6 * normal.stop_distance_mm) << cut_s;
    EXPECT_LT(short_stop.stop_time_s, normal.stop_time_s) << cut_s;
    EXPECT_GT(short_stop.energy_at_rest_j, 0.0) << cut_s;
    EXPECT_GE(short_stop.dc_link_min_v, 400.0) << cut_s;
    EXPECT_LE(short_stop.coupled_error_um, 1.0) << cut_s;
    EXPECT_LT(short_stop.coupled_command_error_um, 1e-3) << cut_s;
  }
  const auto [planned, planned_fault] = cut(no_margin, 3.2);  // no peak above the plan
  EXPECT_EQ(planned.decel_scale, 1.0);
  EXPECT_EQ(planned_fault, control::FaultKind::AmpFault);  // the drives' undervoltage, before rest
}

// The 100-cut sweep's outlier (3.18 µm, the mains cut 10–40 ms after a rapid return arrived,
// while X fed in): the stop had nothing to stop; the drives had overshot the return's end point
// by a few µm and stuck, and crept back — Z first, C 40 ms later, its friction being larger
// against its inertia. The drives' friction compensation now starts both back together, as
// soon as their loops reverse. A short coupled return and the same instant after its arrival:
// 0.057 µm; without the drives' compensation the same cut gives 3.14 µm.
TEST(Coupling, APowerFailWhileTheAxesSettleAfterAReturnStaysOnTheHelix) {
  const std::string program = write_program(
      "G21 G90 G94 G64 P0.005\nG0 X-0.5\nG0 Z100 C0\nG4 P0.3\nM171 P600\nG0 Z-10\nG1 X0.1 F60\nM175\nM2\n");
  auto stop_error_um = [&](const config::MachineProfile& p) {
    PowerFailRun run(p, program, false);
    SimRig& rig = run.rig;
    EXPECT_TRUE(rig.run_until([&] { return rig.status().servo.commanded[Axis::Z] < 0; }, 20000));
    // The command ends its return; 10 ms later the axes creep back from their overshoot.
    EXPECT_TRUE(rig.run_until([&] { return rig.status().servo.commanded[Axis::Z] <= -10 + 1e-9; }, 2000));
    rig.run(10);
    rig.machine().set_mains_ok(false);
    EXPECT_TRUE(rig.run_until([&] { return rig.status().servo.state == control::State::Faulted; }, 5000));
    const broaching::PowerFailReport r = run.recorder->report();
    EXPECT_TRUE(r.happened && r.coupled);
    return r.coupled_error_um;
  };
  EXPECT_LE(stop_error_um(broach()), 1.0);
  EXPECT_GT(stop_error_um(
                broach({"axis.z.sim.friction_compensation_n=0", "axis.c.sim.friction_compensation_nm=0",
                        "axis.z.sim.acceleration_feed_forward=0", "axis.c.sim.acceleration_feed_forward=0"})),
            1.0);
}

}  // namespace
}  // namespace opencnc::controller::test
