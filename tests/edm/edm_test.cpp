// SPDX-License-Identifier: GPL-3.0-or-later
// The sinker EDM through the whole controller on configs/edm-5axis.toml: the gap held in its
// band while the depth grows, an injected short backed off and recovered within a bound, the
// jump's timing and height, the orbit's radius and shape from the trace, arcing without the jump,
// a short that never clears stopped by its time, and the preflight refusing an unknown condition
// at its line.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "edm_rig.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/edm/edm_recorder.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/run_from_line/run_from_line.hpp"

namespace opencnc::controller::test {
namespace {

config::MachineProfile edm(std::vector<std::string> sets = {}) {
  return edm_profile(std::move(sets));
}

std::string write_program(const std::string& text) {
  return test::write_program(text, "opencnc-edm");
}

struct EdmRun {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<edm::EdmRecorder> recorder;
  std::shared_ptr<Samples> samples;
  Outcome opened;
  bool finished = false;
  edm::EdmReport report;
};

/// Opens `text` and runs it to its end; `each` is called between periods (fault injection).
EdmRun run(const std::string& text, const config::MachineProfile& profile = edm(),
           const std::function<void(SimRig&)>& each = {}) {
  EdmRun r;
  Diagnostics d;
  r.rig = std::make_unique<SimRig>(profile, *features::machine_setup(profile, d));
  r.recorder = std::make_shared<edm::EdmRecorder>(profile.edm.config, profile.servo_period_s);
  r.samples = std::make_shared<Samples>();
  r.rig->controller().attach(r.recorder, ObserverOptions{0, true});
  r.rig->controller().attach(r.samples, ObserverOptions{0, true});
  r.rig->step();
  EXPECT_TRUE(on_and_homed(*r.rig));
  EXPECT_TRUE(r.rig->request(Request::set_mode(control::Mode::Auto)).accepted);
  r.opened = r.rig->request(Request::open(write_program(text)), 100000);
  if (!r.opened.accepted) return r;
  EXPECT_TRUE(r.rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  r.finished = r.rig->run_until(
      [&] {
        if (each) each(*r.rig);
        return !r.rig->status().run_active && r.rig->status().servo.state == control::State::Idle;
      },
      60000);
  r.report = r.recorder->report();
  return r;
}

/// A burn of `depth` below the surface (Z −20) with condition `n`.
std::string burn(int n, double depth, const std::string& feed = "F60") {
  return "G21 G90\nG0 Z-19.97\nM180 P" + std::to_string(n) + "\nG1 Z" + std::to_string(-20 - depth) + " " +
         feed + "\nM181\nG0 Z0\nM2\n";
}

TEST(Edm, TheGapIsHeldInBandWhileTheDepthGrows) {
  const EdmRun r = run(burn(1, 0.03));
  ASSERT_TRUE(r.opened.accepted) << r.opened.message;
  ASSERT_TRUE(r.finished);
  EXPECT_GT(r.report.machining_s, 0.5);
  EXPECT_GT(r.report.gap_voltage_in_band_fraction, 0.8);
  // From the first discharge (at Z −19.97: the open gap is 30 µm) to the program's end, Z −20.03.
  EXPECT_NEAR(r.report.depth_mm, 0.06, 0.002);
  EXPECT_EQ(r.report.shorts, 0u);
  EXPECT_GT(r.report.jumps, 0u);
  // The machine burnt what the program asked for: the front moved down, the electrode followed.
  EXPECT_GT(r.rig->machine().edm().depth_mm(), 0.015);
}

TEST(Edm, AnInjectedShortIsBackedOffAlongThePathAndRecovered) {
  bool injected = false;
  double backlog_max = 0;
  const EdmRun r = run(burn(1, 0.03), edm(), [&](SimRig& rig) {
    const control::ServoStatus& s = rig.status().servo;
    backlog_max = std::max(backlog_max, s.edm.backlog_mm);
    if (!injected && s.time_s > 0.5 && s.edm.generator && s.edm.gap_state == machine::GapState::Normal) {
      rig.machine().inject_edm_short();
      injected = true;
    }
  });
  ASSERT_TRUE(r.finished);
  ASSERT_TRUE(injected);
  EXPECT_GE(r.report.shorts, 1u);
  // The 20 µm bridge breaks once the electrode has backed off that far: at 3 mm/s about 7 ms,
  // with the acceleration and the filter well within 50 ms.
  EXPECT_GT(r.report.short_recovery_max_s, 0.004);
  EXPECT_LT(r.report.short_recovery_max_s, 0.05);
  EXPECT_GT(backlog_max, 0.015);
  EXPECT_GT(r.report.gap_voltage_in_band_fraction, 0.75);
}

// A bridge that no backing off breaks (100 mm): the electrode backs off at 3 mm/s to the end of the
// path memory (which starts with the run: the approach from Z0, 20 mm up the path), is told to
// hold there, and once the short has lasted short_timeout_s the machine stops with a fault that
// says so.
TEST(Edm, AShortThatNeverClearsStopsTheMachineWithAFault) {
  const config::MachineProfile p = edm({"edm.sim.short_bridge_mm=100", "edm.short_timeout_s=8"});
  ASSERT_EQ(p.edm.config.find(1)->short_timeout_s, 8.0);
  Diagnostics d;
  SimRig rig(p, *features::machine_setup(p, d));
  EventCursor events(rig.controller().events());
  auto recorder = std::make_shared<edm::EdmRecorder>(p.edm.config, p.servo_period_s);
  rig.controller().attach(recorder, ObserverOptions{0, true});
  rig.step();
  ASSERT_TRUE(on_and_homed(rig));
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(rig.request(Request::open(write_program(burn(1, 0.03))), 100000).accepted);
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  double shorted_at = -1, limit_at = -1;
  ASSERT_TRUE(rig.run_until(
      [&] {
        const control::ServoStatus& s = rig.status().servo;
        if (shorted_at < 0 && s.edm.generator && s.edm.gap_state == machine::GapState::Normal) {
          rig.machine().inject_edm_short();
          shorted_at = s.time_s;
        }
        if (limit_at < 0 && s.edm.retract_limit) limit_at = s.time_s;
        return s.state == control::State::Faulted ||
               (!rig.status().run_active && s.state == control::State::Idle);
      },
      40000));
  const control::ServoStatus s = rig.status().servo;
  ASSERT_EQ(s.state, control::State::Faulted);
  EXPECT_EQ(s.fault.kind, control::FaultKind::EdmShort);
  ASSERT_GE(shorted_at, 0);
  ASSERT_GE(limit_at, shorted_at);
  // The short is timed from its first period: the fault comes 8 s later, to a period or two.
  EXPECT_NEAR(s.time_s - shorted_at, 8, 0.003);
  EXPECT_LT(limit_at - shorted_at, 8);
  EXPECT_NEAR(s.edm.backlog_mm, 20.0, 0.05);
  EXPECT_FALSE(s.edm.generator);
  bool told_limit = false, told_fault = false;
  for (const ControllerEvent& e : events.next()) {
    if (e.kind != ControllerEventKind::Note) continue;
    if (e.code == "control.edm.retract-limit") {
      told_limit = true;
      EXPECT_NE(e.text.find("end of the path memory"), std::string::npos) << e.text;
    }
    if (e.code == "control.fault.edm-short") {
      told_fault = true;
      EXPECT_NE(e.text.find("shorted for 8.00 s, longer than condition 1's short_timeout_s (8 s)"),
                std::string::npos)
          << e.text;
    }
  }
  EXPECT_TRUE(told_limit);
  EXPECT_TRUE(told_fault);
  // The report counts the short that never cleared, with its 8 s until the fault.
  rig.run_until([] { return false; }, 5);
  const edm::EdmReport report = recorder->report();
  EXPECT_EQ(report.shorts, 1u);
  EXPECT_EQ(report.shorts_uncleared, 1u);
  EXPECT_NEAR(report.short_recovery_max_s, 8.0, 0.003);
}

// The finishing cycle's time limit: condition 3's square, full after the burn, must still turn
// once at its 80 µm (a 1 s period); with 50 ms allowed the cycle stops the machine with a fault
// that says how far the orbit came, instead of holding the burn for ever.
TEST(Edm, AFinishingCycleThatOutlastsItsTimeLimitStopsTheMachineWithAFault) {
  config::MachineProfile p = edm({"edm.finish_timeout_s=0.05"});
  for (int i = 0; i < p.edm.config.condition_count; ++i) {
    machine::EdmCondition& c = p.edm.config.conditions[static_cast<std::size_t>(i)];
    if (c.number == 3) c.orbit_finish = c.lateral_servo = true;  // the cycle as shipped
  }
  ASSERT_EQ(p.edm.config.find(3)->finish_timeout_s, 0.05);
  Diagnostics d;
  SimRig rig(p, *features::machine_setup(p, d));
  EventCursor events(rig.controller().events());
  rig.step();
  ASSERT_TRUE(on_and_homed(rig));
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(rig.request(Request::open(write_program(burn(3, 0.003))), 100000).accepted);
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  double finishing_from = -1;
  ASSERT_TRUE(rig.run_until(
      [&] {
        const control::ServoStatus& s = rig.status().servo;
        if (finishing_from < 0 && s.edm.finishing) finishing_from = s.time_s;
        return s.state == control::State::Faulted ||
               (!rig.status().run_active && s.state == control::State::Idle);
      },
      40000));
  const control::ServoStatus s = rig.status().servo;
  ASSERT_EQ(s.state, control::State::Faulted);
  ASSERT_EQ(s.fault.kind, control::FaultKind::EdmFinishTimeout);
  EXPECT_EQ(s.fault.axis, 3);
  EXPECT_EQ(s.fault.limit, 0.05);
  EXPECT_GT(s.fault.value, 0.0);
  EXPECT_LE(s.fault.value, 0.08 + 1e-12);  // here the square is full but has not turned there
  ASSERT_GE(finishing_from, 0);
  // Counted while the cycle machines: 50 ms after it began, to a period or two.
  EXPECT_NEAR(s.time_s - finishing_from, 0.05, 0.003);
  EXPECT_FALSE(s.edm.generator);
  bool told = false;
  for (const ControllerEvent& e : events.next()) {
    if (e.kind != ControllerEventKind::Note || e.code != "control.fault.edm-finish-timeout") continue;
    told = true;
    EXPECT_NE(e.text.find("EDM condition 3's finishing cycle did not bring the orbit to its size within its "
                          "finish_timeout_s (0.05 s): the orbit reached "),
              std::string::npos)
        << e.text;
    EXPECT_NE(e.text.find("its 0.0800 mm but did not turn once there sparking at the final depth"),
              std::string::npos)
        << e.text;
  }
  EXPECT_TRUE(told);
}

// A short that clears within its time is no fault, however long the program runs on.
TEST(Edm, TheShortTimeCountsOnlyAnUnbrokenShort) {
  int shorts = 0;
  double start = -1;  // the run's (after homing)
  const EdmRun r = run(burn(1, 0.03), edm({"edm.short_timeout_s=0.05"}), [&](SimRig& rig) {
    const control::ServoStatus& s = rig.status().servo;
    if (start < 0) start = s.time_s;
    if (shorts < 3 && s.time_s - start > 0.3 * (shorts + 1) && s.edm.generator &&
        s.edm.gap_state == machine::GapState::Normal) {
      rig.machine().inject_edm_short();  // the 20 µm bridge breaks in about 7 ms each time
      ++shorts;
    }
  });
  ASSERT_TRUE(r.finished);
  EXPECT_EQ(shorts, 3);
  EXPECT_EQ(r.rig->status().servo.state, control::State::Idle);
  EXPECT_GE(r.report.shorts, 3u);
  EXPECT_EQ(r.report.shorts_uncleared, 0u);  // each cleared before the burn ended
}

// Resumed at the second feed of condition 2 (ResumeProgram, as run from line and electrode setting
// use it): the condition in force there is selected again and the generator comes on before the
// electrode cuts on: condition 2, not condition 1 nor none.
TEST(Edm, AResumedProgramSelectsTheConditionInForceAgain) {
  const config::MachineProfile p = edm();
  const std::string text =
      "G21 G90\nG0 Z-19.97\nM180 P1\nG1 Z-19.99 F60\nM180 P2\nG1 Z-20.0 F30\nG1 Z-20.02\nM181\n"
      "G0 Z0\nM2\n";
  const std::string path = write_program(text);
  Diagnostics d;
  auto source = features::machine_setup(p, d)->source();
  canon::SegmentId k = 0;  // the segment of line 7 (G1 Z-20.02)
  {
    auto whole = source->execute(path, Pose{}, {});
    for (int i = 0; i < 1000 && whole->state() == StreamState::Reading; ++i) whole->read(100);
    for (std::size_t m = 0; m < whole->program().size(); ++m)
      if (whole->program().move(m).line == 7) k = whole->program().segment_of(m);
  }
  ASSERT_NE(k, 0u);
  SimRig rig(p, *features::machine_setup(p, d));
  rig.step();
  ASSERT_TRUE(on_and_homed(rig));
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Mdi)).accepted);
  ASSERT_TRUE(rig.request(Request::mdi("G0 Z-19.995"), 100000).accepted);  // on segment k's line
  ASSERT_TRUE(rig.run_until(
      [&] { return rig.status().servo.state == control::State::Idle && !rig.status().run_active; }, 20000));
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(rig.request(Request::open(path), 100000).accepted);
  const Outcome resumed = rig.request(Request::resume(k), 100000);
  ASSERT_TRUE(resumed.accepted) << resumed.message;
  int condition_when_burning = -1;
  ASSERT_TRUE(rig.run_until(
      [&] {
        const control::EdmStatus& e = rig.status().servo.edm;
        if (e.generator && condition_when_burning < 0) condition_when_burning = e.condition;
        return !rig.status().run_active && rig.status().servo.state == control::State::Idle;
      },
      60000));
  EXPECT_EQ(condition_when_burning, 2);
  EXPECT_LT(rig.machine().edm().depth_mm(), 0.05);  // it burnt from Z -19.995 to -20.02, no more
  EXPECT_GT(rig.machine().edm().depth_mm(), 0.0);
}

