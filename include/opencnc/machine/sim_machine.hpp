// SPDX-License-Identifier: GPL-3.0-or-later
// SimMachine: the embedded default MachineIO backend, a deterministic machine in virtual time.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/core/vec3.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/sim_broach_load.hpp"
#include "opencnc/machine/sim_config.hpp"
#include "opencnc/machine/sim_edm_process.hpp"
#include "opencnc/machine/sim_joint.hpp"
#include "opencnc/machine/sim_plasma_process.hpp"
#include "opencnc/machine/sim_sphere_probe.hpp"
#include "opencnc/machine/sim_spindle.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {

/// A simulated machine. Each write() advances virtual time by exactly one servo period in
/// `substeps` fixed sub-steps and samples the inputs the next read() returns, so two runs
/// with the same configuration, seed and outputs are bit-for-bit identical.
///
/// Fault and process injection (set_*) and the ground-truth accessors are for tests,
/// scenarios and plots: call them between periods from the thread that drives the machine;
/// they are real-time safe. Injected inputs show from the next write() on.
class SimMachine final : public MachineIO {
 public:
  /// Non-real-time (copies pitch tables). `config` must be valid (the profile loader checks).
  explicit SimMachine(const SimMachineConfig& config);

  MachineCapabilities capabilities() const noexcept override;
  void read(MachineInputs& in) noexcept override;
  void write(const MachineOutputs& out) noexcept override;

  // --- injection ---------------------------------------------------------------------
  void set_estop_pressed(bool pressed) noexcept { estop_pressed_ = pressed; }
  void set_mains_ok(bool ok) noexcept { mains_ok_ = ok; }
  /// An amplifier fault on `joint` (0-based); ignored for joints that do not exist.
  void set_amp_fault(int joint, bool fault) noexcept;
  /// Process load on `joint`'s table (cutting force, broach load, gravity), N or N·m.
  void set_external_effort(int joint, double effort) noexcept;
  void set_spindle_fault(bool fault) noexcept { spindle_.set_fault(fault); }
  /// A cut's torque on the spindle, N·m ≥ 0, opposing its rotation (the simulated spindle has no
  /// cutting model of its own: tests and demos set the load).
  void set_spindle_load(double torque_nm) noexcept { spindle_.set_load(torque_nm); }
  void set_digital_input(int channel, bool value) noexcept;
  void set_analog_input(int channel, double value) noexcept;
  /// Analog input `channel` drifts toward `target` at `units_per_s` (a level sinking, a
  /// temperature rising); a set_analog_input() ends the drift.
  void drift_analog_input(int channel, double target, double units_per_s) noexcept;
  double analog_input(int channel) const noexcept {
    return channel >= 0 && channel < kAnalogChannels ? analog_in_[static_cast<std::size_t>(channel)] : 0.0;
  }
  /// Whether the torch can light (false: gas out, no arc; arc_ok never comes).
  void set_arc_available(bool available) noexcept { arc_available_ = available; }
  /// Plasma: the arc goes out now (until the torch is switched off and on); ignored without a plate.
  void inject_arc_loss() noexcept { plasma_.inject_arc_loss(); }
  /// EDM gap voltage reported while the generator is on (a machine without a simulated gap).
  void set_gap_voltage(double volts) noexcept { gap_voltage_v_ = volts; }
  /// EDM: a short (debris bridge) in the simulated gap until the electrode backs off from it.
  void inject_edm_short() noexcept { edm_.inject_short(); }
  /// EDM: a fresh workpiece (every front back at the surface), as when the next disc is clamped.
  void new_edm_workpiece() noexcept {
    edm_.configure(config_.edm, config_.servo_period_s);
    edm_.mount(mounted_tool_);
  }
  /// Machine temperature, °C (proximity sensors drift with it).
  void set_temperature(double celsius) noexcept { temperature_c_ = celsius; }
  /// The broach's cutter wears: its force grows by `factor` (1 = sharp); ignored without a broach.
  void set_tool_dull(double factor) noexcept { broach_.set_dull_factor(factor); }
  /// The broach's workpiece as another simulation left it (SimBroachLoad::bore()): the machine
  /// powered up again after a power failure finds its groove already cut. False (nothing
  /// changed) without a broach or for a bore of another size.
  bool restore_broach_bore(std::span<const float> bore) noexcept {
    return config_.broach.present && broach_.restore_bore(bore);
  }
  /// The operator moves manual joint `joint` toward `target` at up to `speed` units/s.
  void set_hand_target(int joint, double target, double speed) noexcept;
  /// The electrode in the spindle is replaced by another one (the same tool number): its true
  /// offsets (as an exact tool table would hold them, mm) and tip radius. The reference sphere
  /// is touched and the spark gap burns where it really is; it is new (no wear).
  void set_electrode(const Vec3& offset, double tip_radius) noexcept {
    replace_electrode(mounted_tool_, offset, tip_radius);
  }
  /// The operator puts a new electrode in for `tool` (in the spindle now or in its pocket): its
  /// true offsets and tip radius, no wear; a tool change mounts it. Ignored beyond
  /// kMaxSimElectrodes tools.
  void replace_electrode(std::int32_t tool, const Vec3& offset, double tip_radius) noexcept;
  /// The operator turns the handwheel by `counts` (+ = clockwise); ignored without one.
  void turn_handwheel(std::int32_t counts) noexcept;

