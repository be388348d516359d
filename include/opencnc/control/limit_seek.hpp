// SPDX-License-Identifier: GPL-3.0-or-later
// LimitSeek — one joint's move that seeks a limit switch (what an EDM setter uses to find the end
// of the travel): at speed to the switch, off it and onto it again slowly, then off onto its free side.
#pragma once

#include <cstdint>

#include "opencnc/control/axis_mover.hpp"
#include "opencnc/control/servo_config.hpp"

namespace opencnc::control {

enum class SeekPhase : std::uint8_t {
  Idle,
  Search,   ///< at seek velocity toward the switch
  Release,  ///< stopped within the overtravel; back off the switch at latch velocity
  Latch,    ///< onto the switch again at latch velocity: this trip is the one reported
  Clear,    ///< off the switch at latch velocity, then back_off further (within the soft limits)
  Done,     ///< at rest on the free side; tripped_at() is where the switch tripped
  Failed,   ///< a homed joint went its soft limit + overtravel without the switch tripping
};

/// Name of a phase for status and logs ("search", "latch", …). Any thread; real-time safe.
const char* to_string(SeekPhase p) noexcept;

/// One joint's seek, driving its AxisMover (joint coordinates). Each phase that changes direction
/// first brings the mover to rest. The trip is latched between the last two feedbacks, as homing
/// latches an edge. Real-time safe, noexcept, fixed-size.
class LimitSeek {
 public:
  /// Begins a seek toward `direction` (+1 / −1). `search_end`: how far the search may go (joint
  /// coordinates; ±infinity on a joint that is not homed). `free_end`: the furthest the joint
  /// may rest afterwards (its soft limit on that side once homed, else ±infinity). Tick thread.
  void start(const LimitSeekConfig& config, int direction, double feedback, double search_end,
             double free_end, AxisMover& mover) noexcept;
  /// One period: `feedback` (joint coordinates) and the state of the switch sought. Tick thread.
  void tick(const LimitSeekConfig& config, double feedback, bool switch_on, AxisMover& mover) noexcept;
  /// Stops the seek where it is (the mover is told to stop). Tick thread.
  void cancel(AxisMover& mover) noexcept;

  SeekPhase phase() const noexcept { return phase_; }
  bool active() const noexcept {
    return phase_ != SeekPhase::Idle && phase_ != SeekPhase::Done && phase_ != SeekPhase::Failed;
  }
  /// Search or Latch: the switch tripping is what the seek waits for, not a fault.
  bool expects_trip() const noexcept { return phase_ == SeekPhase::Search || phase_ == SeekPhase::Latch; }
  int direction() const noexcept { return direction_; }
  /// Where the switch tripped at latch velocity (joint coordinates); valid once Done.
  double tripped_at() const noexcept { return tripped_at_; }
  /// Where the switch released on the way off it (joint coordinates).
  double released_at() const noexcept { return released_at_; }

 private:
  void step(const LimitSeekConfig& c, double feedback, bool switch_on, AxisMover& m) noexcept;

  SeekPhase phase_ = SeekPhase::Idle;
  bool stopping_ = false;  ///< waiting for the mover to come to rest before the phase's move
  bool moving_ = false;    ///< the phase's move has been given to the mover
  bool backing_ = false;   ///< Clear: off the switch, the move back_off further is under way
  int direction_ = 1;
  double search_end_ = 0, free_end_ = 0;
  double previous_feedback_ = 0;
  double tripped_at_ = 0, released_at_ = 0;
};

}  // namespace opencnc::control