TEST(Edm, JumpsLiftTheElectrodeEveryPeriodWithTheGeneratorOff) {
  const EdmRun r = run(burn(1, 0.02));
  ASSERT_TRUE(r.finished);
  std::vector<double> starts;  // machining time at each jump's start
  double machining = 0, lift_max = 0;
  bool was = false;
  for (const control::TraceSample& s : r.samples->all) {
    if (s.edm.jumping) {
      EXPECT_FALSE(s.edm.generator);
      lift_max = std::max(lift_max, s.edm.jump_lift_mm);
      if (!was) starts.push_back(machining);
    }
    if (s.edm.generator) machining += 0.001;
    was = s.edm.jumping;
  }
  ASSERT_GE(starts.size(), 3u);
  for (std::size_t i = 1; i < starts.size(); ++i) EXPECT_NEAR(starts[i] - starts[i - 1], 0.25, 0.0015);
  EXPECT_NEAR(lift_max, 0.4, 1e-9);
  EXPECT_EQ(r.report.jumps, starts.size());
}

/// The orbit's offsets from the trace: the commanded XY (the program stays at X0 Y0).
struct OrbitSeen {
  double r_max = 0, chebyshev_max = 0;
  int at_full = 0, round = 0;
};

OrbitSeen orbit_of(const EdmRun& r, double radius) {
  OrbitSeen o;
  for (const control::TraceSample& s : r.samples->all) {
    const double x = s.commanded[Axis::X], y = s.commanded[Axis::Y];
    const double rr = std::hypot(x, y);
    o.r_max = std::max(o.r_max, rr);
    o.chebyshev_max = std::max({o.chebyshev_max, std::fabs(x), std::fabs(y)});
    if (s.edm.orbit_radius_mm > radius - 1e-9) {
      ++o.at_full;
      o.round += std::fabs(rr - radius) < 1e-6;
    }
  }
  return o;
}

