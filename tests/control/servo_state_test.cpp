// SPDX-License-Identifier: GPL-3.0-or-later
// The state table of docs/controller.md, row by row: for each state and command, whether the
// servo takes it and the state it leaves. Then the transitions that happen by themselves.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "opencnc/canon/program_builder.hpp"
#include "servo_harness.hpp"
#include "test_profiles.hpp"

namespace opencnc::control {
// Readable failures.
inline std::ostream& operator<<(std::ostream& os, State s) {
  return os << to_string(s);
}
inline std::ostream& operator<<(std::ostream& os, Refusal r) {
  return os << (r == Refusal::None ? "accepted" : refusal_code(r));
}
}  // namespace opencnc::control

namespace opencnc::control::test {
namespace {

Pose xyz(double x, double y = 0, double z = 0) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

/// G1 X`to` at `feed` mm/min, M2.
canon::Program line_program(double to, double feed) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_feed_rate(feed);
  b.straight_feed(0, xyz(to));
  b.program_end();
  return b.take();
}

/// G1 X1, M0, G1 X2, M2.
canon::Program stop_program() {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_feed_rate(600);
  b.straight_feed(0, xyz(1));
  b.program_stop();
  b.straight_feed(1, xyz(2));
  b.program_end();
  return b.take();
}

using Setup = std::function<void(ServoHarness&)>;

// --- ways into each state ------------------------------------------------------------------

void off(ServoHarness&) {}
void estopped(ServoHarness& h) {
  h.sim().set_estop_pressed(true);
  h.tick();
  h.sim().set_estop_pressed(false);
  h.tick();
}
void estopped_chain_open(ServoHarness& h) {
  h.sim().set_estop_pressed(true);
  h.tick(2);
}
Setup idle(Mode m) {
  return [m](ServoHarness& h) {
    ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
    ASSERT_EQ(h.send_mode(m), Refusal::None);
  };
}
void running_program(ServoHarness& h) {
  idle(Mode::Auto)(h);
  ASSERT_EQ(h.run(line_program(100, 600), Mode::Auto), Refusal::None);
  h.tick(50);
}
void held(ServoHarness& h) {
  running_program(h);
  ASSERT_EQ(h.send(CommandKind::FeedHold), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.status().motion == traj::RunState::Held; }, 2000));
}
void stopped(ServoHarness& h) {
  idle(Mode::Auto)(h);
  ASSERT_EQ(h.run(stop_program(), Mode::Auto), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Stopped; }, 5000));
}
void jogging(ServoHarness& h) {
  idle(Mode::Manual)(h);
  ASSERT_EQ(h.jog(Axis::X, 10), Refusal::None);
  h.tick(20);
}
void homing(ServoHarness& h) {
  idle(Mode::Manual)(h);
  ASSERT_EQ(h.home(), Refusal::None);
  h.tick(20);
}
void faulted(ServoHarness& h) {
  idle(Mode::Manual)(h);
  h.sim().set_amp_fault(0, true);
  h.tick(2);
  h.sim().set_amp_fault(0, false);
  h.tick(2);
}
void faulted_persisting(ServoHarness& h) {
  idle(Mode::Manual)(h);
  h.sim().set_amp_fault(0, true);
  h.tick(2);
}

Command cmd(CommandKind k, double value = 0, double value2 = 0, int axis = -1, bool flag = false) {
  Command c;
  c.kind = k;
  c.value = value;
  c.value2 = value2;
  c.axis = static_cast<std::int8_t>(axis);
  c.flag = flag;
  return c;
}
Command mode(Mode m) {
  Command c = cmd(CommandKind::SetMode);
  c.mode = m;
  return c;
}
Command start_run(Mode m) {
  Command c = cmd(CommandKind::StartRun);
  c.run_mode = m;
  return c;
}

struct Row {
  const char* name;
  bool homing_profile;
  Setup setup;
  State before;
  Command command;
  Refusal refusal;
  State after;
};

constexpr int X = 0;

