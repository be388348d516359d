// SPDX-License-Identifier: GPL-3.0-or-later
// Spindle-driven motion through the whole controller on the simulated machine (issue 6): G33.1
// rigid tapping that follows the simulated spindle's encoder through its reversal, G96 constant
// surface speed computed from X every servo period, and arcs whose end is off the start circle
// run as LinuxCNC's spiral.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

constexpr double kTwoPi = 6.283185307179586;

/// One servo period as the machine saw it.
struct Period {
  double z = 0, x = 0;  ///< commanded (machine) Z and X (the status: one period old)
  double z_true = 0;    ///< the simulated Z table's true position
  double revs = 0;      ///< the simulated spindle's true position (revolutions)
  double rpm_cmd = 0;   ///< commanded spindle speed magnitude
  machine::SpindleDirection dir = machine::SpindleDirection::Stopped;
  std::uint32_t line = 0;
};

/// Runs the program to its end, recording every period.
std::vector<Period> run_recording(Scenario& s, const std::string& path, bool& finished) {
  s.must(Request::open(path));
  const std::uint64_t before = s.status().runs_finished;
  s.forget_samples();
  s.must(Request::simple(control::CommandKind::CycleStart));
  std::vector<Period> periods;
  finished = s.until(
      [&] {
        const ControllerStatus st = s.status();
        Period p;
        p.z = st.servo.commanded[Axis::Z];
        p.x = st.servo.commanded[Axis::X];
        p.z_true = s.sim().joint(2).table_position();
        p.revs = s.sim().spindle().position_rev();
        p.rpm_cmd = st.servo.spindle_rpm;
        p.dir = st.servo.spindle_direction;
        p.line = st.servo.line;
        periods.push_back(p);
        return !st.run_active && st.runs_finished > before;
      },
      400000);
  return periods;
}

}  // namespace

TEST(SpindleScenario, RigidTapFollowsTheSpindleThroughItsReversalAndComesBackOut) {
  Scenario s(control::test::mill());
  TempProgram p("tap.ngc",
                "G21 G90\n"                // 1
                "S600 M3\n"                // 2
                "G0 X10 Y10 Z3\n"          // 3
                "G33.1 Z-12 K1.25 I1.5\n"  // 4: M8 × 1.25, out at 900 rpm
                "G0 Z20\n"                 // 5
                "M5\n"                     // 6
                "M2\n");
  s.on(control::Mode::Auto);
  bool finished = false;
  const std::vector<Period> t = run_recording(s, p.path(), finished);
  ASSERT_TRUE(finished) << s.message();
  // The spindle: clockwise at 600 rpm into the hole, counterclockwise at 900 rpm out of it, then
  // clockwise again; the tap spends its whole time in the thread at pitch 1.25 per turn.
  std::vector<machine::SpindleDirection> dirs;
  double reversed_rpm = 0, deepest = 1e9, highest_after = -1e9;
  double phase = 0;
  bool have_phase = false;
  double worst_phase = 0;
  for (const Period& q : t) {
    if (q.line != 4) continue;
    if (dirs.empty() || dirs.back() != q.dir) dirs.push_back(q.dir);
    if (q.dir == machine::SpindleDirection::Counterclockwise) reversed_rpm = q.rpm_cmd;
    deepest = std::min(deepest, q.z);
    if (dirs.size() >= 3) highest_after = std::max(highest_after, q.z);
    // While the tap is in the material (below Z 3 - a turn), depth and spindle angle keep one
    // relation: the tap is in one thread on the way in and on the way out.
    if (q.z_true < 3 - 1.25) {
      const double v = (3 - q.z_true) - 1.25 * q.revs;
      if (!have_phase) {
        phase = v;
        have_phase = true;
      }
      worst_phase = std::max(worst_phase, std::fabs(v - phase));
    }
  }
  ASSERT_EQ(dirs.size(), 3u);
  EXPECT_EQ(dirs[0], machine::SpindleDirection::Clockwise);
  EXPECT_EQ(dirs[1], machine::SpindleDirection::Counterclockwise);
  EXPECT_EQ(dirs[2], machine::SpindleDirection::Clockwise);
  EXPECT_DOUBLE_EQ(reversed_rpm, 900);
  EXPECT_LE(deepest, -12.0);
  EXPECT_GE(deepest, -12.0 - 1.0);  // 600 rpm stopping at 4000 rpm/s: 0.75 rev = 0.94 mm
  EXPECT_GT(highest_after, 3.0);    // out of the hole, past the start while the spindle turns back
  // The true Z table against the spindle's true angle: one thread within 10 µm (measured 4.6 µm:
  // the drive's following error changes sign with the direction, the encoder reads 1/4096 rev).
  EXPECT_LE(worst_phase, 0.010);
  // Back on the start, then up: the program ended where it says.
  EXPECT_NEAR(t.back().z, 20.0, 1e-9);
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u);
  EXPECT_LE(r.max_command_contour_error_mm, 1e-9);  // on the tap's line throughout
}

