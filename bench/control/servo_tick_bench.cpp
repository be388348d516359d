// SPDX-License-Identifier: GPL-3.0-or-later
// servo_tick_bench — the cost of one full Servo::tick() (safety, commands, interpolation,
// coupling, compensation, limits, outputs, status and trace), six axes, with percentiles.
// Each iteration is one tick timed on its own; the controller's work between ticks is not timed.
// Two machines: a loopback (feedback = command, nearly free: the servo alone) and the simulated
// machine (the servo plus the machine's period). And the drill retrofit (configs/drill-retrofit.toml):
// two steppers through the pulse distributor with pitch and backlash compensation, six interlock
// rules and a hand-fed axis, on a loopback, to show what those stages add. And the plasma table
// (configs/plasma-table.toml) with its simulated plate, the torch on and off, and the torch stage
// alone (TorchHeight::step under height control).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/control/servo.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/machine/sim_machine.hpp"

using namespace opencnc;
using namespace opencnc::control;
using namespace opencnc::controller;

namespace {

const char* kSixAxes = R"(name = "six-axis"
servo_period_s = 0.001
[axis.x]
max_velocity = 100.0
max_acceleration = 1000.0
min_limit = -500.0
max_limit = 500.0
[axis.y]
max_velocity = 100.0
max_acceleration = 1000.0
min_limit = -500.0
max_limit = 500.0
[axis.z]
max_velocity = 100.0
max_acceleration = 1000.0
min_limit = -500.0
max_limit = 500.0
[axis.a]
max_velocity = 360.0
max_acceleration = 3600.0
min_limit = -3600.0
max_limit = 3600.0
[axis.b]
max_velocity = 360.0
max_acceleration = 3600.0
min_limit = -3600.0
max_limit = 3600.0
[axis.c]
max_velocity = 360.0
max_acceleration = 3600.0
min_limit = -36000.0
max_limit = 36000.0
)";

/// Feedback = the last command, switches quiet, e-stop chain closed: the cost of the servo alone.
class LoopbackMachine final : public machine::MachineIO {
 public:
  explicit LoopbackMachine(int joints) : joints_(joints) { in_.estop_ok = true; }
  machine::MachineCapabilities capabilities() const noexcept override {
    machine::MachineCapabilities c;
    c.joint_count = joints_;
    return c;
  }
  void read(machine::MachineInputs& in) noexcept override { in = in_; }
  void write(const machine::MachineOutputs& out) noexcept override {
    ++in_.cycle;
    in_.estop_ok = true;
    for (int j = 0; j < joints_; ++j)
      in_.joints[static_cast<std::size_t>(j)].position = out.joints[static_cast<std::size_t>(j)].position;
  }

 private:
  int joints_;
  machine::MachineInputs in_{};
};

/// A spiral of short lines and helical arcs in XY, Z waving, A B C turning: all six axes move.
std::shared_ptr<canon::Program> six_axis_program() {
  canon::ProgramBuilder b(kXyzabc);
  b.set_motion_control_mode(canon::MotionControl::Continuous, 0.01);
  b.set_feed_rate(3000);
  canon::SegmentId id = 0;
  double th = 0;
  for (int i = 0; i < 30000; ++i) {
    const double r = 30 + 8 * std::sin(i * 0.002);
    th += (0.3 + 0.7 * ((i * 7919) % 97) / 97.0) / r;  // 0.3–1 mm pseudo-random lengths
    Pose p;
    p[Axis::X] = r * std::cos(th);
    p[Axis::Y] = r * std::sin(th);
    p[Axis::Z] = 3 * std::sin(th * 2);
    p[Axis::A] = 20 * std::sin(th);
    p[Axis::B] = 15 * std::cos(th * 3);
    p[Axis::C] = th * 20;
    b.straight_feed(id++, p);
  }
  b.program_end();
  auto prog = std::make_shared<canon::Program>(b.take());
  return prog;
}