const Row kRows[] = {
    // e-stop: from anywhere
    {"estop_off", false, off, State::Off, cmd(CommandKind::EStop), Refusal::None, State::EStopped},
    {"estop_idle", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::EStop), Refusal::None,
     State::EStopped},
    {"estop_running", false, running_program, State::Running, cmd(CommandKind::EStop), Refusal::None,
     State::EStopped},
    {"estop_held", false, held, State::Held, cmd(CommandKind::EStop), Refusal::None, State::EStopped},
    {"estop_stopped", false, stopped, State::Stopped, cmd(CommandKind::EStop), Refusal::None,
     State::EStopped},
    {"estop_jogging", false, jogging, State::Running, cmd(CommandKind::EStop), Refusal::None,
     State::EStopped},
    {"estop_faulted", false, faulted, State::Faulted, cmd(CommandKind::EStop), Refusal::None,
     State::EStopped},
    {"estop_estopped", false, estopped, State::EStopped, cmd(CommandKind::EStop), Refusal::None,
     State::EStopped},
    // reset
    {"reset_estopped", false, estopped, State::EStopped, cmd(CommandKind::Reset), Refusal::None, State::Off},
    {"reset_estop_chain_open", false, estopped_chain_open, State::EStopped, cmd(CommandKind::Reset),
     Refusal::EStopInput, State::EStopped},
    {"reset_faulted", false, faulted, State::Faulted, cmd(CommandKind::Reset), Refusal::None, State::Off},
    {"reset_fault_persists", false, faulted_persisting, State::Faulted, cmd(CommandKind::Reset),
     Refusal::FaultPersists, State::Faulted},
    {"reset_off", false, off, State::Off, cmd(CommandKind::Reset), Refusal::NotApplicable, State::Off},
    {"reset_idle", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::Reset), Refusal::NotApplicable,
     State::Idle},
    {"reset_running", false, running_program, State::Running, cmd(CommandKind::Reset), Refusal::NotApplicable,
     State::Running},
    // machine on
    {"on_off", false, off, State::Off, cmd(CommandKind::MachineOn), Refusal::None, State::Idle},
    {"on_estopped", false, estopped, State::EStopped, cmd(CommandKind::MachineOn), Refusal::EStopActive,
     State::EStopped},
    {"on_faulted", false, faulted, State::Faulted, cmd(CommandKind::MachineOn), Refusal::Faulted,
     State::Faulted},
    {"on_idle", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::MachineOn), Refusal::NotApplicable,
     State::Idle},
    // machine off: whatever runs stops at once
    {"off_idle", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::MachineOff), Refusal::None,
     State::Off},
    {"off_running", false, running_program, State::Running, cmd(CommandKind::MachineOff), Refusal::None,
     State::Off},
    {"off_held", false, held, State::Held, cmd(CommandKind::MachineOff), Refusal::None, State::Off},
    {"off_stopped", false, stopped, State::Stopped, cmd(CommandKind::MachineOff), Refusal::None, State::Off},
    {"off_jogging", false, jogging, State::Running, cmd(CommandKind::MachineOff), Refusal::None, State::Off},
    {"off_off", false, off, State::Off, cmd(CommandKind::MachineOff), Refusal::NotApplicable, State::Off},
    {"off_estopped", false, estopped, State::EStopped, cmd(CommandKind::MachineOff), Refusal::EStopActive,
     State::EStopped},
    {"off_faulted", false, faulted, State::Faulted, cmd(CommandKind::MachineOff), Refusal::Faulted,
     State::Faulted},
    // mode: only while nothing runs
    {"mode_off", false, off, State::Off, mode(Mode::Mdi), Refusal::None, State::Off},
    {"mode_idle", false, idle(Mode::Manual), State::Idle, mode(Mode::Mdi), Refusal::None, State::Idle},
    {"mode_estopped", false, estopped, State::EStopped, mode(Mode::Mdi), Refusal::None, State::EStopped},
    {"mode_faulted", false, faulted, State::Faulted, mode(Mode::Mdi), Refusal::None, State::Faulted},
    {"mode_running", false, running_program, State::Running, mode(Mode::Manual), Refusal::Busy,
     State::Running},
    {"mode_held", false, held, State::Held, mode(Mode::Manual), Refusal::Busy, State::Held},
    {"mode_stopped", false, stopped, State::Stopped, mode(Mode::Manual), Refusal::Busy, State::Stopped},
    {"mode_jogging", false, jogging, State::Running, mode(Mode::Auto), Refusal::Busy, State::Running},
    // jog
    {"jog_idle_manual", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::JogContinuous, 10, 0, X),
     Refusal::None, State::Running},
    {"jog_idle_auto", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::JogContinuous, 10, 0, X),
     Refusal::WrongMode, State::Idle},
    {"jog_running_program", false, running_program, State::Running, cmd(CommandKind::JogContinuous, 10, 0, X),
     Refusal::WrongMode, State::Running},
    {"jog_held", false, held, State::Held, cmd(CommandKind::JogContinuous, 10, 0, X), Refusal::WrongMode,
     State::Held},
    {"jog_jogging", false, jogging, State::Running, cmd(CommandKind::JogContinuous, -10, 0, X), Refusal::None,
     State::Running},
    {"jog_homing", true, homing, State::Running, cmd(CommandKind::JogContinuous, 10, 0, X), Refusal::Busy,
     State::Running},
    {"jog_off", false, off, State::Off, cmd(CommandKind::JogContinuous, 10, 0, X), Refusal::MachineOff,
     State::Off},
    {"jog_estopped", false, estopped, State::EStopped, cmd(CommandKind::JogContinuous, 10, 0, X),
     Refusal::EStopActive, State::EStopped},
    {"jog_faulted", false, faulted, State::Faulted, cmd(CommandKind::JogContinuous, 10, 0, X),
     Refusal::Faulted, State::Faulted},
    {"jog_zero_speed", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::JogContinuous, 0, 0, X),
     Refusal::BadValue, State::Idle},
    {"jog_unknown_axis", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::JogContinuous, 10, 0, 5),
     Refusal::BadValue, State::Idle},
    {"jog_increment_idle", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::JogIncrement, 1, 10, X),
     Refusal::None, State::Running},
    {"jog_increment_moving_joint", false, jogging, State::Running, cmd(CommandKind::JogIncrement, 1, 10, X),
     Refusal::Busy, State::Running},
    {"jog_stop_jogging", false, jogging, State::Running, cmd(CommandKind::JogStop, 0, 0, X), Refusal::None,
     State::Running},
    {"jog_stop_idle", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::JogStop, 0, 0, X),
     Refusal::NotApplicable, State::Idle},
    // home
    {"home_idle_manual", true, idle(Mode::Manual), State::Idle, cmd(CommandKind::Home), Refusal::None,
     State::Running},
    {"home_idle_auto", true, idle(Mode::Auto), State::Idle, cmd(CommandKind::Home), Refusal::WrongMode,
     State::Idle},
    {"home_jogging", false, jogging, State::Running, cmd(CommandKind::Home), Refusal::Busy, State::Running},
    {"home_homing", true, homing, State::Running, cmd(CommandKind::Home), Refusal::Busy, State::Running},
    {"home_off", true, off, State::Off, cmd(CommandKind::Home), Refusal::MachineOff, State::Off},
    // seek a limit switch (the homing mill's X has one on its + side, but no seek keys; the
    // seeks that run are servo_manual_test's LimitSeek.*)
    {"seek_no_seek_keys", true, idle(Mode::Manual), State::Idle, cmd(CommandKind::SeekLimit, 1, 0, 0),
     Refusal::NoLimitSwitch, State::Idle},
    {"seek_bad_direction", true, idle(Mode::Manual), State::Idle, cmd(CommandKind::SeekLimit, 0.5, 0, 0),
     Refusal::BadValue, State::Idle},
    {"seek_idle_auto", true, idle(Mode::Auto), State::Idle, cmd(CommandKind::SeekLimit, 1, 0, 0),
     Refusal::WrongMode, State::Idle},
    {"seek_jogging", false, jogging, State::Running, cmd(CommandKind::SeekLimit, 1, 0, 0), Refusal::Busy,
     State::Running},
    {"seek_off", true, off, State::Off, cmd(CommandKind::SeekLimit, 1, 0, 0), Refusal::MachineOff,
     State::Off},
    // runs (the controller's StartRun)
    {"run_idle_auto", false, idle(Mode::Auto), State::Idle, start_run(Mode::Auto), Refusal::None,
     State::Running},
    {"run_idle_mdi", false, idle(Mode::Mdi), State::Idle, start_run(Mode::Mdi), Refusal::None,
     State::Running},
    {"run_wrong_mode", false, idle(Mode::Manual), State::Idle, start_run(Mode::Auto), Refusal::WrongMode,
     State::Idle},
    {"run_running", false, running_program, State::Running, start_run(Mode::Auto), Refusal::Busy,
     State::Running},
    {"run_not_homed", true, idle(Mode::Auto), State::Idle, start_run(Mode::Auto), Refusal::NotHomed,
     State::Idle},
    {"run_off", false, off, State::Off, start_run(Mode::Auto), Refusal::MachineOff, State::Off},
    {"run_estopped", false, estopped, State::EStopped, start_run(Mode::Auto), Refusal::EStopActive,
     State::EStopped},
    // cycle start, feed hold, resume
    {"cycle_start_held", false, held, State::Held, cmd(CommandKind::CycleStart), Refusal::None,
     State::Running},
    {"cycle_start_stopped", false, stopped, State::Stopped, cmd(CommandKind::CycleStart), Refusal::None,
     State::Running},
    {"cycle_start_running", false, running_program, State::Running, cmd(CommandKind::CycleStart),
     Refusal::NotApplicable, State::Running},
    {"cycle_start_idle", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::CycleStart),
     Refusal::NotApplicable, State::Idle},
    {"cycle_start_off", false, off, State::Off, cmd(CommandKind::CycleStart), Refusal::MachineOff,
     State::Off},
    {"hold_running", false, running_program, State::Running, cmd(CommandKind::FeedHold), Refusal::None,
     State::Held},
    {"hold_held", false, held, State::Held, cmd(CommandKind::FeedHold), Refusal::NotApplicable, State::Held},
    {"hold_stopped", false, stopped, State::Stopped, cmd(CommandKind::FeedHold), Refusal::NotApplicable,
     State::Stopped},
    {"hold_idle", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::FeedHold), Refusal::NotApplicable,
     State::Idle},
    {"hold_jogging", false, jogging, State::Running, cmd(CommandKind::FeedHold), Refusal::NotApplicable,
     State::Running},
    {"resume_held", false, held, State::Held, cmd(CommandKind::Resume), Refusal::None, State::Running},
    {"resume_stopped", false, stopped, State::Stopped, cmd(CommandKind::Resume), Refusal::None,
     State::Running},
    {"resume_running", false, running_program, State::Running, cmd(CommandKind::Resume),
     Refusal::NotApplicable, State::Running},
    {"resume_idle", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::Resume), Refusal::NotApplicable,
     State::Idle},
    // abort: always taken; a controlled stop of what moves
    {"abort_running", false, running_program, State::Running, cmd(CommandKind::Abort), Refusal::None,
     State::Running},
    {"abort_held", false, held, State::Held, cmd(CommandKind::Abort), Refusal::None, State::Idle},  // at rest
    {"abort_stopped", false, stopped, State::Stopped, cmd(CommandKind::Abort), Refusal::None, State::Idle},
    {"abort_jogging", false, jogging, State::Running, cmd(CommandKind::Abort), Refusal::None, State::Running},
    {"abort_homing", true, homing, State::Running, cmd(CommandKind::Abort), Refusal::None, State::Running},
    {"abort_idle", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::Abort), Refusal::None, State::Idle},
    {"abort_off", false, off, State::Off, cmd(CommandKind::Abort), Refusal::None, State::Off},
    {"abort_estopped", false, estopped, State::EStopped, cmd(CommandKind::Abort), Refusal::None,
     State::EStopped},
    {"abort_faulted", false, faulted, State::Faulted, cmd(CommandKind::Abort), Refusal::None, State::Faulted},
    // switches and overrides: any state
    {"single_block_off", false, off, State::Off, cmd(CommandKind::SetSingleBlock, 0, 0, -1, true),
     Refusal::None, State::Off},
    {"optional_stop_running", false, running_program, State::Running,
     cmd(CommandKind::SetOptionalStop, 0, 0, -1, true), Refusal::None, State::Running},
    {"feed_override_running", false, running_program, State::Running, cmd(CommandKind::SetFeedOverride, 1.5),
     Refusal::None, State::Running},
    {"feed_override_too_high", false, running_program, State::Running, cmd(CommandKind::SetFeedOverride, 2.5),
     Refusal::BadValue, State::Running},
    {"feed_override_negative", false, off, State::Off, cmd(CommandKind::SetFeedOverride, -0.1),
     Refusal::BadValue, State::Off},
    {"rapid_override_too_high", false, off, State::Off, cmd(CommandKind::SetRapidOverride, 1.1),
     Refusal::BadValue, State::Off},
    {"spindle_override_estopped", false, estopped, State::EStopped, cmd(CommandKind::SetSpindleOverride, 0.5),
     Refusal::None, State::EStopped},
    // operator's tool change, manual spindle and coolant
    {"tool_changed_idle", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::ToolChanged),
     Refusal::NotApplicable, State::Idle},
    {"spindle_on_manual", false, idle(Mode::Manual), State::Idle,
     cmd(CommandKind::SpindleOn, 1000, 0, -1, true), Refusal::None, State::Idle},
    {"spindle_on_too_fast", false, idle(Mode::Manual), State::Idle,
     cmd(CommandKind::SpindleOn, 9000, 0, -1, true), Refusal::BadValue, State::Idle},
    {"spindle_on_auto", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::SpindleOn, 1000, 0, -1, true),
     Refusal::WrongMode, State::Idle},
    {"spindle_on_off", false, off, State::Off, cmd(CommandKind::SpindleOn, 1000, 0, -1, true),
     Refusal::MachineOff, State::Off},
    {"coolant_manual", false, idle(Mode::Manual), State::Idle, cmd(CommandKind::Coolant, 0, 0, -1, true),
     Refusal::None, State::Idle},
    {"coolant_auto", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::Coolant, 0, 0, -1, true),
     Refusal::WrongMode, State::Idle},
    // the handwheel is a setting, taken in every state where the machine has one (servo_drill_test)
    {"handwheel_without_one", false, idle(Mode::Manual), State::Idle,
     cmd(CommandKind::SetHandwheel, 0.01, 0, 0), Refusal::NotApplicable, State::Idle},
    {"handwheel_without_one_estopped", false, estopped, State::EStopped,
     cmd(CommandKind::SetHandwheel, 0.01, 0, 0), Refusal::NotApplicable, State::EStopped},
    // joint limits (an admin's profile edit): staged joint by joint, applied together while idle
    {"apply_limits_nothing_staged", false, idle(Mode::Manual), State::Idle,
     cmd(CommandKind::ApplyJointLimits), Refusal::NotApplicable, State::Idle},
    {"stage_limits_zero_velocity", false, running_program, State::Running,
     cmd(CommandKind::StageJointLimits, 0, 0, 0), Refusal::BadValue, State::Running},
    {"stage_limits_no_such_joint", false, off, State::Off, cmd(CommandKind::StageJointLimits, 0, 0, 7),
     Refusal::BadValue, State::Off},
    // machining conditions on a machine without an EDM (the mill): nothing to stage them into
    {"stage_conditions_without_edm", false, idle(Mode::Manual), State::Idle,
     cmd(CommandKind::StageEdmConditions), Refusal::NotApplicable, State::Idle},
    // an oxy-fuel cut's start on a machine without a torch stage (the mill), or with no preheat
    {"start_cut_idle", false, idle(Mode::Auto), State::Idle, cmd(CommandKind::StartCut),
     Refusal::NotApplicable, State::Idle},
    {"start_cut_running", false, running_program, State::Running, cmd(CommandKind::StartCut),
     Refusal::NotApplicable, State::Running},
};

