// SPDX-License-Identifier: GPL-3.0-or-later
// The drill retrofit through the whole controller on its simulated machine: the bearing cap's two
// holes drilled, enlarged and reamed with a simulated operator (hand feed of the quill, manual
// tool changes), their positions against the program; e-stop and every hard limit during motion;
// a lost step found when the machine homes again after the part.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

constexpr int kX = 0, kY = 1, kZ = 2;
const std::string kProgram = std::string(OPENCNC_SOURCE_DIR) + "/examples/drill-bearing-cap.ngc";

/// Where machine 0 is on the simulated table: the middle of the sensor's edges, the rising one
/// at level 0.5 (the zone's start, −2.0 at 20 °C) and the falling one below 0.45 (25 µm past its
/// end at +2.0).
constexpr double kOriginOnTable = 0.5 * (-2.0 + 2.025);

/// The machine's operator: brings the quill where a waiting program wants it (fast up, feeding
/// down), changes the tool when asked (in 3 s), and nothing else.
class Operator {
 public:
  explicit Operator(Scenario& s) : s_(s) {}

  /// One look at the machine, every period.
  void act() {
    const control::ServoStatus& v = status_ = s_.status().servo;
    if (v.wait == control::Wait::HandAxis && v.hand_wait.axis == kZ) {
      s_.sim().set_hand_target(kZ, v.hand_wait.target, v.hand_wait.retract ? 40.0 : 3.0);
      if (!v.hand_wait.retract) plunged_to_ = v.hand_wait.target;
    }
    if (v.wait == control::Wait::ManualToolChange) {
      if (++changing_ == 3000) {
        s_.rig().controller().submit(Request::simple(control::CommandKind::ToolChanged));
        ++tool_changes_;
      }
    } else {
      changing_ = 0;
    }
  }
  const control::ServoStatus& status() const { return status_; }
  int tool_changes() const { return tool_changes_; }

 private:
  Scenario& s_;
  control::ServoStatus status_{};
  int changing_ = 0;
  int tool_changes_ = 0;
  double plunged_to_ = 0;
};

/// The table's place in machine coordinates, from the simulated machine's ground truth.
double table_x(Scenario& s) {
  return s.sim().joint(kX).table_position() - kOriginOnTable;
}
double table_y(Scenario& s) {
  return s.sim().joint(kY).table_position() - kOriginOnTable;
}

void home(Scenario& s) {
  s.on(control::Mode::Manual);
  s.must(Request::home());
  ASSERT_TRUE(s.until(
      [&] { return s.status().servo.state == control::State::Idle && s.status().servo.all_homed; }, 100000));
}

struct Hole {
  double x = 0, y = 0, worst = 0;
  int tools = 0;
};

