// SPDX-License-Identifier: GPL-3.0-or-later
// Interpolator — the real-time half of the trajectory: every servo period it advances along the
// queued motion blocks and returns the commanded position of every axis.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/core/axes.hpp"
#include "opencnc/traj/block_queue.hpp"

namespace opencnc::traj {

/// Longest moving-average filter (servo periods) the interpolator supports.
inline constexpr int kMaxFilterTicks = 2048;
/// Most marker events one tick reports; the rest follow in the next ticks.
inline constexpr int kMaxTickEvents = 16;

/// Fixed at start-up; must match the planner that fills the queue (plan::Planner gives it).
struct InterpolatorConfig {
  double period_s = 1e-3;          ///< servo period
  int filter_ticks = 1;            ///< moving-average length on s in periods (1 = none: no jerk limit)
  double max_feed_override = 2.0;  ///< feed override inputs are clamped to [0, this]
  /// The largest acceleration budget any block may have (s-units/s²): bounds the braking a
  /// jerk-limited generator loses while it may not yet turn its acceleration round.
  double max_path_accel = 0;
  /// The largest speed along s any block may have (s-units/s): how far such a coast may reach.
  double max_path_speed = 0;
};

/// Inputs sampled once per tick. Levels stay as long as the condition holds; `cycle_start`,
/// `abort` and `sync_done` are read as edges (true for one tick is enough).
struct TickInput {
  double feed_override = 1.0;    ///< 0 … max_feed_override (1 = 100 %)
  double rapid_override = 1.0;   ///< 0 … 1
  bool feed_hold = false;        ///< decelerate on the path and stay (level)
  bool cycle_start = false;      ///< continue after M0, M1 or a single-block stop (edge)
  bool abort = false;            ///< controlled stop on the path, then drop the queue (edge)
  bool single_block = false;     ///< stop at the end of every programmed move (level)
  bool optional_stop = false;    ///< M1 waits for cycle start while this is on (level)
  bool sync_done = false;        ///< the controller finished a Sync marker's action (edge)
  bool spindle_at_speed = true;  ///< spindle at its commanded speed (for SpindleWait markers)
  double spindle_revs = 0;       ///< spindle encoder position, revolutions (G33)
  double spindle_rev_s = 0;      ///< spindle speed, revolutions per second (G95, G33)
  /// While aborting, the path brakes at up to this many times each block's acceleration budget
  /// (≥ 1; the servo raises it when the drives' DC link would not last the normal stop). Level.
  double abort_decel_scale = 1.0;
  /// The drives a kWaitInPosition marker waits for stand in position (the servo decides). Level.
  bool in_position = true;
};

/// What the interpolator is doing.
enum class RunState : std::uint8_t {
  Idle,               ///< nothing queued yet
  Running,            ///< moving, or about to
  Holding,            ///< decelerating for a feed hold
  Held,               ///< stopped on the path by a feed hold
  Starved,            ///< stopped at the end of the queued blocks; the program goes on
  Dwelling,           ///< G4
  WaitingCycleStart,  ///< M0, M1 with optional stop on, or a single-block stop
  WaitingSpindle,     ///< spindle not yet at speed
  WaitingSync,        ///< waiting for the controller (tool change, M66, ...)
  Aborting,           ///< decelerating after an abort
  Aborted,            ///< stopped and queue dropped; restart() to run again
  Finished,           ///< program end reached and settled
};

/// A marker the commanded position reached in this tick.
struct TickEvent {
  std::uint64_t seq = 0;  ///< block seq of the marker
  MarkerKind kind = MarkerKind::None;
  std::uint32_t action = 0;  ///< index into canon::Program::actions()
};

/// Everything one tick produces. Plain data.
struct TickOutput {
  Pose position{};           ///< commanded position of every axis (mm, degrees)
  double path_velocity = 0;  ///< ds/dt of the commanded position (s-units/s)
  /// The acceleration budget of the block the generator is in (s-units/s², 0 when none): the
  /// normal deceleration a stop on the path brakes at (the servo's power-fail stop estimates by it).
  double path_acceleration = 0;
  RunState state = RunState::Idle;
  std::uint64_t block_seq = 0;      ///< block at the commanded position
  std::uint64_t segment = 0;        ///< canon segment id of the move being executed
  std::uint64_t segment_first = 0;  ///< the programmed moves the block stands for (merges, blends)
  std::uint64_t segment_last = 0;
  std::uint32_t line = 0;     ///< its source line
  std::uint32_t context = 0;  ///< its SourceMap context
  double block_offset = 0;    ///< s within that block
  /// Path length from the start of `segment` to the commanded position (the block's
  /// segment_offset + block_offset): where inside its move the machine is.
  double segment_offset = 0;
  int event_count = 0;
  std::array<TickEvent, kMaxTickEvents> events{};
  bool spindle_synced = false;  ///< following the spindle (G33) with a constant lag
  bool sync_lost = false;       ///< a limit forced the motion off the spindle during this run
  /// Rigid tap (G33.1): the spindle must turn the other way, at `tap_speed_scale` times its speed
  /// (from the bottom of the tap until it is back at its start). A level, for the spindle output.
  bool tap_reverse = false;
  double tap_speed_scale = 1;
  /// At a kWaitInPosition marker, waiting for TickInput::in_position (state Dwelling).
  bool waiting_in_position = false;
};

/// Consumes motion blocks and computes the commanded position every servo period.
///
/// Along the path parameter s it runs a one-dimensional generator with piecewise-constant
/// acceleration (exact within each period): speed ≤ the block's cap × override, |acceleration|
/// ≤ the block's budget, and braking curves v² ≤ v_q² + C(q) − C(s) toward the next junction,
/// the end of the queued data, lower nominal speeds further on and dynamic stops (feed hold,
/// single block). When jerk is limited, a moving average of length filter_ticks turns that
/// trapezoidal profile into an S-curve; the planner has widened the limits accordingly.
/// See docs/planner.md. All methods are for the tick thread and real-time safe; nothing
/// allocates after construction.
class Interpolator {
 public:
  /// `queue` must outlive the interpolator. `start` is the machine position.
  Interpolator(BlockQueue& queue, const InterpolatorConfig& config, const Pose& start) noexcept;

