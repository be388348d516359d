// SPDX-License-Identifier: GPL-3.0-or-later
// One simulated joint: drive loops, mass with friction, backlash, pitch error, encoder, switches.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/sim_config.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {

/// Lead-screw pitch error: linear interpolation between sorted points, the end values held
/// beyond the ends. Construction allocates (non-real-time); at() is real-time safe.
class PitchErrorTable {
 public:
  PitchErrorTable() = default;
  explicit PitchErrorTable(std::vector<PitchPoint> points);

  bool empty() const noexcept { return points_.empty(); }
  /// Error at nominal screw position `s`. Remembers the last segment, so a slowly moving
  /// axis costs O(1) per call; the result does not depend on that memory.
  double at(double s) const noexcept;

 private:
  std::vector<PitchPoint> points_;
  std::vector<double> slopes_;       // error change per unit along each segment
  mutable std::size_t segment_ = 0;  // points_[segment_] ≤ s < points_[segment_ + 1] last time
};

/// A servo drive and its mechanics over one whole period while they are linear (moving one way,
/// or held by static friction): the product of the sub-step maps, in coordinates relative to
/// the period's command (docs/machine.md, "Whole periods at once"). Built by the joint's
/// constructor.
struct SimPeriodMap {
  /// z: feedback − command, velocity − feed-forward, force, the two integrators (the state),
  /// then feed-forward velocity, constant force (load − Coulomb friction) and encoder bias.
  static constexpr int kSize = 8;
  static constexpr int kStates = 5;
  using Row = std::array<double, kSize>;
  /// What a period needs that is linear in z: the state at its end, the force command and the
  /// velocity reference at the first and the last sub-step. Held periods need the first rows only
  /// (the first five, seven with a velocity limit).
  enum Output : int {
    kNextForce,
    kNextPosIntegral,
    kNextVelIntegral,
    kForceCommandFirst,
    kForceCommandLast,
    kVelRefFirst,
    kVelRefLast,
    kNextRelPosition,
    kNextRelVelocity,
    kOutputs
  };
  /// How far from the chord between first and last sub-step a quantity can bend, per |z_k|
  /// (every sub-step's value lies within Σ_k bend_k·|z_k| of that chord).
  enum Bend : int { kForceCommandBend, kVelRefBend, kVelocityBend, kBends };
  /// Column k holds z_k's coefficients (one product for all of them), padded to even lengths.
  std::array<std::array<double, kOutputs + 1>, kSize> outputs{};
  std::array<std::array<double, kBends + 1>, kSize> bends{};
  std::array<Row, kSize> energy{};  ///< energy_j = zᵀ·energy·z
};

/// A joint of the simulated machine. The owner calls begin_period(), then substep() for
/// i = 0 … substeps-1, then end_period(), once per servo period; sample() fills the inputs.
/// begin_period() integrates a whole period at once where the drive stays linear all period
/// (SimPeriodMap; needs_substeps() is then false and substep() does nothing).
/// Everything but the constructor is real-time safe and allocation-free.
class SimJoint {
 public:
  SimJoint() = default;
  /// Non-real-time. `config` must be valid (the profile loader checks it). `linear_periods`:
  /// integrate the periods in which the drive and the mechanics are linear at once.
  SimJoint(const SimJointConfig& config, double servo_period_s, int substeps, bool linear_periods = true);

  /// Latches this period's command. `powered`: the drive has power (e-stop chain closed,
  /// DC link above undervoltage, no fault). `external_effort` acts on the table, N or N·m.
  void begin_period(const JointOutputs& cmd, bool powered, double external_effort) noexcept;
  /// False when begin_period() has integrated the whole period already.
  bool needs_substeps() const noexcept { return !period_done_; }
  /// Integrates sub-step `i` of the period.
  void substep(int i) noexcept;
  /// Finishes the period: index marks, velocity of a stepper.
  void end_period() noexcept;
  /// Feedback, index and switches as the inputs of the next servo tick; proximity sensors read
  /// at `temperature_c`.
  void sample(JointInputs& in, SplitMix64& rng, double temperature_c = kReferenceTemperatureC) noexcept;

  /// An injected drive fault: the drive drops its force and reports amp_fault.
  void set_fault(bool fault) noexcept { injected_fault_ = fault; }
  /// A manual joint: the operator moves it toward `target` at up to `speed` (units/s), with the
  /// acceleration of a hand (kHandAcceleration). Ignored by driven joints.
  void set_hand_target(double target, double speed) noexcept;
  /// Hand acceleration of a manual joint, units/s².
  static constexpr double kHandAcceleration = 500;

