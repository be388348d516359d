// SPDX-License-Identifier: GPL-3.0-or-later
// AxisMover — the single-joint motion generator of jogs and homing moves: acceleration-limited,
// exact stops on a target, and the same moving average as the interpolator for jerk limits.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/traj/interpolator.hpp"

namespace opencnc::control {

/// A point moving along one joint. Every period it moves toward its goal — a speed, or a
/// position reached at rest — with |acceleration| ≤ A, and never passes a position goal (the
/// braking curve v² ≤ 2·A·d is kept exactly from period to period). With a jerk limit J the
/// output is the moving average of the last M = ⌈2A/(J·T)⌉ positions: its acceleration is an
/// average of accelerations (≤ A), its jerk at most 2A/(M·T) ≤ J, and it stays between the
/// positions averaged, so it never passes a goal either. Fixed-size; every method is real-time
/// safe and noexcept.
class AxisMover {
 public:
  /// Sets the limits; the mover is at rest at `position`. Any thread before use.
  void configure(double period_s, double max_acceleration, double max_jerk, double position) noexcept;
  /// At rest at `position` (forgets goal and history). Tick thread.
  void reset(double position) noexcept;

  /// Go to `target` at up to `speed` and stop there. Tick thread.
  void move_to(double target, double speed) noexcept;
  /// Run at `velocity` (signed) until told otherwise. Tick thread.
  void run_at(double velocity) noexcept;
  /// Decelerate to rest. Tick thread.
  void stop() noexcept { run_at(0); }

  /// Advances one period; returns the commanded position. Tick thread.
  double tick() noexcept;

  double position() const noexcept { return out_; }  ///< commanded (filtered)
  /// Where it is heading: the position goal, or (running at a speed) where the generator is now.
  double goal() const noexcept { return goal_ == Goal::Position ? goal_position_ : raw_; }
  double velocity() const noexcept { return vel_; }  ///< of the unfiltered generator
  /// At rest, goal reached and the average settled: the commanded position no longer changes.
  bool settled() const noexcept { return vel_ == 0 && still_ >= filter_ticks_ && !pending(); }
  /// Distance the generator needs to stop from its present speed. Tick thread.
  double stopping_distance() const noexcept;
  int filter_ticks() const noexcept { return filter_ticks_; }

 private:
  enum class Goal : std::uint8_t { Velocity, Position };
  bool pending() const noexcept {
    return goal_ == Goal::Position ? raw_ != goal_position_ : goal_velocity_ != 0;
  }
  void step_velocity() noexcept;
  void step_position() noexcept;
  double filter() noexcept;

  double period_ = 1e-3;
  double accel_ = 1;
  int filter_ticks_ = 1;
  Goal goal_ = Goal::Velocity;
  double goal_velocity_ = 0;
  double goal_position_ = 0;
  double goal_speed_ = 0;
  double raw_ = 0, vel_ = 0, out_ = 0;
  std::array<double, traj::kMaxFilterTicks> history_{};
  int head_ = 0;
  double sum_ = 0;
  int still_ = 0;  ///< consecutive periods without raw motion
};

}  // namespace opencnc::control