  // --- ground truth ------------------------------------------------------------------
  std::uint64_t cycle() const noexcept { return inputs_.cycle; }
  double time_s() const noexcept { return static_cast<double>(inputs_.cycle) * config_.servo_period_s; }
  const SimJoint& joint(int j) const noexcept { return joints_[static_cast<std::size_t>(j)]; }
  const SimSpindle& spindle() const noexcept { return spindle_; }
  const SimEdmProcess& edm() const noexcept { return edm_; }
  /// The simulated plate and arc (a plasma table).
  const SimPlasmaProcess& plasma() const noexcept { return plasma_; }
  const SimSphereProbe& sphere_probe() const noexcept { return sphere_; }
  /// The tool the last tool change mounted (0 before any).
  std::int32_t mounted_tool() const noexcept { return mounted_tool_; }
  /// The mounted electrode's true offsets and tip radius (zero for a tool the simulation does
  /// not know), without its wear.
  const SimElectrode& electrode() const noexcept { return electrode_; }
  /// True while the drives have power: e-stop chain closed, released, DC link above minimum.
  bool drives_powered() const noexcept;
  double ups_remaining_s() const noexcept {
    return static_cast<double>(ups_periods_left_) * config_.servo_period_s;
  }
  double temperature_c() const noexcept { return temperature_c_; }
  /// The broaching load model (material cut so far, the chip, the force).
  const SimBroachLoad& broach() const noexcept { return broach_; }
  /// The broach's workpiece (SimBroachLoad::bore()); empty on a machine without a broach.
  std::span<const float> broach_bore() const noexcept {
    return config_.broach.present ? broach_.bore() : std::span<const float>{};
  }

 private:
  void advance(const MachineOutputs& out) noexcept;
  void update_power(const MachineOutputs& out) noexcept;
  void update_auxiliaries() noexcept;
  void update_broach() noexcept;
  void step_edm() noexcept;
  void step_plasma() noexcept;
  void mount(std::int32_t tool) noexcept;
  Vec3 worn_offset() const noexcept;
  void sample() noexcept;
  void sample_probe() noexcept;
  void sample_sphere_probe() noexcept;

  SimMachineConfig config_;
  std::array<SimJoint, kMaxJoints> joints_{};
  SimSpindle spindle_;
  SimEdmProcess edm_;
  SimPlasmaProcess plasma_;
  bool tool_changed_ = false;  ///< the tool changer acknowledged a change last period
  std::int32_t mounted_tool_ = 0;
  SimElectrode electrode_{};  ///< the mounted tool's true electrode
  SimSwitch probe_;
  SimSphereProbe sphere_;
  std::array<SimSwitch, kMaxSimInputSwitches> input_switches_{};
  double probe_table_ = 0;  ///< the probe joint's table position at the last sample
  std::array<double, kMaxJoints> previous_feedback_{};  ///< the encoders at the sample before
  SplitMix64 rng_;
  SimBroachLoad broach_;  ///< the broaching load (config_.broach.present)
  // The outputs latched by the last write() that the machine uses between writes.
  bool estop_release_ = false;
  ProcessOutputs process_{};
  std::uint64_t digital_out_ = 0;  ///< the last digital outputs (the oxy-fuel torch's cutting oxygen)
  ToolChangerOutputs tool_{};
  MachineInputs inputs_{};
  // Injected world.
  bool estop_pressed_ = false;
  bool mains_ok_ = true;
  bool arc_available_ = true;
  double gap_voltage_v_ = 0;
  std::array<double, kMaxJoints> external_effort_{};
  std::uint64_t digital_in_ = 0;
  std::array<double, kAnalogChannels> analog_in_{};
  std::array<double, kAnalogChannels> analog_target_{}, analog_rate_{};  ///< drifts (rate 0: none)
  double temperature_c_ = kReferenceTemperatureC;
  std::uint32_t handwheel_count_ = 0;  // wraps like a counter
  // Power supply: DC link, UPS, and the undervoltage fault each drive latches.
  double dc_link_v_ = 0;
  std::uint64_t ups_periods_left_ = 0;
  bool on_battery_ = false;  // the UPS held the link during the last period
  bool undervoltage_ = false;
  std::array<bool, kMaxJoints> undervoltage_fault_{};
  // Auxiliary timers, in whole periods, and the periods each one needs.
  std::uint64_t arc_periods_ = 0, prepare_periods_ = 0, change_periods_ = 0;
  std::uint64_t arc_needed_ = 0, prepare_needed_ = 0, change_needed_ = 0;
};

}  // namespace opencnc::machine
