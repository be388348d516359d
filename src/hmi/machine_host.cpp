// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated machine and the controller running on their own threads for the server.
#include "opencnc/hmi/machine_host.hpp"

#include <pthread.h>
#include <sched.h>

#include <chrono>
#include <string>

#include <fmt/format.h>

#include "opencnc/control/servo.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/machine/sim_machine.hpp"

namespace opencnc::hmi {

MachineHost::MachineHost(const config::MachineProfile& profile,
                         std::shared_ptr<controller::ProgramSource> source, HostOptions options)
    : options_(options), period_s_(profile.servo_period_s) {
  if (options_.realtime) {
    channels_ = std::make_unique<control::ServoChannels>();
    sim_ = std::make_unique<machine::SimMachine>(config::sim_machine_config(profile));
    servo_ = std::make_unique<control::Servo>(controller::servo_config(profile), *channels_, *sim_);
    // The servo ticks by itself: the controller's long work never holds back its loop.
    controller_ = std::make_unique<controller::Controller>(
        profile, *channels_, std::move(source), controller::ControllerOptions{.long_work_on_thread = true});
    control::RealtimeClock::Options clock;
    clock.period_ns = static_cast<std::int64_t>(profile.servo_period_s * 1e9 + 0.5);
    clock.cpu = options_.servo_cpu;
    clock_ = std::make_unique<control::RealtimeClock>(clock);
  } else {
    // Paced virtual time keeps up with the wall clock while a program is checked, as real time would.
    rig_ = std::make_unique<controller::SimRig>(profile, std::move(source), 1,
                                                controller::ControllerOptions{.long_work_on_thread = true});
  }
}

namespace {

// The calling thread leaves `cpu` to the servo; threads it starts afterwards inherit the mask.
// Returns a warning, or "" when done.
std::string keep_off_cpu(int cpu) {
  if (cpu >= CPU_SETSIZE) return fmt::format("no CPU {} to keep the server's threads off", cpu);
  cpu_set_t set;
  CPU_ZERO(&set);
  if (pthread_getaffinity_np(pthread_self(), sizeof set, &set) != 0)
    return "cannot read this thread's CPU affinity: the server shares the servo's CPU";
  CPU_CLR(static_cast<unsigned>(cpu), &set);
  if (CPU_COUNT(&set) == 0)
    return fmt::format("CPU {} is the only one allowed: the server shares it with the servo", cpu);
  if (pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0)
    return fmt::format("cannot keep the server's threads off CPU {}", cpu);
  return {};
}

}  // namespace

MachineHost::~MachineHost() {
  stop();
}

bool MachineHost::start(std::vector<std::string>* warnings) {
  if (options_.realtime) {
    const bool ok = clock_->start(*servo_);
    if (warnings) warnings->insert(warnings->end(), clock_->warnings().begin(), clock_->warnings().end());
    if (!ok) return false;
    if (options_.servo_cpu >= 0) {
      const std::string w = keep_off_cpu(options_.servo_cpu);
      if (!w.empty() && warnings) warnings->push_back(w);
    }
    thread_ = std::thread([this] { run_controller(); });
  } else {
    thread_ = std::thread([this] { run_paced(); });
  }
  return true;
}

void MachineHost::stop() {
  {
    std::lock_guard lock(simulate_mutex_);  // a simulate() waiting sees stop_ and returns
    stop_ = true;
  }
  simulate_applied_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (clock_) clock_->stop();
}

controller::Controller& MachineHost::controller() noexcept {
  return rig_ ? rig_->controller() : *controller_;
}

std::uint64_t MachineHost::ticks() const noexcept {
  return clock_ ? clock_->ticks() : paced_ticks_.load();
}

std::uint64_t MachineHost::overruns() const noexcept {
  return clock_ ? clock_->overruns() : 0;
}

const control::LatencyHistogram* MachineHost::latency() const noexcept {
  return clock_ ? &clock_->latency() : nullptr;
}

std::string MachineHost::simulate(const SimulationEvent& event) {
  if (event.event != "mains-off" && event.event != "mains-on" && event.event != "electrode" &&
      event.event != "spindle-load")
    return fmt::format("no simulation event \"{}\"", event.event);
  if (!rig_) return "the simulation controls need virtual time (opencnc serve --speed X)";
  std::unique_lock lock(simulate_mutex_);
  simulate_.push_back(event);
  const std::uint64_t mine = ++simulate_queued_;
  simulate_pending_.store(true, std::memory_order_release);
  // Waiting makes the event happen before whatever the caller asks next (a measurement on the
  // sphere must not see the electrode change half-way through its touches).
  if (!simulate_applied_cv_.wait_for(lock, std::chrono::seconds(5),
                                     [&] { return simulate_applied_ >= mine || stop_.load(); }))
    return "the simulated machine did not take the event within 5 s";
  if (simulate_applied_ < mine) return "the simulated machine stopped before it took the event";
  return {};
}

void MachineHost::apply_simulation_events() {
  {
    std::lock_guard lock(simulate_mutex_);
    for (const SimulationEvent& e : simulate_) {
      if (e.event == "electrode")
        rig_->machine().set_electrode(e.offset_mm, e.tip_radius_mm);
      else if (e.event == "spindle-load")
        rig_->machine().set_spindle_load(e.torque_nm);
      else
        rig_->machine().set_mains_ok(e.event == "mains-on");
    }
    simulate_.clear();
    simulate_applied_ = simulate_queued_;
    simulate_pending_.store(false, std::memory_order_relaxed);
  }
  simulate_applied_cv_.notify_all();
}

// The controller's loop beside the real-time servo: one service() per servo period (it reads
// whatever the servo produced meanwhile, so a late service costs nothing but latency).
void MachineHost::run_controller() {
  const auto period = std::chrono::duration<double>(period_s_);
  auto next = std::chrono::steady_clock::now();
  while (!stop_.load(std::memory_order_relaxed)) {
    controller_->service();
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    const auto now = std::chrono::steady_clock::now();
    if (next < now) next = now;  // behind: do not try to catch up in a burst
    std::this_thread::sleep_until(next);
  }
}

// Virtual time paced to `speed` × the wall clock: the rig steps until it is where the wall clock
// says, then sleeps a millisecond. Deterministic in its steps, not in when requests arrive.
void MachineHost::run_paced() {
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t done = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const auto due = static_cast<std::uint64_t>(wall_s * options_.speed / period_s_);
    for (int k = 0; done < due && k < 20000; ++k, ++done) {
      if (simulate_pending_.load(std::memory_order_acquire)) apply_simulation_events();
      rig_->step();
    }
    if (simulate_pending_.load(std::memory_order_acquire)) apply_simulation_events();
    paced_ticks_.store(done, std::memory_order_relaxed);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace opencnc::hmi