void PrintTo(const Row& r, std::ostream* os) {
  *os << r.name;
}

class StateTable : public ::testing::TestWithParam<Row> {};

TEST_P(StateTable, Row) {
  const Row& row = GetParam();
  ServoHarness h(row.homing_profile ? homing_mill() : mill());
  row.setup(h);
  ASSERT_EQ(h.state(), row.before) << to_string(h.state());
  Command c = row.command;
  if (c.kind == CommandKind::StartRun) {  // with blocks queued, as the controller sends it
    EXPECT_EQ(h.run(line_program(h.status().commanded[Axis::X] + 10, 600), c.run_mode), row.refusal);
  } else {
    EXPECT_EQ(h.send(c), row.refusal) << refusal_code(h.status().last_refusal);
  }
  EXPECT_EQ(h.state(), row.after) << to_string(h.state());
}

INSTANTIATE_TEST_SUITE_P(Servo, StateTable, ::testing::ValuesIn(kRows),
                         [](const ::testing::TestParamInfo<Row>& i) { return std::string(i.param.name); });

// --- transitions that happen by themselves -------------------------------------------------

TEST(StateTransitions, ProgramEndGoesIdle) {
  ServoHarness h(mill());
  idle(Mode::Auto)(h);
  ASSERT_EQ(h.run(line_program(1, 600), Mode::Auto), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 1000));
  ASSERT_TRUE(h.last(EventKind::RunEnded));
  EXPECT_EQ(h.last(EventKind::RunEnded)->run_end, RunEnd::Finished);
  EXPECT_DOUBLE_EQ(h.status().commanded[Axis::X], 1.0);
}

