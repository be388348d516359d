// SPDX-License-Identifier: GPL-3.0-or-later
// JointHoming — the homing state machine of one joint (switch, switch + index, index, deceleration
// dog + home switch, immediate), driving the joint's AxisMover.
#pragma once

#include <cstdint>

#include "opencnc/control/axis_mover.hpp"
#include "opencnc/control/servo_config.hpp"

namespace opencnc::control {

/// What homing reads each period, in joint coordinates.
struct HomingInputs {
  double feedback = 0;
  bool home_switch = false;
  bool decel_switch = false;
  std::uint32_t index_count = 0;
  double index_position = 0;
};

enum class HomingPhase : std::uint8_t {
  Idle,
  Clear,    ///< the switch is already active: move off it against the search direction
  Search,   ///< at search velocity toward the switch (or the deceleration dog)
  BackOff,  ///< off the switch again, to approach it slowly
  Latch,    ///< at latch velocity until the edge (rising, or falling when latching away)
  Index,    ///< at latch velocity until the next encoder index mark
  Final,    ///< to the home position
  Done,
};

/// One joint's homing. The latch sets the joint's offset (machine = joint + offset) so that the
/// latched edge or index mark is at `switch_position`; the joint then moves to `position`.
/// Sequence per method (signs of the velocities give directions):
/// - Switch: [Clear] → Search → stop → (latch same way as search: BackOff → Latch on the rising
///   edge | latch the other way: Latch on the falling edge) → stop → Final;
/// - SwitchIndex: the same, and after the switch edge Index at latch velocity;
/// - Index: Index at latch velocity;
/// - DecelHome: [Clear] → Search until the dog → Latch at latch velocity until the home switch;
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
  /// Where the latch happened (joint feedback), for tests and logs.
  double latched_at() const noexcept { return latched_at_; }

 private:
  void latch(const HomeConfig& config, double joint_position, double& offset) noexcept;
  void after_switch_latch(const HomeConfig& config, AxisMover& mover) noexcept;
  void step(const HomeConfig& config, const HomingInputs& in, AxisMover& mover, double& offset) noexcept;
  bool trigger(const HomingInputs& in) const noexcept;

  HomingPhase phase_ = HomingPhase::Idle;
  bool stopping_ = false;          ///< waiting for the mover to settle before the next phase
  bool latch_on_release_ = false;  ///< Latch waits for the switch to release
  std::uint32_t index_count_ = 0;  ///< index count when Index began
  double latched_at_ = 0;
  double previous_feedback_ = 0;  ///< feedback of the last period, for the latch
  double offset_ = 0;             ///< the latched offset, for the final move
};

}  // namespace opencnc::control
