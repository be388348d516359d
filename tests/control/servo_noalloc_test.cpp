// SPDX-License-Identifier: GPL-3.0-or-later
// Servo::tick() must not allocate: this executable replaces operator new and counts the calls
// made inside the tick while the whole controller runs homing, jogs, MDI, a program with every
// kind of marker, holds, overrides, faults and an e-stop (the controller's work between ticks
// may allocate).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include "../support/counting_new.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/control/shared_memory.hpp"
#include "opencnc/control/shared_servo.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/machine/sim_machine.hpp"
#include "test_profiles.hpp"

using opencnc::test::g_allocations;
using opencnc::test::g_armed;

namespace opencnc::control::test {
namespace {

/// The whole controller, with only the servo's ticks armed.
class Armed {
 public:
  explicit Armed(const config::MachineProfile& p) {
    Diagnostics d;
    rig_ = std::make_unique<controller::SimRig>(p, *features::machine_setup(p, d));
    rig_->channels().trace_enabled = true;
  }
  void tick() {
    rig_->controller().service();
    TraceSample t;
    while (rig_->channels().trace.try_pop(t)) {
    }
    g_armed = true;
    rig_->servo().tick();
    g_armed = false;
  }
  bool until(const std::function<bool()>& done, int max) {
    for (int i = 0; i < max; ++i) {
      tick();
      if (done()) return true;
    }
    return false;
  }
  void ask(controller::Request r) {
    const std::uint64_t id = rig_->controller().submit(std::move(r));
    until([&] { return rig_->controller().outcome(id).has_value(); }, 100);
  }
  State state() const { return rig_->status().servo.state; }
  bool idle() {
    return until([&] { return state() == State::Idle && !rig_->status().run_active; }, 200000);
  }
  controller::SimRig& rig() { return *rig_; }