/// XY circles of 0.3–1 mm lines over the drill's table, reversing every quarter turn on one axis:
/// the backlash is taken up again and again.
std::shared_ptr<canon::Program> drill_program() {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_motion_control_mode(canon::MotionControl::Continuous, 0.01);
  b.set_feed_rate(1500);
  canon::SegmentId id = 0;
  double th = 0;
  for (int i = 0; i < 30000; ++i) {
    th += (0.3 + 0.7 * ((i * 7919) % 97) / 97.0) / 40.0;
    Pose p;
    p[Axis::X] = 300 + 40 * std::cos(th);
    p[Axis::Y] = 200 + 40 * std::sin(th);
    b.straight_feed(id++, p);
  }
  b.program_end();
  return std::make_shared<canon::Program>(b.take());
}

template <typename Machine>
void servo_tick(benchmark::State& state, std::unique_ptr<Machine> machine,
                const config::ProfileLoad& load = config::parse_profile(kSixAxes, "six-axis.toml"),
                std::shared_ptr<canon::Program> program = six_axis_program()) {
  if (!load.ok()) {
    state.SkipWithError("profile");
    return;
  }
  auto channels = std::make_unique<ServoChannels>();
  channels->trace_enabled = true;
  Servo servo(servo_config(*load.profile), *channels, *machine);
  Controller controller(*load.profile, *channels);
  const auto submit = [&](Request r) {
    const std::uint64_t id = controller.submit(std::move(r));
    for (int i = 0; i < 100 && !controller.outcome(id); ++i) {
      controller.service();
      servo.tick();
    }
    const auto o = controller.outcome(id);
    return o && o->accepted;
  };
  if (!submit(Request::simple(CommandKind::MachineOn)) || !submit(Request::set_mode(Mode::Auto)) ||
      !submit(Request::open(program, "bench")) || !submit(Request::simple(CommandKind::CycleStart))) {
    state.SkipWithError("the program does not start");
    return;
  }
  std::vector<double> ns;
  ns.reserve(1 << 22);
  TraceSample t;
  std::uint64_t n = 0;
  for (auto _ : state) {
    controller.service();
    while (channels->trace.try_pop(t)) {
    }
    if (++n % 4000 == 0) {  // an override change now and then
      controller.submit(Request::feed_override((n / 4000) % 2 ? 0.8 : 1.0));
    }
    if (!controller.status().run_active && !submit(Request::simple(CommandKind::CycleStart))) {
      state.SkipWithError("the run ended and does not start again");
      break;
    }
    const auto t0 = std::chrono::steady_clock::now();
    servo.tick();
    const auto t1 = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(t1 - t0).count();
    state.SetIterationTime(dt);
    ns.push_back(dt * 1e9);
  }
  std::sort(ns.begin(), ns.end());
  const auto pct = [&](double p) {
    return ns.empty() ? 0.0 : ns[static_cast<std::size_t>(p * static_cast<double>(ns.size() - 1))];
  };
  state.counters["p50_ns"] = pct(0.5);
  state.counters["p99_ns"] = pct(0.99);
  state.counters["p999_ns"] = pct(0.999);
  state.counters["max_ns"] = ns.empty() ? 0.0 : ns.back();
}

void BM_ServoTickLoopback(benchmark::State& state) {
  servo_tick(state, std::make_unique<LoopbackMachine>(6));
}

void BM_ServoTickSimMachine(benchmark::State& state) {
  const config::ProfileLoad load = config::parse_profile(kSixAxes, "six-axis.toml");
  servo_tick(state, std::make_unique<machine::SimMachine>(config::sim_machine_config(*load.profile)));
}