  /// Advances by one servo period. Tick thread; real-time safe, noexcept, no allocation.
  void tick(const TickInput& in, TickOutput& out) noexcept;

  /// Forgets all motion state and starts again from `start` (after Finished or Aborted, once the
  /// owner has reset the queue). Tick thread; real-time safe.
  void restart(const Pose& start) noexcept;

  /// Tick thread; real-time safe.
  const InterpolatorConfig& config() const noexcept { return config_; }
  /// Number of ticks since construction or restart(). Tick thread; real-time safe.
  std::uint64_t ticks() const noexcept { return ticks_; }

 private:
  /// This period's bounds from the jerk budget where the commanded position is (see turn_).
  struct Turn {
    bool active = false;
    double delta = 0;   ///< the acceleration may differ from T earlier by at most this
    double lo_old = 0;  ///< the period T earlier: highest and lowest acceleration
    double hi_old = 0;
    double coast_hist = 0;  ///< time after this period before full braking is allowed (history)
    double coast_full = 0;  ///< the same if this period accelerates
    double coast_accel_hist = 0;  ///< the largest budget either coast may cross
    double coast_accel_full = 0;
  };
  void handle_commands(const TickInput& in) noexcept;
  double advance_unfiltered(const TickInput& in) noexcept;
  Turn turn_bounds(const TickInput& in) noexcept;
  void step_piece(const TickInput& in, const MotionBlock& b, std::size_t index, const Turn& turn, double& tau,
                  double& integral) noexcept;
  void commit_single_block_stop(std::size_t available) noexcept;
  double target_speed(const TickInput& in, const MotionBlock& b) const noexcept;
  double filter(double integral) noexcept;
  void advance_filtered(TickOutput& out) noexcept;
  void update_waiting(const TickInput& in) noexcept;
  void release_marker() noexcept;
  void pop_and_rebase() noexcept;
  void fill_output(TickOutput& out, double s_prev) noexcept;
  void write_shown(TickOutput& out) const noexcept;
  void update_sync(const TickInput& in) noexcept;
  double sync_acceleration(const MotionBlock& b, double tau) noexcept;
  // rigid_tap.cpp
  bool run_tap(const TickInput& in) noexcept;
  bool start_tap(const TickInput& in) noexcept;
  void follow_spindle(const TickInput& in, const MotionBlock& b) noexcept;
  void place_tap(const MotionBlock& b) noexcept;
  void finish_tap() noexcept;
  void show_tap(TickOutput& out) noexcept;
  std::size_t index_of(std::uint64_t seq) const noexcept {
    return static_cast<std::size_t>(seq - queue_->popped());
  }