TEST(DrillScenario, BearingCapHolesWithinFiveMicrometres) {
  Scenario s(control::test::drill());
  home(s);
  s.must(Request::set_mode(control::Mode::Auto));
  s.must(Request::open(kProgram));
  Operator op(s);
  // While the quill is down in a hole the table must stand where the program put it.
  std::vector<Hole> holes{{150.0, 140.0}, {530.0, 140.0}};
  int interlock_stops = 0;
  int cutting_without_spindle = 0;  // periods with the tool in the part and the spindle not at speed
  bool down = false;
  EventCursor events(s.rig().controller().events());
  s.must(Request::simple(control::CommandKind::CycleStart));
  const bool finished = s.until(
      [&] {
        op.act();
        for (const ControllerEvent& e : events.next()) interlock_stops += e.code == "control.interlock";
        const double z = s.status().servo.joints[kZ].actual;
        const bool in_part = z < -60.0 - 1.0;  // the tool below the cap's face
        if (in_part) {
          cutting_without_spindle += s.status().servo.spindle_at_speed ? 0 : 1;
          for (Hole& h : holes) {
            if (std::abs(table_x(s) - h.x) > 1.0) continue;
            h.worst = std::max({h.worst, std::abs(table_x(s) - h.x), std::abs(table_y(s) - h.y)});
            if (!down) ++h.tools;
          }
        }
        down = in_part;
        return !s.status().run_active && s.status().runs_finished > 0;
      },
      2'000'000);
  ASSERT_TRUE(finished) << "state " << to_string(s.status().servo.state) << " " << s.status().fault_text;
  EXPECT_EQ(op.tool_changes(), 3);
  for (const Hole& h : holes) {
    EXPECT_EQ(h.tools, 3) << h.x;  // drilled, enlarged, reamed
    EXPECT_LE(h.worst, 0.005) << h.x;
    std::printf("hole at X%.0f Y%.0f: table within %.2f µm of it while the tools were in it\n", h.x, h.y,
                1000 * h.worst);
  }
  // The PLC stopped the spindle each time the quill came back to its top stop with it running, and
  // held each start back until the table stood still: no tool entered the part without it.
  EXPECT_GE(interlock_stops, 3);
  EXPECT_EQ(cutting_without_spindle, 0);
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u) << "output: " << r.output_limit_violations << " first at "
                                    << r.first_output_violation.time_s << " s, axis "
                                    << r.first_output_violation.axis << " derivative "
                                    << r.first_output_violation.derivative << " "
                                    << r.first_output_violation.value << " > "
                                    << r.first_output_violation.limit;
  EXPECT_GT(r.max_compensation_mm, 0.03);
  // After the part the machine homes again: nothing was lost, the origin is where it was.
  ASSERT_TRUE(s.until(
      [&] { return s.status().servo.state == control::State::Idle && s.status().servo.all_homed; }, 100000));
  EXPECT_LE(std::abs(s.status().servo.homing[kX].origin_shift), 0.001);
  EXPECT_LE(std::abs(s.status().servo.homing[kY].origin_shift), 0.001);
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 0.0);
}

// Steps lost without a stall detector (Y) go unseen during the part; homing again after it finds
// them: the positions had been off by what was lost.
TEST(DrillScenario, HomingAfterThePartFindsLostSteps) {
  Scenario s(control::test::drill());
  home(s);
  s.must(Request::set_mode(control::Mode::Auto));
  TempProgram p("y.ngc", "G21 G90\nG0 X20 Y100\nG4 P0.5\nG1 Y101 F600\nG4 P0.5\nG0 Y10\nM30\n");
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  int pushed = 0;
  ASSERT_TRUE(s.until(
      [&] {
        // A chip jams the saddle for 20 ms as the short move starts: more than the motor can pull.
        const control::ServoStatus& v = s.status().servo;
        if (pushed == 0 && v.line == 4 && v.path_velocity > 0) {
          s.sim().set_external_effort(kY, -1500.0);
          pushed = 1;
        } else if (pushed > 0 && ++pushed == 21) {
          s.sim().set_external_effort(kY, 0.0);
        }
        return !s.status().run_active;
      },
      200000));
  ASSERT_EQ(s.status().runs_finished, 1u) << s.status().fault_text;
  const double lost_mm = static_cast<double>(s.sim().joint(kY).lost_steps()) / 640.0;
  EXPECT_GT(lost_mm, 1.0);
  ASSERT_TRUE(s.until(
      [&] { return s.status().servo.state == control::State::Idle && s.status().servo.all_homed; }, 100000));
  EXPECT_NEAR(s.status().servo.homing[kY].origin_shift, lost_mm, 0.002);
  EXPECT_LE(std::abs(s.status().servo.homing[kX].origin_shift), 0.001);
  // Homed again, the table stands where the controller says.
  s.ticks(500);
  EXPECT_NEAR(table_y(s), s.status().servo.joints[kY].actual, 0.003);
}

