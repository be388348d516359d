// SPDX-License-Identifier: GPL-3.0-or-later
// JointHoming — the homing state machine of one joint (switch, switch + index, index, deceleration
// dog + home switch, immediate), driving the joint's AxisMover.
#pragma once

#include <cstdint>

#include "opencnc/control/axis_mover.hpp"
#include "opencnc/control/servo_config.hpp"

namespace opencnc::control {

/// What homing reads each period, in joint coordinates (before compensation).
struct HomingInputs {
  double feedback = 0;
  bool home_switch = false;
  bool decel_switch = false;
  std::uint32_t index_count = 0;
  double index_position = 0;
  double home_level = 0;  ///< the proximity sensor's analog level (DecelMidpoint)
};

enum class HomingPhase : std::uint8_t {
  Idle,
  Clear,    ///< the switch is already active: move off it against the search direction
  Search,   ///< at search velocity toward the switch (or the deceleration dog)
  BackOff,  ///< off the switch again, to approach it slowly
  Latch,    ///< at latch velocity until the edge (rising, or falling when latching away)
  Index,    ///< at latch velocity until the next encoder index mark
  Overrun,  ///< DecelMidpoint: on past the dog by the overrun distance, to rest
  Return,   ///< DecelMidpoint: back at Vm (working direction) until the sensor's rising edge
  Measure,  ///< DecelMidpoint: at Vp over the on-zone until its falling edge
  Center,   ///< DecelMidpoint: back half the measured width, to the middle of the zone
  Final,    ///< to the home position
  Done,
  Failed,  ///< the switch or sensor was not where it must be (a fault)
};

/// Name of a phase for traces and logs ("search", "measure", …). Any thread; real-time safe.
const char* to_string(HomingPhase p) noexcept;

/// The crossing of a level by an analog signal sampled at positions, interpolated between the
/// samples: samples at the same position (a stepper standing between steps) are averaged, and the
/// crossing lies between the mean level at the previous position and the level at the present
/// one. Real-time safe, fixed-size.
class EdgeInterpolator {
 public:
  void reset() noexcept { *this = EdgeInterpolator{}; }
  /// One sample.
  void add(double position, double level) noexcept;
  /// Where the signal crossed `level` between the previous position and this one (the present
  /// position when there is no previous one or the levels are equal).
  double crossing(double level) const noexcept;

 private:
  double position_ = 0, sum_ = 0;
  int count_ = 0;
  double previous_position_ = 0, previous_level_ = 0;
  bool have_previous_ = false;
};

/// One joint's homing. The latch sets the joint's offset (machine = joint + offset) so that the
/// latched edge or index mark is at `switch_position`; the joint then moves to `position`.
/// Sequence per method (signs of the velocities give directions):
/// - Switch: [Clear] → Search → stop → (latch same way as search: BackOff → Latch on the rising
///   edge | latch the other way: Latch on the falling edge) → stop → Final;
/// - SwitchIndex: the same, and after the switch edge Index at latch velocity;
/// - Index: Index at latch velocity;
/// - DecelHome: [Clear] → Search until the dog → Latch at latch velocity until the home switch;
/// - DecelMidpoint: [Clear] → Search at Vc until the dog → Overrun (decelerate, go on to the
///   overrun distance past the dog's edge) → Return at Vm the other way (the working direction,
///   so the backlash is taken up) until the sensor's level crosses level_on (rising edge,
///   interpolated) → Measure at Vp until it falls below level_off (falling edge, interpolated):
///   width S → stop → Center: back S/2 to the middle, which is `switch_position` → Final. Both
///   edges must come while the dog is still on (else Failed);
/// - Immediate: the present position becomes `position` at once.
/// Real-time safe, noexcept, fixed-size.
class JointHoming {
 public:
  /// Begins homing. Tick thread.
  void start(const HomeConfig& config, const HomingInputs& in) noexcept;
  /// Advances one period: commands `mover` (joint coordinates) and, at the latch, writes the
  /// new `offset`. Tick thread.
  void tick(const HomeConfig& config, const HomingInputs& in, AxisMover& mover, double& offset) noexcept;
  /// Stops homing where it is (the mover is told to stop). Tick thread.
  void cancel(AxisMover& mover) noexcept;

  HomingPhase phase() const noexcept { return phase_; }
  bool active() const noexcept { return phase_ != HomingPhase::Idle && phase_ != HomingPhase::Done; }
  bool done() const noexcept { return phase_ == HomingPhase::Done; }
  bool failed() const noexcept { return phase_ == HomingPhase::Failed; }
  /// Where the latch happened (joint feedback), for tests and logs.
  double latched_at() const noexcept { return latched_at_; }
  /// DecelMidpoint: the interpolated edges (joint coordinates) of the last measurement.
  double rising_edge() const noexcept { return rising_; }
  double falling_edge() const noexcept { return falling_; }

 private:
  void latch(const HomeConfig& config, double joint_position, double& offset) noexcept;
  void after_switch_latch(const HomeConfig& config, AxisMover& mover) noexcept;
  void step(const HomeConfig& config, const HomingInputs& in, AxisMover& mover, double& offset) noexcept;
  void step_midpoint(const HomeConfig& config, const HomingInputs& in, AxisMover& mover,
                     double& offset) noexcept;
  bool trigger(const HomingInputs& in) const noexcept;

  HomingPhase phase_ = HomingPhase::Idle;
  bool stopping_ = false;          ///< waiting for the mover to settle before the next phase
  bool latch_on_release_ = false;  ///< Latch waits for the switch to release
  std::uint32_t index_count_ = 0;  ///< index count when Index began
  double latched_at_ = 0;
  double previous_feedback_ = 0;  ///< feedback of the last period, for the latch
  double offset_ = 0;             ///< the latched offset, for the final move
  // DecelMidpoint.
  EdgeInterpolator edge_;
  bool sensor_on_ = false;  ///< the software comparator on the sensor's level
  double dog_at_ = 0;       ///< where the dog was met
  double rising_ = 0, falling_ = 0;
};

}  // namespace opencnc::control