  BlockQueue* queue_;
  InterpolatorConfig config_;
  Pose position_{};
  std::uint64_t ticks_ = 0;
  RunState state_ = RunState::Idle;
  bool started_ = false;

  // Unfiltered generator: block, global s of its start, s and ds/dt.
  std::uint64_t u_seq_ = 0;
  double u_start_ = 0, s_u_ = 0, v_u_ = 0;
  int still_ticks_ = 0;  ///< consecutive ticks without unfiltered motion
  // Filtered (commanded) position: block and global s of its start, s.
  std::uint64_t f_seq_ = 0, report_seq_ = 0;
  double f_start_ = 0, s_f_ = 0;
  // Moving-average history: ∫ s dt over each of the last filter_ticks periods.
  std::array<double, kMaxFilterTicks> history_{};
  int history_pos_ = 0;
  // The generator's lowest and highest acceleration in each of those periods (0 counts: rest).
  // The average's jerk is (a(t) − a(t − T))/T, so keeping every acceleration within the block's
  // jerk budget × T of the one a window earlier keeps the commanded jerk within it.
  std::array<double, kMaxFilterTicks> acc_lo_{}, acc_hi_{};
  double period_lo_ = 0, period_hi_ = 0;  ///< this period's
  // This tick: the blocks from the generator's as far as a coast before braking can reach
  // (turn_bounds): how many, from which.
  static constexpr int kCoastScan = 256;
  int coast_count_ = 0;
  std::uint64_t coast_from_ = 0;
  double full_end_ = -1e300;  ///< this tick: where a coast after accelerating may reach (global s)
  double commit_end_ =
      -1e300;  ///< where the coasts the accelerating periods in the window committed to may reach

  // Operator state.
  bool hold_ = false, aborting_ = false;
  std::uint64_t released_seq_ = kNoBlock;  ///< stop marker already dealt with
  std::uint64_t stop_seq_ = kNoBlock;      ///< committed single-block stop (start of that block)
  std::uint64_t step_from_seq_ = 0;        ///< single-block stops only after this block
  std::uint64_t dwell_ticks_left_ = 0;
  bool waiting_ = false;  ///< at a stop marker, action not finished
  bool waiting_in_position_ = false;  ///< this tick, at a kWaitInPosition marker not yet in position

  // Spindle-synchronised motion (G33): wait for the index, catch up, then follow the encoder.
  enum class Sync : std::uint8_t { Off, WaitIndex, CatchUp, Locked };
  Sync sync_ = Sync::Off;
  double sync_target_ = 0;  ///< s the spindle position asks for (global s)
  double sync_lag_ = 0;     ///< constant distance behind it once locked
  double prev_revs_ = 0;
  double sync_rev_s_ = 0;  ///< spindle speed of this tick
  bool sync_lost_ = false;

  // Rigid tapping (G33.1): a generator of its own, signed along the tap's line, that follows the
  // spindle in, through its reversal, out and through its restoring, then places the tap back
  // on its start (LinuxCNC's TAPPING, REVERSING, RETRACTION, FINAL_REVERSAL, FINAL_PLACEMENT).
  enum class Tap : std::uint8_t { Off, WaitIndex, In, Reversing, Out, Restoring, Placing };
  Tap tap_ = Tap::Off;
  bool tap_locked_ = false;   ///< following the spindle with a constant lag
  bool tap_reverse_ = false;  ///< output: the spindle turns the other way
  double tap_depth_ = 0;      ///< along the tap's line from its start (in = positive)
  double tap_v_ = 0;          ///< d(tap_depth_)/dt
  double tap_lag_ = 0;        ///< constant distance behind the spindle once locked
  double tap_dir_ = 1;        ///< +1 when the spindle position rises as the tap goes in
  double tap_rev0_ = 0;       ///< spindle position of the index the tap started at
  double tap_revs_ = 0;       ///< spindle position of the previous tick

  struct Shown {  // the block at the commanded position, kept once it has been popped
    std::uint64_t seq = 0, segment = 0, segment_first = 0, segment_last = 0;
    std::uint32_t line = 0, context = 0;
    double offset = 0;
    double segment_offset = 0;  ///< the block's own segment_offset
  } shown_;
};

}  // namespace opencnc::traj
