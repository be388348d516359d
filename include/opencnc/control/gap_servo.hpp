// SPDX-License-Identifier: GPL-3.0-or-later
// GapServo — the sinker EDM's stage of the tick: a signed speed along the programmed path from the
// gap voltage (back along the path already machined through a memory of it), the jump and the
// orbit as offsets. Fixed-size plain data; nothing allocates (docs/edm.md).
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/control/edm_adaptive.hpp"
#include "opencnc/control/edm_status.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/machine/edm.hpp"
#include "opencnc/machine/machine_io.hpp"

namespace opencnc::control {

using machine::EdmCondition;
using machine::EdmConfig;
using machine::JumpMode;
using machine::OrbitKind;

/// The path the interpolator has put out, as points at least `spacing` apart (and one at every
/// new block, so corners are points), with their path length s; the live head is the last point.
/// Lets the electrode stand anywhere behind the head, on the path, across block boundaries.
class PathMemory {
 public:
  static constexpr int kPoints = machine::kEdmPathPoints;

  /// Forgets everything: the path starts at `at` (s = 0). Servo thread; real-time safe.
  void reset(const Pose& at) noexcept;
  /// The head moved to `head`: kept as a point once `spacing` from the last one or when `corner`
  /// (a new block). Servo thread; real-time safe.
  void advance(const Pose& head, double spacing, bool corner) noexcept;
  /// The point at path length `s`, clamped to what is remembered. Any thread; real-time safe.
  Pose at(double s) const noexcept;
  double head_s() const noexcept { return head_s_; }
  /// The oldest path length still remembered.
  double tail_s() const noexcept;

 private:
  std::size_t slot(int i) const noexcept { return static_cast<std::size_t>((first_ + i) % kPoints); }
  std::array<Pose, kPoints> points_{};
  std::array<double, kPoints> s_{};
  int first_ = 0, count_ = 0;
  Pose head_{};
  double head_s_ = 0;
};

/// What the tick tells the gap servo each period.
struct GapInputs {
  bool hold = false;       ///< feed hold, abort or a stop: hold the electrode, generator off
  Pose head{};             ///< the interpolator's commanded position (machine coordinates)
  bool new_block = false;  ///< the head entered a new block this period
  double head_feed = 0;    ///< nominal speed of the head's block (s-units/s); 0: a marker
  bool rapid = false;      ///< the head's block is a rapid (G0): nothing to machine
  double gap_voltage_v = 0;
  machine::GapState gap_state = machine::GapState::Open;
};

/// The EDM stage. Servo thread only; every member is real-time safe and allocates nothing.
class GapServo {
 public:
  /// `jump_accel_mm_s2` bounds the jump's and the servo's acceleration (the tool axis' limit).
  void configure(const EdmConfig& config, double period_s, double jump_accel_mm_s2) noexcept;
  bool enabled() const noexcept { return config_.enabled; }

  /// A run starts at `at`: the path memory starts there, the generator is off.
  void begin_run(const Pose& at) noexcept;
  /// M180 P<n> (select condition n, generator on) or M181 (generator off). False: no such
  /// condition (the generator goes off). `q` > 0: the burn's orbit radius (M180's Q, at most
  /// the condition's). Under a condition with the finishing cycle the code waits
  /// (the interpolator with it) until the orbit is full at the path's end and has turned there.
  bool apply_code(int code, double p, double q = 0) noexcept;
  /// One period: returns where the electrode shall be (the head, or behind it, plus offsets).
  Pose step(const GapInputs& in) noexcept;
  /// The factor the interpolator's feed override is multiplied by (0 while the electrode is
  /// behind the head or the gap wants it back).
  double feed_scale() const noexcept { return feed_scale_; }
  /// The electrode stands behind the head or is lifted: the interpolator waits, rapids included.
  bool head_waits() const noexcept {
    return finishing_ || jump_ != Jump::Idle || s_ < memory_.head_s() - 1e-9;
  }
  /// The generator's pulses on, and its settings.
  bool generator_on() const noexcept { return status_.generator; }
  machine::GeneratorOutputs generator() const noexcept;
  const EdmStatus& status() const noexcept { return status_; }
  /// The active condition (number 0: none), with the settings adaptive control has moved.
  const EdmCondition& condition() const noexcept { return cond_; }
  /// The gap has been shorted for longer than the condition's short_timeout_s: the machine must
  /// stop (the tick faults).
  bool short_timed_out() const noexcept {
    return status_.on && cond_.short_timeout_s > 0 && status_.short_s >= cond_.short_timeout_s;
  }
  /// The finishing cycle has held the burn's end for the condition's finish_timeout_s without
  /// the orbit reaching its size and turning there: the machine must stop (the tick faults).
  bool finish_timed_out() const noexcept {
    return finishing_ && cond_.finish_timeout_s > 0 && finish_elapsed_s_ >= cond_.finish_timeout_s;
  }
  /// The orbit's radius now (the size the finishing cycle has reached).
  double orbit_radius_mm() const noexcept { return radius_; }
  /// This period backing off reached the end of the path memory while the servo wanted to go on.
  bool reached_retract_limit() const noexcept { return reached_retract_limit_; }