/// The drill on a loopback, homed where it stands (the tick of a run is what is timed, not the
/// decel_midpoint homing before it).
void BM_ServoTickDrillLoopback(benchmark::State& state) {
  config::ProfileLoad load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.toml");
  if (load.ok()) {
    for (config::AxisProfile& a : load.profile->axes) a.homing = config::HomingProfile{};
  }
  servo_tick(state, std::make_unique<LoopbackMachine>(3), load, drill_program());
}

/// The plasma table (configs/plasma-table.toml) on its simulated machine and plate: squares of
/// 100 mm cut at 2400 mm/min, the torch on (M190: the plate found, pierced, the height control
/// acting) or, with `torch` false, the same path with the torch stage idle.
std::shared_ptr<canon::Program> plasma_program(bool torch) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  canon::SegmentId id = 0;
  Pose p;
  p[Axis::X] = 300;
  p[Axis::Y] = 300;
  p[Axis::Z] = 15;
  b.straight_traverse(id++, p);
  if (torch) b.process_code(canon::ProcessCode{machine::kTorchOnCode, 0, 0, machine::kTorchOnCode});
  b.set_feed_rate(2400);
  for (int k = 0; k < 40; ++k) {
    for (const auto& [x, y] : {std::pair{400.0, 300.0}, {400.0, 400.0}, {300.0, 400.0}, {300.0, 300.0}}) {
      p[Axis::X] = x;
      p[Axis::Y] = y;
      b.straight_feed(id++, p);
    }
  }
  if (torch) b.process_code(canon::ProcessCode{machine::kTorchOffCode, 0, 0, machine::kTorchOnCode});
  b.program_end();
  return std::make_shared<canon::Program>(b.take());
}

void plasma_tick(benchmark::State& state, bool torch) {
  const config::ProfileLoad load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/plasma-table.toml");
  if (!load.ok()) {
    state.SkipWithError("profile");
    return;
  }
  servo_tick(state, std::make_unique<machine::SimMachine>(config::sim_machine_config(*load.profile)), load,
             plasma_program(torch));
}

void BM_ServoTickPlasmaTorchOn(benchmark::State& state) {
  plasma_tick(state, true);
}
void BM_ServoTickPlasmaTorchOff(benchmark::State& state) {
  plasma_tick(state, false);
}

/// The torch stage alone, cutting under height control (a voltage with a small error and noise).
void BM_TorchHeightStep(benchmark::State& state) {
  machine::PlasmaConfig c;
  c.enabled = 1;
  TorchHeight t;
  t.configure(c, 1e-3);
  t.apply_code(machine::kTorchOnCode, 0);
  TorchInputs in;
  in.programmed_z = 15;
  in.path_velocity = in.feed = 40;
  std::uint64_t n = 0;
  const auto feed = [&] {
    in.measured_z = in.programmed_z + t.offset_mm();
    in.sensor = in.measured_z <= -1.5;
    in.arc_ok = t.torch_on();
    in.arc_voltage_v = in.arc_ok ? 100 + 7.5 * (in.measured_z + 0.2) + 0.3 * std::sin(0.1 * ++n) : 0.0;
  };
  for (int i = 0; i < 20000 && t.status().thc != ThcState::Active; ++i) {
    feed();
    t.step(in);
  }
  if (t.status().thc != ThcState::Active) {
    state.SkipWithError("the height control did not start");
    return;
  }
  double sum = 0;
  for (auto _ : state) {
    feed();
    sum += t.step(in);
  }
  benchmark::DoNotOptimize(sum);
}

}  // namespace

BENCHMARK(BM_TorchHeightStep);
BENCHMARK(BM_ServoTickPlasmaTorchOn)->UseManualTime()->Iterations(200000)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ServoTickPlasmaTorchOff)->UseManualTime()->Iterations(200000)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ServoTickLoopback)->UseManualTime()->Iterations(200000)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ServoTickSimMachine)->UseManualTime()->Iterations(200000)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ServoTickDrillLoopback)->UseManualTime()->Iterations(200000)->Unit(benchmark::kNanosecond);
BENCHMARK_MAIN();