TEST(StateTransitions, AbortStopsOnThePathThenIdle) {
  ServoHarness h(mill());
  running_program(h);
  ASSERT_EQ(h.send(CommandKind::Abort), Refusal::None);
  EXPECT_TRUE(h.status().aborting);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 1000));
  EXPECT_EQ(h.last(EventKind::RunEnded)->run_end, RunEnd::Aborted);
  EXPECT_LT(h.status().commanded[Axis::X], 100.0);
  EXPECT_EQ(h.status().commanded[Axis::Y], 0.0);
  EXPECT_EQ(h.channels().blocks.available(), 0u);
}

TEST(StateTransitions, ProgramStopIsStoppedUntilCycleStart) {
  ServoHarness h(mill());
  stopped(h);
  EXPECT_EQ(h.status().stop_reason, StopReason::ProgramStop);
  EXPECT_DOUBLE_EQ(h.status().commanded[Axis::X], 1.0);
  h.tick(100);
  EXPECT_EQ(h.state(), State::Stopped);
  ASSERT_EQ(h.send(CommandKind::CycleStart), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 2000));
  EXPECT_DOUBLE_EQ(h.status().commanded[Axis::X], 2.0);
}

TEST(StateTransitions, JogEndsIdleWhenSettled) {
  ServoHarness h(mill());
  idle(Mode::Manual)(h);
  Command c = cmd(CommandKind::JogIncrement, 2.5, 20, X);
  ASSERT_EQ(h.send(c), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 1000));
  EXPECT_DOUBLE_EQ(h.status().commanded[Axis::X], 2.5);
}

TEST(StateTransitions, EstopInputEstopsFromAnyState) {
  ServoHarness h(mill());
  running_program(h);
  h.sim().set_estop_pressed(true);
  h.tick(2);
  EXPECT_EQ(h.state(), State::EStopped);
  EXPECT_FALSE(h.status().drives_enabled);
  EXPECT_EQ(h.last(EventKind::RunEnded)->run_end, RunEnd::EStopped);
}

}  // namespace
}  // namespace opencnc::control::test