TEST(Edm, ACircleOrbitGrowsInStepsToItsRadius) {
  const EdmRun r = run(burn(2, 0.03, "F30"), edm({"edm.sim.electrode_area_mm2=20"}));
  ASSERT_TRUE(r.finished);
  const OrbitSeen o = orbit_of(r, 0.05);
  EXPECT_NEAR(o.r_max, 0.05, 1e-9);
  ASSERT_GT(o.at_full, 500);
  EXPECT_EQ(o.round, o.at_full);  // a circle: every sample at the full radius is on it
  // Grew a step per turn: a turn (1 s; the orbit turns through the jumps) after it began, one step.
  double turning = 0;
  for (const control::TraceSample& s : r.samples->all) {
    if (s.edm.orbit_radius_mm > 0) turning += 0.001;
    if (turning > 0.95 && turning < 0.97) {
      EXPECT_NEAR(s.edm.orbit_radius_mm, 0.01, 1e-9);
    }
  }
  // After M181 the orbit came back to the centre before the program ended.
  EXPECT_EQ(r.samples->all.back().commanded[Axis::X], 0.0);
}

TEST(Edm, ASquareOrbitReachesItsCorners) {
  const EdmRun r = run(burn(3, 0.025, "F20"));
  ASSERT_TRUE(r.finished);
  const OrbitSeen o = orbit_of(r, 0.08);
  EXPECT_NEAR(o.chebyshev_max, 0.08, 1e-9);
  EXPECT_NEAR(o.r_max, 0.08 * std::sqrt(2.0), 1e-9);  // the corners
  ASSERT_GT(o.at_full, 200);
  EXPECT_LT(o.round, o.at_full / 4);  // not a circle
}