// The table moves only with the quill where the program left it: brought down while the table
// traverses, the run holds (with a warning naming the axis), cycle start is refused until the
// quill is back up, and then the run goes on to its end.
TEST(DrillScenario, TheQuillLeavingItsPlaceHoldsTheTable) {
  Scenario s(control::test::drill());
  home(s);
  s.must(Request::set_mode(control::Mode::Auto));
  TempProgram p("q.ngc", "G21 G90\nG0 X20 Y20\nG1 Z-5 F100\nG0 Z0\nG0 X300\nM30\n");
  s.must(Request::open(p.path()));
  Operator op(s);
  EventCursor events(s.rig().controller().events());
  s.must(Request::simple(control::CommandKind::CycleStart));
  bool pushed = false;
  ASSERT_TRUE(s.until(
      [&] {
        op.act();
        const control::ServoStatus& v = s.status().servo;
        if (!pushed && v.commanded[Axis::X] > 100.0) {
          s.sim().set_hand_target(kZ, -2.0, 20.0);  // the operator lowers the quill on the way
          pushed = true;
        }
        return v.state == control::State::Held;
      },
      200000));
  int warnings = 0;
  for (const ControllerEvent& e : events.next()) warnings += e.code == "control.hand-axis";
  EXPECT_EQ(warnings, 1);
  ASSERT_TRUE(s.until([&] { return s.status().servo.path_velocity == 0; }, 5000));
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::CycleStart)).refusal, control::Refusal::HandAxis);
  s.sim().set_hand_target(kZ, 0.0, 20.0);
  s.ticks(1000);
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return !s.status().run_active; }, 100000));
  EXPECT_EQ(s.status().runs_finished, 1u) << s.status().fault_text;
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 300.0);
}

// "block spindle unless tool_up and …": an M3 with the quill down waits before the move
// (Wait::Interlock, the rule in status) and starts the spindle once the quill is back at the top
// ("stop spindle when tool_up" stops a turning spindle, not a start that waits), then the move.
TEST(DrillScenario, ASpindleStartWaitsForItsInterlock) {
  Scenario s(control::test::drill());
  home(s);
  s.sim().set_hand_target(kZ, -5.0, 20.0);
  s.ticks(1000);
  s.must(Request::set_mode(control::Mode::Mdi));
  s.must(Request::mdi("M3 S600 G1 X30 F300"));
  ASSERT_TRUE(s.until([&] { return s.status().servo.wait == control::Wait::Interlock; }, 5000));
  EXPECT_EQ(s.status().servo.interlock_rule, 2);
  s.ticks(500);
  EXPECT_EQ(s.status().servo.wait, control::Wait::Interlock);
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 0.0);
  EXPECT_EQ(s.sim().spindle().speed_rps(), 0.0);
  s.sim().set_hand_target(kZ, 0.0, 20.0);
  ASSERT_TRUE(s.until([&] { return !s.status().run_active; }, 20000));
  EXPECT_EQ(s.status().runs_finished, 1u) << s.status().fault_text;
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 30.0);
  EXPECT_EQ(s.status().servo.spindle_direction, machine::SpindleDirection::Clockwise);
  s.ticks(5);  // the table at rest again: the rule no longer holds
  EXPECT_EQ(s.status().servo.interlock_rule, -1);
}

/// How far a table coasting at `v` mm/s stops on its friction alone (drives without power), and
/// one period of travel before anything reacts.
double coast_bound(const config::MachineProfile& p, Axis a, double v) {
  const config::AxisProfile& ax = *p.find(a);
  const double decel = ax.sim.coulomb_friction / ax.sim.inertia * 1000;  // mm/s²
  return v * v / (2 * decel) + v * p.servo_period_s;
}