 private:
  bool select(int code, double p, double q) noexcept;
  double servo_speed(const GapInputs& in, bool brake) noexcept;
  void run_finish(const GapInputs& in, bool due) noexcept;
  void run_lateral(const GapInputs& in, double target) noexcept;
  void adapt(const GapInputs& in) noexcept;
  bool jump_due() const noexcept;
  void move_electrode(double v, const GapInputs& in) noexcept;
  void run_jump(bool may_start) noexcept;
  void run_orbit(const GapInputs& in) noexcept;
  void follow_gap(bool shorted) noexcept;
  void turn() noexcept;
  void return_offsets() noexcept;
  void catch_up() noexcept;
  static double approach(double x, double target, double& v, double v_max, double a_max, double dt) noexcept;

  EdmConfig config_{};
  double period_s_ = 1e-3;
  double accel_ = 1000;
  EdmCondition cond_{};
  PathMemory memory_;
  double s_ = 0;        ///< the electrode's path length on the memory
  double v_ = 0;        ///< its signed speed along the path
  double catch_v_ = 0;  ///< its speed walking up to the head with nothing to machine
  double law_mm_s_ = 0;  ///< the law's speed target this period (before the acceleration limit)
  double feed_scale_ = 1;
  bool reached_retract_limit_ = false;
  bool pressing_limit_ = false;  ///< backing off against the end of the memory (until it lets go)
  EdmStatus status_{};
  // Jump: axis lift or path backlog, its phase and the machining time since the last one.
  enum class Jump : std::uint8_t { Idle, Up, Down };
  Jump jump_ = Jump::Idle;
  double lift_ = 0, lift_v_ = 0;  ///< axis jump: lift along the tool axis and its speed
  double jump_from_s_ = 0;        ///< path jump: where the electrode left the path
  double machining_s_ = 0;
  // Orbit: phase (turns, 0 … 1), the radius now and the turns completed.
  double phase_ = 0, radius_ = 0;
  double orbit_rate_ = 1;  ///< the share of its period's speed the orbit turns at (the lateral servo)
  int turns_ = 0;
  OrbitKind shape_ = OrbitKind::None;  ///< the shape drawn now (a new condition's waits for the centre)
  double draw_period_s_ = 1, draw_rate_ = 0;  ///< its period and its radial rate (mm/s)
  double orbit_[2] = {0, 0};
  // The finishing cycle: the code it holds back, the radial speed and the burnt turn at full size.
  bool finishing_ = false;
  int pending_code_ = 0;
  double pending_p_ = 0, pending_q_ = 0;
  double lateral_v_ = 0;
  double full_turn_ = 0;  ///< turns burnt at the full radius (1: done)
  double finish_s_ = 0;   ///< the path length where the burn's path ended
  double finish_elapsed_s_ = 0;  ///< machining time since the cycle began (its time limit)
  // Adaptive control: the condition's own settings and bounds (cond_ holds those in force).
  EdmCondition base_{};
  EdmAdaptive adaptive_;
};

/// The orbit's offset at phase `phase` (turns) and radius `r` for `kind`. Any thread; real-time safe.
void orbit_offset(OrbitKind kind, double phase, double r, double out[2]) noexcept;

}  // namespace opencnc::control