TEST(SpindleScenario, ConstantSurfaceSpeedDrivesTheSpindleFromXEveryPeriod) {
  Scenario s(control::test::mill());
  TempProgram p("css.ngc",
                "G21 G90 G18\n"        // 1
                "G10 L2 P1 X7\n"       // 2: the spindle axis at machine X 7
                "G0 X60 Z0\n"          // 3
                "G96 D3000 S120 M3\n"  // 4: 120 m/min, at most 3000 rpm
                "G1 X1 F600\n"         // 5: towards the axis
                "G97 S900\n"           // 6
                "G1 X30\n"             // 7
                "M5\n"                 // 8
                "M2\n");
  s.on(control::Mode::Auto);
  bool finished = false;
  const std::vector<Period> t = run_recording(s, p.path(), finished);
  ASSERT_TRUE(finished) << s.message();
  int css = 0, clamped = 0, rpm_mode = 0;
  for (const Period& q : t) {
    if (q.line == 5 && q.dir == machine::SpindleDirection::Clockwise) {
      const double radius = std::fabs(q.x - 7.0);
      const double want = std::min(120000.0 / (kTwoPi * radius), 3000.0);
      EXPECT_NEAR(q.rpm_cmd, want, 1e-9 * want) << "X " << q.x;
      ++css;
      clamped += want == 3000.0;
    }
    if (q.line == 7) {
      EXPECT_DOUBLE_EQ(q.rpm_cmd, 900);
      ++rpm_mode;
    }
  }
  EXPECT_GT(css, 1000);
  EXPECT_GT(clamped, 10);  // within 6.4 mm of the axis the D limit holds it
  EXPECT_GT(rpm_mode, 100);
  // The simulated spindle follows the command within its acceleration limit.
  EXPECT_GT(std::fabs(s.sim().spindle().speed_rps()), 0.0);
}

TEST(SpindleScenario, ConstantSurfaceSpeedWithoutDIsBoundByTheSpindlesMaximum) {
  Scenario s(control::test::mill());
  TempProgram p("css2.ngc", "G21 G90\nG0 X40\nG96 S200 M3\nG1 X0.5 F900\nM5\nM2\n");
  s.on(control::Mode::Auto);
  bool finished = false;
  const std::vector<Period> t = run_recording(s, p.path(), finished);
  ASSERT_TRUE(finished) << s.message();
  double highest = 0;
  for (const Period& q : t) {
    if (q.line == 4) highest = std::max(highest, q.rpm_cmd);
  }
  EXPECT_DOUBLE_EQ(highest, 8000);  // configs/mill-3axis.toml: spindle.max_rpm
}

TEST(SpindleScenario, ArcsOffTheirCircleRunAsSpiralsWithinTheLimits) {
  Scenario s(control::test::mill());
  TempProgram p("spiral.ngc",
                "G21 G90 G64 P0.01 F2400\n"
                "G0 X5 Y0\n"
                "G3 X0 Y5.025 I-5 J0\n"
                "G3 X-5 Y0 I0 J-5.025\n"
                "G1 X0 Y300\n"
                "G2 X0 Y-299.75 I0 J-300\n"
                "M2\n");
  s.on(control::Mode::Auto);
  ASSERT_TRUE(s.run_file(p.path())) << s.message();
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u);
  EXPECT_LE(r.max_command_contour_error_mm, 0.01 * (1 + 1e-9));
  EXPECT_NEAR(s.status().servo.commanded[Axis::Y], -299.75, 1e-9);
}

// M99 in the main program: LinuxCNC's task starts the program again from its first line with the
// state as it is (the counter below goes on counting), until the operator stops the run.
TEST(EndlessProgramScenario, M99InTheMainProgramRepeatsItUntilTheOperatorStops) {
  Scenario s(control::test::mill());
  TempProgram p("warmup.ngc",
                "G21 G90 F6000\n"
                "#<_pass> = [#<_pass> + 1]\n"
                "G1 X[#<_pass> * 2] Y0\n"
                "G1 Y10\n"
                "G0 Y0\n"
                "M99\n");
  s.on(control::Mode::Auto);
  const Outcome opened = s.ask(Request::open(p.path()));
  ASSERT_TRUE(opened.accepted) << s.message();
  // The preflight reads the program once, as rs274 does, and says that a run repeats it.
  bool warned = false;
  for (const auto& d : opened.diagnostics.items()) warned = warned || d.code == "gcode.main-program-repeats";
  EXPECT_TRUE(warned) << s.message();
  const std::uint64_t finished = s.status().runs_finished;
  s.must(Request::simple(control::CommandKind::CycleStart));
  // Ten passes: X steps 2 mm each time round.
  ASSERT_TRUE(s.until([&] { return s.status().servo.commanded[Axis::X] >= 20.0 - 1e-9; }, 200000));
  EXPECT_TRUE(s.status().run_active);
  s.must(Request::simple(control::CommandKind::Abort));
  ASSERT_TRUE(s.idle(20000));
  EXPECT_FALSE(s.status().run_active);
  EXPECT_EQ(s.status().runs_finished, finished);  // stopped, never finished
  EXPECT_EQ(s.report().limit_violations, 0u);
}

}  // namespace opencnc::controller::test