 private:
  std::unique_ptr<controller::SimRig> rig_;
};

TEST(ServoAllocations, NoneInsideTheTick) {
  const auto dir = std::filesystem::temp_directory_path() / "opencnc-noalloc";
  std::filesystem::create_directories(dir);
  const std::string program = (dir / "all.ngc").string(), tools = (dir / "tools.tbl").string();
  std::ofstream(tools) << "T2 P2 Z0\n";
  std::ofstream(program) << "G21 G90 G64 P0.05\nS2000 M3\nM8\nT2 M6\nG0 X250 Y20 Z-10\nG1 X260 F3000\n"
                            "M62 P1\nG2 X270 Y30 I0 J10\nM1\nG3 X260 Y40 Z-12 I-10 J0\nM63 P1\nM66 P0 L0\n"
                            "G4 P0.05\nM0\nG1 X250 Y20\nM9\nM5\nM2\n";
  g_allocations = 0;
  Armed a(homing_mill({"interpreter.tool_table=\"" + tools + "\""}));
  a.ask(controller::Request::simple(CommandKind::MachineOn));
  a.ask(controller::Request::set_mode(Mode::Manual));
  a.ask(controller::Request::home());
  ASSERT_TRUE(a.idle());
  a.ask(controller::Request::jog(Axis::X, -30));
  a.until([] { return false; }, 300);
  a.ask(controller::Request::jog_stop());
  ASSERT_TRUE(a.idle());
  a.ask(controller::Request::set_mode(Mode::Mdi));
  a.ask(controller::Request::mdi("G91 G1 Y2 F600"));
  ASSERT_TRUE(a.idle());
  a.ask(controller::Request::set_mode(Mode::Auto));
  a.ask(controller::Request::optional_stop(true));
  a.ask(controller::Request::open(program));
  a.ask(controller::Request::simple(CommandKind::CycleStart));
  int n = 0;
  ASSERT_TRUE(a.until(
      [&] {
        ++n;
        if (n == 900) a.ask(controller::Request::feed_override(1.7));
        if (n == 2000) a.ask(controller::Request::simple(CommandKind::FeedHold));
        if (n == 2300) a.ask(controller::Request::simple(CommandKind::Resume));
        if (a.state() == State::Stopped) a.ask(controller::Request::simple(CommandKind::CycleStart));
        return a.state() == State::Idle && !a.rig().status().run_active;
      },
      200000));
  EXPECT_EQ(a.rig().status().runs_finished, 2u);  // the MDI line and the program
  EXPECT_NEAR(a.rig().status().servo.commanded[Axis::X], 250.0, 1e-9);
  EXPECT_EQ(a.rig().status().servo.tool, 2);
  // An admin's change of the limits while idle: staged joint by joint, applied by one command.
  const JointConfig& x = a.rig().servo().config().joints[0];
  Command stage;
  stage.kind = CommandKind::StageJointLimits;
  stage.axis = 0;
  stage.limits = {x.max_velocity / 2, x.max_acceleration,    x.min_limit,
                  x.max_limit,        x.max_following_error, x.home.final_velocity / 2};
  Command apply;
  apply.kind = CommandKind::ApplyJointLimits;
  ASSERT_TRUE(a.rig().channels().commands.try_push(stage) && a.rig().channels().commands.try_push(apply));
  const double halved = stage.limits.max_velocity;
  a.until([] { return false; }, 5);
  EXPECT_EQ(a.rig().servo().config().joints[0].max_velocity, halved);
  a.rig().machine().set_amp_fault(0, true);
  a.until([] { return false; }, 5);
  a.rig().machine().set_estop_pressed(true);
  a.until([] { return false; }, 5);
  EXPECT_EQ(a.state(), State::EStopped);
  EXPECT_EQ(g_allocations.load(), 0);
  std::filesystem::remove_all(dir);
}

TEST(ServoAllocations, NoneWhileRigidTappingOrUnderConstantSurfaceSpeed) {
  // G96: the spindle's speed computed from X every period; G33.1: the tap following the spindle
  // through its reversal (issue 6).
  const auto dir = std::filesystem::temp_directory_path() / "opencnc-noalloc-spindle";
  std::filesystem::create_directories(dir);
  const std::string program = (dir / "spindle.ngc").string();
  std::ofstream(program) << "G21 G90\nG0 X60 Y0 Z5\nG96 D3000 S150 M3\nG1 X2 F900\nG97 S600\n"
                            "G0 X10 Y10 Z3\nG33.1 Z-8 K1.25 I1.5\nG0 Z20\nM5\nM2\n";
  g_allocations = 0;
  Armed a(mill());
  a.ask(controller::Request::simple(CommandKind::MachineOn));
  a.ask(controller::Request::set_mode(Mode::Auto));
  a.ask(controller::Request::open(program));
  a.ask(controller::Request::simple(CommandKind::CycleStart));
  ASSERT_TRUE(a.until([&] { return a.state() == State::Idle && !a.rig().status().run_active; }, 200000));
  EXPECT_EQ(a.rig().status().runs_finished, 1u);
  EXPECT_NEAR(a.rig().status().servo.commanded[Axis::Z], 20.0, 1e-9);
  EXPECT_EQ(g_allocations.load(), 0);
  std::filesystem::remove_all(dir);
}

// The broach's tick: every coupling law engaged and released in a run, a feed hold while coupled,
// and a power failure's stop with the coupling held, braking harder on a nearly empty DC link.
TEST(ServoAllocations, NoneInsideTheCoupledTick) {
  const auto dir = std::filesystem::temp_directory_path() / "opencnc-noalloc-coupled";
  std::filesystem::create_directories(dir);
  const std::string program = (dir / "broach.ngc").string();
  std::ofstream(program)
      << "G21 G90 G0 X0 Z0 C0\nM171 P60\nG1 X0.1 F60\nG1 Z40 F6000\nM172 P600 Q-0.2\n"
         "G1 Z80\nM173 P1\nG1 Z120\nM174 P2\nG1 Z100\nG0 Z0\nM175\nM171 P60\nG1 Z200 F3000\nM2\n";
  g_allocations = 0;
  // A nearly empty DC link (no UPS runtime, 40 µF): the power-fail stop brakes harder.
  const std::vector<std::string> empty_link = {"power.sim.ups_runtime_s=0",
                                               "power.dc_link_capacitance_f=0.00004"};
  Armed a(loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml", empty_link)));
  a.ask(controller::Request::simple(CommandKind::MachineOn));
  a.ask(controller::Request::set_mode(Mode::Auto));
  a.ask(controller::Request::open(program));
  a.ask(controller::Request::simple(CommandKind::CycleStart));
  int n = 0;
  bool coupled_seen = false;
  ASSERT_TRUE(a.until(
      [&] {
        ++n;
        coupled_seen = coupled_seen || a.rig().status().servo.coupling.kind != motion::CouplingKind::Off;
        if (n == 300) a.ask(controller::Request::simple(CommandKind::FeedHold));
        if (n == 600) a.ask(controller::Request::simple(CommandKind::Resume));
        if (a.rig().status().servo.commanded[Axis::Z] > 150) a.rig().machine().set_mains_ok(false);
        return a.state() == State::Faulted;
      },
      200000));
  EXPECT_TRUE(coupled_seen);
  EXPECT_GT(a.rig().status().servo.stop_decel_scale, 1.0);  // the energy's stop ran in the tick
  EXPECT_EQ(g_allocations.load(), 0);
  std::filesystem::remove_all(dir);
}

// The broach's load guard in the tick: a worn cutter's hold, a resume, an overload's stop on the
// helix and the radial lift (and the simulated load model under it).
TEST(ServoAllocations, NoneInsideTheLoadGuard) {
  const auto dir = std::filesystem::temp_directory_path() / "opencnc-noalloc-load";
  std::filesystem::create_directories(dir);
  const std::string program = (dir / "broach.ngc").string();
  std::ofstream(program) << "G21 G90 G0 X-0.5 Z-10 C0\nM171 P600\nG1 X0.1 F60\nG1 Z200 F3000\nM175\nM2\n";
  g_allocations = 0;
  Armed a(loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml")));
  a.rig().machine().set_tool_dull(1.8);
  a.ask(controller::Request::simple(CommandKind::MachineOn));
  a.ask(controller::Request::set_mode(Mode::Auto));
  a.ask(controller::Request::open(program));
  a.ask(controller::Request::simple(CommandKind::CycleStart));
  bool held = false;
  ASSERT_TRUE(a.until(
      [&] {
        const ServoStatus s = a.rig().status().servo;
        if (!held && s.state == State::Held && s.path_velocity == 0) {
          held = true;
          a.rig().machine().set_tool_dull(3.0);  // worse: the resumed cut overloads
          a.ask(controller::Request::simple(CommandKind::Resume));
        }
        return held && s.load_action == LoadAction::Lifted;
      },
      20000));
  EXPECT_EQ(g_allocations.load(), 0);
  std::filesystem::remove_all(dir);
}

// The event log keeps its entries in a ring built once: a job that runs for days appends events
// without the log's memory growing (the strings are copied into fixed fields).
TEST(ServoAllocations, NoneWhenTheEventLogAppends) {
  controller::EventLog log(8);
  controller::ControllerEvent e;
  e.text = std::string(400, 'x');  // longer than its field: cut, not stored on the heap
  e.code = "control.fault.stall";
  e.location.file = "part.ngc";
  e.location.calls = {"o<a> called at part.ngc:1", "o<b> called at a.ngc:2"};
  g_allocations = 0;
  g_armed = true;
  for (int i = 0; i < 100; ++i) log.append(e);
  g_armed = false;
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_EQ(log.last(), 100u);
}

// The sinker EDM's tick: the gap servo forward and back along the path (an injected short), jumps
// along the tool axis and along the path, circle and square orbits growing, a feed hold, M181;
// before it, homing on the cams and the seek of a limit switch.
TEST(ServoAllocations, NoneInsideTheEdmTick) {
  const auto dir = std::filesystem::temp_directory_path() / "opencnc-noalloc-edm";
  std::filesystem::create_directories(dir);
  const std::string program = (dir / "edm.ngc").string();
  std::ofstream(program) << "G21 G90\nT1 M6\nG0 B-30 X-0.8\nG0 Z-19.97\nM180 P1\nG1 Z-20.06 C0.1 F60\n"
                            "M180 P2\nG1 Z-20.07 F30\nM180 P3\nG1 Z-20.075 F20\nM181\nG0 Z0 B0 X0\nM2\n";
  g_allocations = 0;
  const std::vector<std::string> sets = {"edm.sim.electrode_area_mm2=5"};
  Armed a(loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml", sets)));
  a.ask(controller::Request::simple(CommandKind::MachineOn));
  a.ask(controller::Request::set_mode(Mode::Manual));
  a.ask(controller::Request::home());  // on the reference cams
  ASSERT_TRUE(a.idle());
  a.ask(controller::Request::seek_limit(Axis::Z, +1));  // to Z's + limit switch, latched, backed off
  ASSERT_TRUE(a.idle());
  ASSERT_TRUE(a.rig().status().servo.seek[2].found);
  a.ask(controller::Request::set_mode(Mode::Auto));
  a.ask(controller::Request::open(program));
  a.ask(controller::Request::simple(CommandKind::CycleStart));
  int n = 0;
  bool shorted = false, jumped = false, orbited = false, backed = false;
  ASSERT_TRUE(a.until(
      [&] {
        const EdmStatus& e = a.rig().status().servo.edm;
        jumped = jumped || e.jumping;
        orbited = orbited || e.orbit_radius_mm > 0;
        backed = backed || e.backlog_mm > 0.01;
        if (!shorted && e.generator && e.gap_state == machine::GapState::Normal && ++n > 100) {
          a.rig().machine().inject_edm_short();
          shorted = true;
        }
        if (n == 400) a.ask(controller::Request::simple(CommandKind::FeedHold));
        if (n == 450) a.ask(controller::Request::simple(CommandKind::Resume));
        if (shorted) ++n;
        return a.state() == State::Idle && !a.rig().status().run_active;
      },
      400000));
  EXPECT_TRUE(shorted);
  EXPECT_TRUE(jumped);
  EXPECT_TRUE(orbited);
  EXPECT_TRUE(backed);
  // The simulated gap's side walls, the electrode change and its wear ran in the counted ticks.
  const machine::SimEdmProcess& sim = a.rig().machine().edm();
  EXPECT_GT(sim.cavity_oversize_max_mm(), 0.04);  // orbits beyond the roughing's side gap
  EXPECT_GT(sim.electrode_wear_mm(), 0.0);
  // An admin's edit of the conditions, an add and a delete: staged and taken at rest, in the counted ticks.
  EdmConditionTable& next = a.rig().channels().edm_conditions;
  next.conditions = a.rig().servo().config().edm.conditions;
  next.count = a.rig().servo().config().edm.condition_count;
  next.conditions[0].on_time_us = 60;
  Command stage;
  stage.kind = CommandKind::StageEdmConditions;
  Command apply;
  apply.kind = CommandKind::ApplyJointLimits;
  ASSERT_TRUE(a.rig().channels().commands.try_push(stage) && a.rig().channels().commands.try_push(apply));
  a.until([] { return false; }, 20);
  EXPECT_EQ(a.rig().servo().config().edm.find(1)->on_time_us, 60.0);
  // A condition added (a copy of 1 as 7) and then one deleted (the last): the table's count changes.
  const int count = next.count;
  next.conditions[static_cast<std::size_t>(count)] = next.conditions[0];
  next.conditions[static_cast<std::size_t>(count)].number = 7;
  next.count = count + 1;
  ASSERT_TRUE(a.rig().channels().commands.try_push(stage) && a.rig().channels().commands.try_push(apply));
  a.until([] { return false; }, 20);
  EXPECT_EQ(a.rig().servo().config().edm.condition_count, count + 1);
  next.count = count - 1;
  ASSERT_TRUE(a.rig().channels().commands.try_push(stage) && a.rig().channels().commands.try_push(apply));
  a.until([] { return false; }, 20);
  EXPECT_EQ(a.rig().servo().config().edm.condition_count, count - 1);
  EXPECT_EQ(g_allocations.load(), 0);
  std::filesystem::remove_all(dir);
}

// The drill retrofit's tick: midpoint homing on the analog sensors, the compensation stage, the
// interlock rules, the handwheel, hand-axis waits with a simulated operator, a stall and an e-stop.
TEST(ServoAllocations, NoneInsideTheDrillsTick) {
  g_allocations = 0;
  Armed a(drill());
  a.ask(controller::Request::simple(CommandKind::MachineOn));
  a.ask(controller::Request::set_mode(Mode::Manual));
  a.ask(controller::Request::home());
  ASSERT_TRUE(a.idle());
  a.ask(controller::Request::handwheel(Axis::X, 0.01));
  a.rig().machine().turn_handwheel(40);
  a.until([] { return false; }, 50);
  ASSERT_TRUE(a.idle());
  a.ask(controller::Request::set_mode(Mode::Auto));
  a.ask(controller::Request::open(OPENCNC_SOURCE_DIR "/examples/drill-bearing-cap.ngc"));
  a.ask(controller::Request::simple(CommandKind::CycleStart));
  int changing = 0;
  ASSERT_TRUE(a.until(
      [&] {
        const ServoStatus v = a.rig().status().servo;
        if (v.wait == Wait::HandAxis)
          a.rig().machine().set_hand_target(2, v.hand_wait.target, v.hand_wait.retract ? 60.0 : 20.0);
        if (v.wait == Wait::ManualToolChange && ++changing % 500 == 0)
          a.rig().controller().submit(controller::Request::simple(CommandKind::ToolChanged));
        return a.state() == State::Idle && !a.rig().status().run_active && a.rig().status().servo.all_homed;
      },
      2'000'000));
  EXPECT_EQ(a.rig().status().runs_finished, 1u);
  // An admin's new pitch table for X: the controller's buffer, staged and switched to at rest,
  // then taken up (the lookup reads the channels' buffer from here on).
  motion::PitchTable& next = a.rig().channels().pitch_tables.joints[0][0];
  next = a.rig().servo().compensation().pitch_table(0);
  for (int i = 0; i < next.count; ++i) next.forward[static_cast<std::size_t>(i)] += 0.005;
  Command stage;
  stage.kind = CommandKind::StagePitchTable;
  stage.axis = 0;
  stage.table_buffer = 0;
  Command apply;
  apply.kind = CommandKind::ApplyJointLimits;
  ASSERT_TRUE(a.rig().channels().commands.try_push(stage) && a.rig().channels().commands.try_push(apply));
  a.until([] { return false; }, 100);
  EXPECT_EQ(&a.rig().servo().compensation().pitch_table(0), &next);
  a.ask(controller::Request::set_mode(Mode::Manual));
  a.ask(controller::Request::jog(Axis::X, 30));
  a.until([] { return false; }, 200);
  a.rig().machine().set_external_effort(0, -3000);  // a stall the X drive detects
  a.until([] { return false; }, 50);
  EXPECT_EQ(a.state(), State::Faulted);
  a.rig().machine().set_estop_pressed(true);
  a.until([] { return false; }, 5);
  EXPECT_EQ(a.state(), State::EStopped);
  EXPECT_EQ(g_allocations.load(), 0);
}

TEST(ServoAllocations, NoneWithProcessAlarmsAndAReferenceSphere) {
  const config::ProfileLoad load =
      config::load_profile(OPENCNC_SOURCE_DIR "/tests/scenario/edm-setting.toml");
  ASSERT_TRUE(load.ok());
  g_allocations = 0;
  Armed a(*load.profile);
  a.ask(controller::Request::simple(CommandKind::MachineOn));
  a.ask(controller::Request::set_mode(Mode::Mdi));
  a.ask(controller::Request::mdi("G0 X110 Y50 Z-150"));
  ASSERT_TRUE(a.idle());
  a.ask(controller::Request::mdi("G38.2 X100 F600"));  // the simulated sphere's probe: contact at X105
  ASSERT_TRUE(a.idle());
  EXPECT_NEAR(a.rig().status().servo.probe_position[Axis::X], 105.0, 0.001);
  a.ask(controller::Request::mdi("G1 X0 F3000"));
  a.until([] { return false; }, 200);
  a.rig().machine().drift_analog_input(2, 80, 100);  // resistor box: a message
  a.until([] { return false; }, 200);
  a.rig().machine().set_analog_input(1, 45);  // dielectric temperature: feed hold
  a.until([] { return false; }, 50);
  EXPECT_EQ(a.state(), State::Held);
  a.rig().machine().set_analog_input(1, 30);
  a.until([] { return false; }, 5);
  a.ask(controller::Request::simple(CommandKind::CycleStart));
  a.until([] { return false; }, 50);
  a.rig().machine().drift_analog_input(0, 20, 100);  // dielectric level: stop and fault
  a.until([] { return false; }, 1000);
  EXPECT_EQ(a.state(), State::Faulted);
  EXPECT_EQ(a.rig().status().servo.alarms_active, 0b101u);
  EXPECT_EQ(g_allocations.load(), 0);
  // The status carries each alarm's input (what the HMI's alarm lines show beside the bounds):
  // the dielectric temperature (input 1) set back to 30 °C, the level drifted down to 20 mm.
  EXPECT_EQ(a.rig().status().servo.alarm_values[1], 30.0);
  EXPECT_LT(a.rig().status().servo.alarm_values[0], 40.0);
}

/// The simulated machine behind the shared-memory host, its capabilities handed over at run time.
class SimBackend final : public ConfigurableMachine {
 public:
  explicit SimBackend(const config::MachineProfile& p) : sim_(config::sim_machine_config(p)) {}
  machine::MachineCapabilities capabilities() const noexcept override { return caps_; }
  void read(machine::MachineInputs& in) noexcept override { sim_.read(in); }
  void write(const machine::MachineOutputs& out) noexcept override { sim_.write(out); }
  void set_capabilities(const machine::MachineCapabilities& caps) noexcept override { caps_ = caps; }

 private:
  machine::SimMachine sim_;
  machine::MachineCapabilities caps_{};
};

// The HAL component's tick: the host over shared memory, taking a set-up (the servo built in place),
// a jog, the heartbeat stopping (the controlled stop and the fault), a second set-up taken.
TEST(ServoAllocations, NoneInsideTheSharedMemoryHostsTick) {
  const config::MachineProfile p = mill();
  std::string error;
  auto segment =
      SegmentMapping::create("/opencnc-noalloc-" + std::to_string(::getpid()), 1'000'000, 20, error);
  ASSERT_TRUE(segment) << error;
  SharedSegment& s = segment->segment();
  SimBackend backend(p);
  SharedServoHost host(s, backend);
  const SharedSetup setup = controller::shared_setup(p);
  Command c;
  c.kind = CommandKind::MachineOn;
  c.id = 1;
  g_allocations = 0;
  offer_setup(s, setup);
  auto beat_and_tick = [&](int n) {
    for (int i = 0; i < n; ++i) {
      s.header.heartbeat.fetch_add(1);
      g_armed = true;
      host.tick();
      g_armed = false;
      ServoEvent e;
      while (s.channels.events.try_pop(e)) {
      }
    }
  };
  beat_and_tick(5);
  ASSERT_TRUE(host.running());
  s.channels.commands.try_push(c);
  c.kind = CommandKind::SetMode;
  c.mode = Mode::Manual;
  c.id = 2;
  s.channels.commands.try_push(c);
  c.kind = CommandKind::JogContinuous;
  c.axis = 0;
  c.value = 20;
  c.id = 3;
  s.channels.commands.try_push(c);
  beat_and_tick(300);
  g_armed = true;
  for (int i = 0; i < 500; ++i) host.tick();  // the heartbeat stops
  g_armed = false;
  EXPECT_EQ(s.header.heartbeat_losses.load(), 1u);
  offer_setup(s, controller::shared_setup(mill({"servo_period_s=0.0005"})));
  beat_and_tick(5);
  EXPECT_EQ(s.header.setup_taken.load(), 2u);
  EXPECT_EQ(g_allocations.load(), 0);
}

}  // namespace
}  // namespace opencnc::control::test