TEST(DrillScenario, EStopDuringAProgramStopsAndRefusesMotionUntilResetAndHomed) {
  const config::MachineProfile profile = control::test::drill();
  Scenario s(profile);
  home(s);
  s.must(Request::set_mode(control::Mode::Auto));
  TempProgram p("x.ngc", "G21 G90\nG0 X500 Y20\nM30\n");
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.joints[kX].commanded > 200.0; }, 100000));
  const double v = std::abs(s.status().servo.joints[kX].velocity);
  EXPECT_GT(v, 40.0);
  const double at = s.sim().joint(kX).table_position();
  s.sim().set_estop_pressed(true);
  ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::EStopped; }, 10));
  s.ticks(2000);
  EXPECT_FALSE(s.status().run_active);
  EXPECT_FALSE(s.status().servo.drives_enabled);
  const double coasted = s.sim().joint(kX).table_position() - at;
  EXPECT_GE(coasted, 0.0);
  EXPECT_LE(coasted, coast_bound(profile, Axis::X, v) + 0.05);  // + one period of the period's steps
  EXPECT_EQ(s.sim().joint(kX).velocity(), 0.0);
  // Motion is refused until reset; reset until the button is released; then the steppers, which
  // lost their place without power, must home again before a program may run.
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::CycleStart)).refusal, control::Refusal::EStopActive);
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::Reset)).refusal, control::Refusal::EStopInput);
  s.sim().set_estop_pressed(false);
  s.ticks(2);
  s.must(Request::simple(control::CommandKind::Reset));
  s.must(Request::simple(control::CommandKind::MachineOn));
  EXPECT_FALSE(s.status().servo.all_homed);
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::CycleStart)).refusal, control::Refusal::NotHomed);
  s.must(Request::set_mode(control::Mode::Manual));
  s.must(Request::home());
  ASSERT_TRUE(s.until(
      [&] { return s.status().servo.state == control::State::Idle && s.status().servo.all_homed; }, 100000));
  s.must(Request::set_mode(control::Mode::Auto));
  EXPECT_TRUE(s.start_and_finish());
}

struct LimitCase {
  Axis axis;
  double direction;
  double switch_at;  ///< table position of the switch
};

// Every hard limit, met at full speed: the machine stops within the coasting distance past the
// switch, refuses to go further, may jog off it after reset, and must home before a program.
TEST(DrillScenario, EveryHardLimitStopsTheMachineAndRefusesMotionPastIt) {
  const config::MachineProfile profile = control::test::drill();
  for (const LimitCase& c : {LimitCase{Axis::X, -1, -12.0}, LimitCase{Axis::X, 1, 612.0},
                             LimitCase{Axis::Y, -1, -12.0}, LimitCase{Axis::Y, 1, 412.0}}) {
    SCOPED_TRACE(std::string(1, letter(c.axis)) + (c.direction > 0 ? "+" : "-"));
    const int j = index(c.axis);
    Scenario s(control::test::drill({std::string("axis.") + letter(c.axis) + ".sim.start_position=" +
                                     (c.direction > 0 ? std::to_string(c.switch_at - 30) : "20.0")}));
    s.on(control::Mode::Manual);
    ASSERT_EQ(s.status().servo.state, control::State::Idle);
    // Unhomed: no soft limits, so a jog at full speed runs into the switch.
    s.must(Request::jog(c.axis, c.direction * 48.0));
    ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::Faulted; }, 100000));
    EXPECT_EQ(s.status().servo.fault.kind, control::FaultKind::LimitSwitch);
    EXPECT_EQ(s.status().servo.fault.axis, j);
    s.ticks(2000);
    const double past = c.direction * (s.sim().joint(j).table_position() - c.switch_at);
    EXPECT_GE(past, 0.0);
    EXPECT_LE(past, coast_bound(profile, c.axis, 48.0) + 0.05);
    EXPECT_EQ(s.ask(Request::jog(c.axis, c.direction * 10.0)).refusal, control::Refusal::Faulted);
    s.must(Request::simple(control::CommandKind::Reset));
    s.must(Request::simple(control::CommandKind::MachineOn));
    EXPECT_EQ(s.ask(Request::jog(c.axis, c.direction * 10.0)).refusal, control::Refusal::LimitSwitch);
    s.must(Request::jog(c.axis, -c.direction * 10.0));  // off the switch
    ASSERT_TRUE(s.until(
        [&] {
          return !s.status().servo.joints[static_cast<std::size_t>(j)].limit_neg &&
                 !s.status().servo.joints[static_cast<std::size_t>(j)].limit_pos;
        },
        20000));
    s.must(Request::jog_stop());
    ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::Idle; }, 20000));
    s.must(Request::set_mode(control::Mode::Mdi));
    EXPECT_EQ(s.ask(Request::mdi("G0 X10 Y10")).refusal, control::Refusal::NotHomed);
  }
}

