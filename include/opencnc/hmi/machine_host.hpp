// SPDX-License-Identifier: GPL-3.0-or-later
// MachineHost — the controller and the servo on the simulated machine, running by themselves for
// a server: the servo on a real-time periodic thread with the controller's loop on another, or
// virtual time paced against the wall clock (tests, demonstrations at a multiple of real time).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/clock.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/hmi/simulation.hpp"

namespace opencnc::control {
class Servo;
}  // namespace opencnc::control

namespace opencnc::controller {
class SimRig;
}  // namespace opencnc::controller

namespace opencnc::machine {
class SimMachine;
}

namespace opencnc::hmi {

struct HostOptions {
  /// The servo on a real-time periodic thread (SCHED_FIFO where permitted). Otherwise virtual
  /// time on one thread, `speed` machine seconds per wall-clock second.
  bool realtime = true;
  double speed = 1;
  /// Real time only: pin the servo thread to this CPU (-1: no pinning) and keep the host's other
  /// threads off it, as on a machine with a CPU set aside for the servo (isolcpus).
  int servo_cpu = -1;
};

/// Runs a machine until stopped. start()/stop() from one non-real-time thread; controller()
/// from any (its API is thread-safe).
class MachineHost {
 public:
  MachineHost(const config::MachineProfile& profile, std::shared_ptr<controller::ProgramSource> source,
              HostOptions options);
  ~MachineHost();
  MachineHost(const MachineHost&) = delete;
  MachineHost& operator=(const MachineHost&) = delete;

  /// Starts the threads; false when none could be started. Warnings (no SCHED_FIFO, …) in
  /// `*warnings`. With `servo_cpu` set, the calling thread (and so every thread it starts later,
  /// such as the server's) is moved off the servo's CPU.
  bool start(std::vector<std::string>* warnings);
  /// Stops and joins the threads. Idempotent.
  void stop();

  controller::Controller& controller() noexcept;
  /// Servo periods run so far; periods whose tick finished after the next deadline (real time
  /// only); the servo thread's wake-up latency (real time only, else null). Any thread.
  std::uint64_t ticks() const noexcept;
  std::uint64_t overruns() const noexcept;
  const control::LatencyHistogram* latency() const noexcept;
  /// The real-time clock (its overrun log and thread id, for benchmarks); null in virtual time.
  const control::RealtimeClock* realtime_clock() const noexcept { return clock_.get(); }
  /// A control of the simulated machine: "mains-off" (the mains fail: the power-fail stop),
  /// "mains-on", "electrode" (the electrode in the spindle, for the reference sphere). Applied by
  /// the thread that steps the machine before its next period, and returns once it is: a request
  /// submitted afterwards meets the changed machine. "" or why not (in real time the servo thread
  /// alone touches the machine: virtual time only). Any thread but the stepping one.
  std::string simulate(const SimulationEvent& event);

 private:
  void run_paced();
  void apply_simulation_events();
  void run_controller();

  HostOptions options_;
  double period_s_;
  // Real time: the pieces of a rig, with the servo on the clock's thread.
  std::unique_ptr<control::ServoChannels> channels_;
  std::unique_ptr<machine::SimMachine> sim_;
  std::unique_ptr<control::Servo> servo_;
  std::unique_ptr<controller::Controller> controller_;
  std::unique_ptr<control::RealtimeClock> clock_;
  // Paced virtual time.
  std::unique_ptr<controller::SimRig> rig_;
  std::atomic<std::uint64_t> paced_ticks_{0};
  std::mutex simulate_mutex_;
  std::condition_variable simulate_applied_cv_;
  std::vector<SimulationEvent> simulate_;  ///< events for the paced thread to apply
  std::uint64_t simulate_queued_ = 0, simulate_applied_ = 0;  ///< counts, under simulate_mutex_
  std::atomic<bool> simulate_pending_{false};                 ///< a cheap look before every period

  std::atomic<bool> stop_{false};
  std::thread thread_;  ///< the controller's loop (real time) or the paced rig
};

}  // namespace opencnc::hmi
