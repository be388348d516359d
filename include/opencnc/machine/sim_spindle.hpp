// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated spindle: speed ramp with an acceleration limit, orient, encoder with index.
#pragma once

#include <cstdint>

#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/sim_config.hpp"

namespace opencnc::machine {

/// Same period protocol as SimJoint: begin_period(), substep() × n, end_period(), sample().
/// Everything but the constructor is real-time safe.
class SimSpindle {
 public:
  SimSpindle() = default;
  /// Non-real-time. `config` must be valid.
  /// `linear_periods`: a period at constant speed is integrated at once.
  SimSpindle(const SimSpindleConfig& config, double servo_period_s, int substeps, bool linear_periods = true);

  /// `powered`: the spindle drive has power and no fault; without it the spindle coasts
  /// down at the ramp limit (a drive that lost power brakes on its own resistor).
  void begin_period(const SpindleOutputs& cmd, bool powered) noexcept;
  /// False when begin_period() has integrated the whole period (constant speed).
  bool needs_substeps() const noexcept { return !period_done_; }
  void substep() noexcept;
  void end_period() noexcept;
  void sample(SpindleInputs& in) const noexcept;

  void set_fault(bool fault) noexcept { fault_ = fault; }
  /// A load torque opposing the rotation (a cut), N·m ≥ 0; it shows in the drive's torque.
  void set_load(double torque_nm) noexcept { load_nm_ = torque_nm; }
  double torque_nm() const noexcept { return torque_nm_; }  ///< the drive's torque, last period

  double position_rev() const noexcept { return position_rev_; }  ///< true position, rev
  double speed_rps() const noexcept { return speed_rps_; }        ///< true speed, rev/s

 private:
  bool orienting() const noexcept { return powered_ && cmd_.orient && config_.orient; }
  double orient_target_speed() const noexcept;
  void update_torque() noexcept;

  SimSpindleConfig config_{};
  double h_ = 0;
  double period_s_ = 0;
  double max_step_rps_ = 0;  // speed change per sub-step, rev/s
  bool linear_periods_ = true;
  bool period_done_ = false;
  SpindleOutputs cmd_{};
  bool powered_ = false;
  bool fault_ = false;
  double target_rps_ = 0;
  double position_rev_ = 0, speed_rps_ = 0;
  double position_at_period_start_ = 0;
  double speed_at_period_start_ = 0;
  double load_nm_ = 0;
  double torque_nm_ = 0;
  std::uint32_t index_count_ = 0;
  double index_position_rev_ = 0;
};

}  // namespace opencnc::machine