  JointCapabilities capabilities() const noexcept;

  // Ground truth, for tests and plots.
  double motor_position() const noexcept { return motor_; }
  double table_position() const noexcept;                    ///< after backlash and pitch error
  double velocity() const noexcept { return velocity_; }     ///< motor velocity, units/s
  double effort() const noexcept { return effort_; }
  /// Mechanical energy the drive put into the axis during the last period, J (negative when
  /// braking). Feeds the DC link model.
  double energy_j() const noexcept;
  /// Stepper: the rotor is out of step (stalled, or coasting without power).
  bool stalled() const noexcept { return stalled_; }
  /// Stepper: steps emitted that the rotor did not make (lost steps, + = the rotor is behind).
  std::int64_t lost_steps() const noexcept { return lost_steps_; }

 private:
  double feedback_raw() const noexcept;
  std::int64_t counts(double position) const noexcept;
  double quantise(double position) const noexcept;
  double quantise_fast(double position) const noexcept;
  void servo_substep(double t_s) noexcept;
  void stepper_substep(int i) noexcept;
  bool integrate_stepper_period() noexcept;
  void coast() noexcept;
  void integrate_hand_period() noexcept;
  void compensate_friction() noexcept;
  void feed_forward_acceleration() noexcept;
  void integrate_mechanics(double drive_effort) noexcept;
  void take_up_backlash() noexcept;
  void update_index(double before, double after) noexcept;
  SimPeriodMap build_period_map(bool held) const;
  bool integrate_period() noexcept;
  bool integrate_moving_period() noexcept;
  bool integrate_held_period() noexcept;
  void load_state(double feedback) noexcept;
  struct MapValues;
  template <std::size_t Rows, std::size_t Bends>
  MapValues evaluate(const SimPeriodMap& map) const noexcept;
  bool within_limits(const MapValues& y) const noexcept;
  void take_state(const MapValues& y) noexcept;

  SimJointConfig config_{};
  PitchErrorTable pitch_;
  SimSwitch limit_neg_, limit_pos_, home_, decel_;
  // Derived constants.
  double h_ = 0;               // sub-step, s
  double unit_per_count_ = 0;  // 1 / counts_per_unit
  int substeps_ = 1;
  double period_s_ = 0;
  double accel_per_effort_ = 0;           // (units/s²) per N: scale / inertia
  double velocity_gain_ = 0;              // N per (units/s)
  double velocity_integral_ = 0;          // 1/s
  double current_alpha_ = 1;              // first-order lag factor per sub-step
  double power_per_effort_velocity_ = 0;  // W per (N · units/s)
  double half_backlash_ = 0;
  bool linear_periods_ = false;  // integrate linear periods at once (servo joints)
  bool linear_moving_ = false;   // … also while moving (the loop is not closed around backlash)
  double encoder_bias_ = 0;      // mean of position − encoder reading: half a count
  SimPeriodMap moving_map_{}, held_map_{};
  // Latched command.
  JointOutputs cmd_{};
  bool powered_ = false;
  double external_effort_ = 0;
  bool injected_fault_ = false;
  // State.
  double motor_ = 0, velocity_ = 0, effort_ = 0, screw_ = 0;
  double position_integral_ = 0, velocity_error_integral_ = 0;
  int command_direction_ = 0;    // sign of the last period's commanded velocity (friction compensation)
  double last_velocity_ff_ = 0;  // the last period's commanded velocity (acceleration feed-forward)
  double accel_ff_shift_ = 0;    // this period's feed-forward, as a shift of the velocity integrator
  std::int64_t steps_emitted_ = 0, steps_at_period_start_ = 0;
  double feedback_at_period_start_ = 0;
  double energy_j_ = 0;
  bool period_done_ = false;    // begin_period() integrated the period
  bool period_moving_ = false;  // … by the moving map, from z_ (for energy_j())
  SimPeriodMap::Row z_{};
  std::uint32_t index_count_ = 0;
  double index_position_ = 0;
  // Stepper with a pull-out curve.
  bool stepper_dynamic_ = false;  // the rotor is a mass that can stall
  bool stalled_ = false;          // dropped out of step under power (what a stall detector sees)
  bool in_step_ = true;           // the rotor follows the steps (false: it coasts)
  std::int64_t lost_steps_ = 0;   // emitted − made
  double step_velocity_ = 0;      // the step rate as the rotor feels it (lagged), units/s
  // Manual joint: where the operator's hand is heading.
  double hand_target_ = 0, hand_speed_ = 0;
  SimProximity home_sensor_;
};

}  // namespace opencnc::machine