TEST(Edm, WithoutTheJumpDebrisMakesTheGapArc) {
  const EdmRun with = run(burn(1, 0.04));
  const EdmRun without = run(burn(9, 0.04));
  ASSERT_TRUE(with.finished);
  ASSERT_TRUE(without.finished);
  EXPECT_GT(without.report.arc_periods, 20 * std::max<std::uint64_t>(with.report.arc_periods, 1));
  EXPECT_GT(without.report.arcs, 10u);
  EXPECT_EQ(without.report.jumps, 0u);
  EXPECT_GT(without.report.machining_s, with.report.machining_s);  // arcs remove little
}

// The preflight sees what the gap servo adds to the path: condition 3's square orbit (0.08 mm)
// around a burn 0.05 mm inside X's limit of 150 mm, condition 1's axis jump (0.4 mm up Z) on a
// burn 0.2 mm below Z's limit of 50 mm; both refused at the burn's line, the same burns without
// the orbit or the jump are not.
TEST(Edm, ThePreflightSeesTheOrbitAndTheJump) {
  struct Case {
    std::string program, message;  // message "": accepted
    unsigned line = 4;
  };
  const Case cases[] = {
      {"G21 G90\nG0 X149.95 Z-19.97\nM180 P3\nG1 Z-20.01 F60\nM181\nG0 Z0\nM2\n",
       "with EDM condition 3's orbit (0.08 mm) this move takes X to 150.0300 mm, beyond its maximum soft "
       "limit of 150 mm"},
      {"G21 G90\nG0 Z49.8\nM180 P1\nG1 Z49.7 F60\nM181\nG0 Z0\nM2\n",
       "with EDM condition 1's jump (0.4 mm) this move takes Z to 50.2000 mm, beyond its maximum soft limit"},
      {"G21 G90\nG0 X149.95 Z-19.97\nM180 P1\nG1 Z-20.01 F60\nM181\nG0 Z0\nM2\n", ""},
      // Condition 2's orbit (0.05 mm, 0.01 mm a turn of 1 s) takes 1.25 s to spiral back after
      // M181: the second short move after it is still widened ...
      {"G21 G90\nG0 X149.9 Z-19.97\nM180 P2\nG1 Z-20.01 F60\nM181\nG0 Z-19.9\nG0 X149.97\nG0 Z0\nM2\n",
       "with EDM condition 2's orbit (0.05 mm) and jump (0.3 mm) this move takes X to 150.0200 mm", 7},
      // ... but not once a move that takes at least 2 s (49.9 mm at X's 25 mm/s) has passed.
      {"G21 G90\nG0 X149.9 Z-19.97\nM180 P2\nG1 Z-20.01 F60\nM181\nG0 X100\nG0 X149.97\nG0 Z0\nM2\n", ""},
      // Condition 3's square spirals in while condition 2's circle grows: the larger one counts.
      {"G21 G90\nG0 X149.9 Z-19.97\nM180 P3\nG1 Z-20.01 F60\nM180 P2\nG1 X149.94 Z-20.02 F30\nM181\nG0 "
       "Z0\nM2\n",
       "with EDM condition 3's orbit (0.08 mm) and condition 2's jump (0.3 mm) this move takes X to 150.0200 "
       "mm",
       6},
  };
  for (const Case& c : cases) {
    const config::MachineProfile p = edm();
    Diagnostics d;
    SimRig rig(p, *features::machine_setup(p, d));
    rig.step();
    ASSERT_TRUE(on_and_homed(rig));
    ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
    const Outcome o = rig.request(Request::open(write_program(c.program)), 100000);
    if (c.message.empty()) {
      EXPECT_TRUE(o.accepted) << o.message
                              << (o.diagnostics.items().empty() ? "" : o.diagnostics.items()[0].format());
      continue;
    }
    ASSERT_FALSE(o.accepted) << c.program;
    ASSERT_FALSE(o.diagnostics.items().empty());
    const Diagnostic& first = o.diagnostics.items().front();
    EXPECT_EQ(first.code, "control.soft-limit");
    EXPECT_EQ(first.line, c.line) << c.program;
    EXPECT_NE(first.message.find(c.message), std::string::npos) << first.message;
  }
}