// A limit switch met by a program (a switch set inside the travel: an obstacle on the way).
TEST(DrillScenario, HardLimitDuringAProgram) {
  const config::MachineProfile profile = control::test::drill({"axis.x.switches.limit_max=300.0"});
  Scenario s(profile);
  home(s);
  s.must(Request::set_mode(control::Mode::Auto));
  TempProgram p("x.ngc", "G21 G90\nG0 X500 Y20\nM30\n");
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::Faulted; }, 100000));
  EXPECT_EQ(s.status().servo.fault.kind, control::FaultKind::LimitSwitch);
  s.ticks(2000);
  EXPECT_FALSE(s.status().run_active);
  const double past = s.sim().joint(kX).table_position() - 300.0;
  EXPECT_GE(past, 0.0);
  EXPECT_LE(past, coast_bound(profile, Axis::X, 50.0) + 0.05);
  EXPECT_FALSE(s.status().servo.joints[kX].homed);  // steppers without power lose their place
}

/// The drill's profile and tool table copied into a folder of the test's own (an admin's change
/// writes the file); removed with the object.
class DrillCopy {
 public:
  DrillCopy() {
    dir_ = std::filesystem::temp_directory_path() /
           ("opencnc-drill-copy-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    for (const char* f : {"drill-retrofit.toml", "drill-retrofit.tbl"})
      std::filesystem::copy_file(std::filesystem::path(OPENCNC_SOURCE_DIR "/configs") / f, dir_ / f,
                                 std::filesystem::copy_options::overwrite_existing);
  }
  ~DrillCopy() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string profile() const { return (dir_ / "drill-retrofit.toml").string(); }

 private:
  std::filesystem::path dir_;
};

/// X's pitch errors (the seed's table) with `shift` added: one TOML array for both directions.
std::string seed_errors_plus(double shift) {
  const double errors[] = {0,     0.003, 0.006, 0.010, 0.015, 0.018, 0.022,
                           0.027, 0.028, 0.030, 0.033, 0.037, 0.040};
  std::string s = "[";
  for (double e : errors) s += (s.size() > 1 ? ", " : "") + fmt::format("{}", e + shift);
  return s + "]";
}

// An admin's new pitch table while X stands homed at 175 mm (its last motion +): the table (the
// simulated machine's ground truth) moves by the tables' difference, the drive's command never
// faster than the take-up velocity (2 mm/s); a second change (the other buffer) moves it on.
// Both changes lower the error, so the drive moves on in + and the nut stays engaged (a change
// the other way is lost in the screw's backlash until the axis reverses: docs/compensation.md).
TEST(DrillScenario, APitchTableChangeMovesTheTableByItsDifferenceWithoutAStep) {
  DrillCopy copy;
  Scenario s(control::test::loaded(config::load_profile(copy.profile())));
  home(s);
  s.must(Request::jog_by(Axis::X, 175.0 - s.status().servo.commanded[Axis::X], 40));
  ASSERT_TRUE(s.idle());
  s.ticks(500);
  const double before = table_x(s);
  EXPECT_NEAR(before, 175.0, 0.002);
  for (const double shift : {-0.010, -0.020}) {
    s.forget_samples();
    const double start = table_x(s);
    const std::string errors = seed_errors_plus(shift);
    s.must(Request::edit_profile(
        {{"axis.x.compensation.forward", errors}, {"axis.x.compensation.reverse", errors}}, "admin"));
    s.ticks(300);
    double fastest = 0;
    const std::vector<control::TraceSample>& t = s.samples();
    for (std::size_t i = 1; i < t.size(); ++i)
      fastest = std::max(fastest, std::abs(t[i].output[Axis::X] - t[i - 1].output[Axis::X]) / 1e-3);
    EXPECT_GT(fastest, 0.5);  // it moved, at up to the take-up velocity
    EXPECT_LE(fastest, 2.0 * (1 + 1e-9));
    EXPECT_NEAR(table_x(s) - start, 0.010, 0.0015);  // to the stepper's step (1 µm) at each end
    // −E(175) + backlash/2 (X's last motion was +).
    EXPECT_NEAR(s.rig().servo().compensation().correction(kX), -(0.0125 + shift) + 0.01, 1e-12);
  }
  EXPECT_NEAR(table_x(s), before + 0.020, 0.0015);
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 175.0);
}

}  // namespace
}  // namespace opencnc::controller::test