TEST(Edm, ThePreflightRefusesAConditionTheMachineLacks) {
  const EdmRun r = run("G21 G90\nG0 Z-19.97\nM180 P5\nG1 Z-20.01 F60\nM2\n");
  ASSERT_FALSE(r.opened.accepted);
  ASSERT_FALSE(r.opened.diagnostics.items().empty());
  const Diagnostic& d = r.opened.diagnostics.items().front();
  EXPECT_EQ(d.code, "edm.condition");
  EXPECT_EQ(d.line, 3u);
  EXPECT_NE(d.message.find("1, 2, 3, 9"), std::string::npos) << d.message;
}

// An admin's edit of a machining condition while the machine is idle: the file changes in its
// [[edm.condition]] element, the audit says what changed, and a program that selects the
// condition afterwards jumps by the new height; a condition the tick cannot run (handed to it
// directly) makes the apply refuse and leaves the conditions as they were.
// A copy of edm-5axis (and its tool table) in a folder of its own, for the tests that edit the
// profile's conditions; the folder goes with the object.
struct EditableEdm {
  explicit EditableEdm(const std::string& tag)
      : dir(std::filesystem::temp_directory_path() /
            ("opencnc-edm-" + tag + "-" + std::to_string(::getpid()))),
        path((dir / "edm-5axis.toml").string()) {
    std::filesystem::create_directories(dir);
    std::filesystem::copy_file(std::filesystem::path(OPENCNC_SOURCE_DIR "/configs/edm-5axis.tbl"),
                               dir / "edm-5axis.tbl", std::filesystem::copy_options::overwrite_existing);
    // The profile without issue 28's keys (as edm_rig.hpp's edm_profile): these tests measure the
    // jump by the condition's own height, which adaptive control would move.
    std::ifstream in(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml");
    std::ofstream out(path);
    const std::vector<std::string> issue_28 = {
        "adaptive",           "lateral_servo",       "orbit_finish",          "gain_min_mm_s_per_v",
        "gain_max_mm_s_per_v", "jump_period_min_s",  "jump_period_max_s",     "jump_height_min_mm",
        "jump_height_max_mm", "servo_reference_min_v", "servo_reference_max_v", "side_walls",
        "electrode_perimeter_mm", "short_debris"};
    for (std::string line; std::getline(in, line);) {
      const std::string key = line.substr(0, line.find_first_of(" ="));
      if (std::find(issue_28.begin(), issue_28.end(), key) == issue_28.end()) out << line << "\n";
    }
  }
  ~EditableEdm() { std::filesystem::remove_all(dir); }
  const std::filesystem::path dir;
  const std::string path;
  /// The profile as edited so far, with the small electrode the burns use.
  config::MachineProfile profile() const {
    return control::test::loaded(
        config::load_profile(path, std::vector<std::string>{"edm.sim.electrode_area_mm2=5"}));
  }
};

TEST(Edm, AnEditedConditionIsTheOneAProgramSelectsAfterwards) {
  EditableEdm edm("edit");
  const std::string& path = edm.path;
  {
    const config::MachineProfile p = edm.profile();
    Diagnostics d;
    SimRig rig(p, *features::machine_setup(p, d));
    auto samples = std::make_shared<Samples>();
    rig.controller().attach(samples, ObserverOptions{0, true});
    rig.step();
    ASSERT_TRUE(on_and_homed(rig));
    const Outcome o =
        rig.request(Request::edit_profile({{"edm.condition.1.jump_height_mm", "0.25"}}, "admin"));
    ASSERT_TRUE(o.accepted) << o.message;
    EXPECT_EQ(o.message, "edm.condition.1.jump_height_mm 0.4 → 0.25");
    EXPECT_EQ(rig.servo().config().edm.find(1)->jump_height_mm, 0.25);
    std::string text;
    ASSERT_TRUE(read_file(path, text, nullptr));
    EXPECT_NE(text.find("number = 1\non_time_us = 100.0"), std::string::npos);
    EXPECT_NE(text.find("jump_height_mm = 0.25\njump_period_s = 0.25      # T_on"), std::string::npos);

    ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
    ASSERT_TRUE(rig.request(Request::open(write_program(burn(1, 0.01))), 100000).accepted);
    ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
    ASSERT_TRUE(rig.run_until(
        [&] { return !rig.status().run_active && rig.status().servo.state == control::State::Idle; }, 60000));
    double lift_max = 0;
    for (const control::TraceSample& s : samples->all) lift_max = std::max(lift_max, s.edm.jump_lift_mm);
    EXPECT_NEAR(lift_max, 0.25, 1e-9);

    control::EdmConditionTable& bad = rig.channels().edm_conditions;
    bad.conditions = rig.servo().config().edm.conditions;
    bad.count = rig.servo().config().edm.condition_count;
    bad.conditions[0].servo_reference_v = bad.conditions[0].voltage_v;  // the gap would never burn
    control::Command stage;
    stage.id = 78001;
    stage.kind = control::CommandKind::StageEdmConditions;
    control::Command apply;
    apply.id = 78002;
    apply.kind = control::CommandKind::ApplyJointLimits;
    ASSERT_TRUE(rig.channels().commands.try_push(stage) && rig.channels().commands.try_push(apply));
    rig.run(3);
    ASSERT_TRUE(rig.controller().outcome(78002).has_value());
    EXPECT_EQ(rig.controller().outcome(78002)->refusal, control::Refusal::BadValue);
    EXPECT_EQ(rig.servo().config().edm.find(1)->servo_reference_v, 45.0);
  }
}

// Conditions added and deleted by the admin while idle: a program opened after the add selects
// the new condition and burns with its values (a copy of 1, its jump lowered); deleting the
// condition the open program selects is refused at the program's line; an MDI line (its session
// older than the change) and a program opened after a delete get the interpreter's error for an
// unknown condition. The event log says "machining conditions changed".
TEST(Edm, AnAddedConditionIsSelectableAndADeletedOneIsNot) {
  EditableEdm edm("add");
  {
    const config::MachineProfile p = edm.profile();
    Diagnostics d;
    // Run from line (set up with the others) reads the program with a source of its own, made
    // before the add.
    SimRig rig(p, *features::machine_setup(p, d));
    auto samples = std::make_shared<Samples>();
    rig.controller().attach(samples, ObserverOptions{0, true});
    rig.step();
    ASSERT_TRUE(on_and_homed(rig));
    ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
    const std::string five = write_program(burn(5, 0.01));
    const Outcome unknown = rig.request(Request::open(five), 100000);
    ASSERT_FALSE(unknown.accepted);  // no condition 5 yet
    Outcome o = rig.request(Request::change_conditions({{5, false, 1}}, "admin"));
    ASSERT_TRUE(o.accepted) << o.message;
    o = rig.request(Request::edit_profile({{"edm.condition.5.jump_height_mm", "0.15"}}, "admin"));
    ASSERT_TRUE(o.accepted) << o.message;
    EXPECT_EQ(rig.servo().config().edm.condition_count, 5);
    ASSERT_TRUE(rig.request(Request::open(five), 100000).accepted);
    // The open program selects 5 at its line 3: it stays.
    o = rig.request(Request::change_conditions({{5, true, 0}}, "admin"));
    ASSERT_FALSE(o.accepted);
    EXPECT_EQ(o.refusal, control::Refusal::ProgramError);
    EXPECT_NE(o.message.find(five + ":3:"), std::string::npos) << o.message;
    ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
    int condition = 0;
    ASSERT_TRUE(rig.run_until(
        [&] {
          condition = std::max(condition, rig.status().servo.edm.condition);
          return !rig.status().run_active && rig.status().servo.state == control::State::Idle;
        },
        60000));
    EXPECT_EQ(condition, 5);
    double lift_max = 0;
    for (const control::TraceSample& s : samples->all) lift_max = std::max(lift_max, s.edm.jump_lift_mm);
    EXPECT_NEAR(lift_max, 0.15, 1e-9);
    // Run from line 4 scans past the M180 P5 at line 3: its source knows the added condition too.
    const Outcome from =
        rig.request(Request::feature("run-from-line", "start", run_from_line::RunFromLineArgs{4}), 100000);
    EXPECT_TRUE(from.accepted) << from.message;
    // The approach (an auxiliary job), then the program from line 4 to its end.
    ASSERT_TRUE(
        rig.run_until([&] { return rig.status().run_active && rig.status().job == JobKind::Program; }, 60000))
        << rig.status().fault_text;
    ASSERT_TRUE(rig.run_until(
        [&] { return !rig.status().run_active && rig.status().servo.state == control::State::Idle; }, 60000))
        << rig.status().fault_text;
    EXPECT_TRUE(rig.status().fault_text.empty()) << rig.status().fault_text;
    // 9 deleted: an MDI line (its session made before) and a program opened afterwards that
    // select it get the interpreter's message.
    const Outcome to_mdi = rig.request(Request::set_mode(control::Mode::Mdi));
    ASSERT_TRUE(to_mdi.accepted) << to_mdi.message;
    const auto mdi = [&](const char* line) {
      const Outcome m = rig.request(Request::mdi(line), 100000);
      rig.run_until(
          [&] { return !rig.status().run_active && rig.status().servo.state == control::State::Idle; },
          20000);
      return m;
    };
    ASSERT_TRUE(mdi("G0 Z0").accepted);
    o = rig.request(Request::change_conditions({{9, true, 0}}, "admin"));
    ASSERT_TRUE(o.accepted) << o.message;
    EXPECT_EQ(rig.servo().config().edm.find(9), nullptr);
    const Outcome m9 = mdi("M180 P9");
    EXPECT_FALSE(m9.accepted);
    ASSERT_FALSE(m9.diagnostics.items().empty());
    EXPECT_NE(m9.diagnostics.items().front().message.find("(1, 2, 3, 5)"), std::string::npos);
    ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
    const std::string nine = write_program(burn(9, 0.01));
    o = rig.request(Request::open(nine), 100000);
    ASSERT_FALSE(o.accepted);
    ASSERT_FALSE(o.diagnostics.items().empty());
    const Diagnostic& e = o.diagnostics.items().front();
    EXPECT_EQ(e.line, 3u);
    EXPECT_NE(e.message.find("machining conditions as P (1, 2, 3, 5)"), std::string::npos) << e.message;
    bool noted = false;
    EventCursor cursor(rig.controller().events(), true);
    for (const ControllerEvent& ev : cursor.next())
      noted |=
          ev.code == "control.profile" &&
          ev.text.rfind("admin: machining conditions changed: edm.condition.9 defined → deleted", 0) == 0;
    EXPECT_TRUE(noted);
  }
}

// The setter's seek of the end of the travel through the controller: the request, the note that
// says where the switch tripped and where the axis rests, the status; C (no limit switch) refused
// with the reason.
TEST(EdmSeek, TheControllerSaysWhereTheLimitSwitchTripped) {
  const config::MachineProfile p = edm({"axis.y.sim.start_position=95.0"});
  Diagnostics d;
  SimRig rig(p, *features::machine_setup(p, d));
  EventCursor events(rig.controller().events());
  rig.step();
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Manual)).accepted);
  const Outcome refused = rig.request(Request::seek_limit(Axis::C, -1));
  EXPECT_FALSE(refused.accepted);
  EXPECT_EQ(refused.refusal, control::Refusal::NoLimitSwitch);
  EXPECT_NE(refused.message.find("no limit switch on that side"), std::string::npos) << refused.message;
  ASSERT_TRUE(rig.request(Request::seek_limit(Axis::Y, +1)).accepted);
  bool running_shown = false;
  ASSERT_TRUE(rig.run_until(
      [&] {
        running_shown = running_shown || rig.status().servo.seek[1].phase == control::SeekPhase::Search;
        return rig.status().servo.state == control::State::Idle;
      },
      20000));
  EXPECT_TRUE(running_shown);
  std::string note;
  for (const ControllerEvent& e : events.next()) {
    if (e.code == "control.seek-limit") note = e.text;
  }
  const control::LimitSeekStatus st = rig.status().servo.seek[1];
  EXPECT_TRUE(st.found);
  EXPECT_NEAR(st.tripped_at, 101.0, 0.002);  // the switch's noise: 1 µm
  EXPECT_NEAR(st.rest_at, 100.49, 0.002);    // not homed: 0.5 mm off where it released
  EXPECT_EQ(note, fmt::format("Y's + limit switch trips at {:.4f} mm; the axis backed off to {:.4f} mm",
                              st.tripped_at, st.rest_at));
}

/// Runs until the machine is idle again with nothing moving; false if that takes `ticks`.
bool comes_to_rest(SimRig& rig, std::uint64_t ticks) {
  return rig.run_until(
      [&] {
        return rig.status().servo.state == control::State::Idle &&
               rig.status().servo.activity == control::Activity::None;
      },
      ticks);
}

TEST(EdmJog, ZJogsOnTheHomedMachineEnd) {
  // Reported last stop: a Z jog on the homed EDM that never finished (the mover creeping about its
  // goal at 1e-10 mm/s, fixed with homing on switches). Incremental, continuous with a stop, and
  // continuous to the soft limit: each ends, where it should, within a stepper step.
  const config::MachineProfile p = edm();
  Diagnostics d;
  SimRig rig(p, *features::machine_setup(p, d));
  ASSERT_TRUE(on_and_homed(rig));
  const double step = 1 / 1600.0;
  const auto z = [&] { return rig.status().servo.commanded[Axis::Z]; };
  ASSERT_TRUE(rig.request(Request::jog_by(Axis::Z, -5.0, 10.0)).accepted);
  ASSERT_TRUE(comes_to_rest(rig, 2000)) << "5 mm at 10 mm/s: 0.5 s and its ramps";
  EXPECT_NEAR(z(), -5.0, 1e-9);
  EXPECT_NEAR(rig.status().servo.actual[Axis::Z], -5.0, step);
  ASSERT_TRUE(rig.request(Request::jog_by(Axis::Z, 0.001, 0.2)).accepted);  // one handwheel count
  ASSERT_TRUE(comes_to_rest(rig, 1000));
  EXPECT_NEAR(z(), -4.999, 1e-9);
  ASSERT_TRUE(rig.request(Request::jog(Axis::Z, 20.0)).accepted);
  rig.run(200);
  EXPECT_EQ(rig.status().servo.state, control::State::Running);
  ASSERT_TRUE(rig.request(Request::jog_stop(Axis::Z)).accepted);
  ASSERT_TRUE(comes_to_rest(rig, 500)) << "stopped from 20 mm/s at 2 m/s²: 10 ms";
  EXPECT_GT(z(), -1.0);
  ASSERT_TRUE(rig.request(Request::jog(Axis::Z, 60.0)).accepted);
  ASSERT_TRUE(comes_to_rest(rig, 3000)) << "to the + soft limit, 51 mm at 60 mm/s";
  EXPECT_NEAR(z(), 50.0, 1e-9);
  EXPECT_NEAR(rig.status().servo.actual[Axis::Z], 50.0, step);
}

}  // namespace
}  // namespace opencnc::controller::test
