// SPDX-License-Identifier: GPL-3.0-or-later
// plan::Planner — turns a canon::Program into motion blocks for the servo tick: geometry with
// corner blends, per-block speed and acceleration limits from the axis limits, look-ahead.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "opencnc/canon/program.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/plan/machine_limits.hpp"
#include "opencnc/traj/block_queue.hpp"
#include "opencnc/traj/interpolator.hpp"

namespace opencnc::plan {

/// Checks move `id` of `program` against the machine as start() checks every move: finite
/// coordinates, configured axes, a positive feed, a valid arc, a supported kind. Errors go to
/// `diags` with the move's file and line. Non-real-time.
bool check_move(const canon::Program& program, canon::SegmentId id, const MachineLimits& limits,
                Diagnostics& diags);

/// Length in seconds of the moving average on s that meets the jerk limits (docs/planner.md,
/// "Jerk"): the largest A/J of the axes with a jerk limit, in whole servo periods; 0 without jerk
/// limits. The commanded position trails the path generator by up to half of it, so a feed hold
/// taken at speed v travels v·T/2 beyond the generator's braking distance. Any thread.
double jerk_filter_s(const MachineLimits& limits, double servo_period_s) noexcept;

/// Planner settings (the machine profile's [trajectory] part).
struct PlannerConfig {
  double servo_period_s = 1e-3;        ///< must equal the interpolator's period
  std::size_t lookahead_moves = 1000;  ///< most programmed moves held ahead of the queue (≥ 2)
  double max_feed_override = 2.0;      ///< the largest feed override the operator can set
  /// Largest share of an axis's acceleration that the centripetal part may take on arcs and
  /// blends; the rest stays available along the path. In (0, 1).
  double normal_accel_share = 0.95;
  /// With jerk limits: share of each axis's jerk reserved where a curvature step is left (a
  /// line meeting an arc tangentially under G61, sampled at the servo period). In (0, 1).
  double jerk_step_share = 0.5;
  /// With jerk limits, runs of short feed lines are replaced by one curvature-continuous curve
  /// within the G64 P tolerance before G64 Q may merge what is left (docs/planner.md, "Runs of
  /// short moves"). Without jerk limits the moves keep their circular blends.
  bool smooth_short_moves = true;
};

enum class PlanStatus : std::uint8_t {
  Working,   ///< more blocks to come: call pump() again
  Finished,  ///< every block of the program is in the queue
  Failed,    ///< the program or the configuration was rejected: see diagnostics()
};

/// Counters of a planning run, for reports and tests.
struct PlanStats {
  std::uint64_t moves = 0;         ///< programmed moves read
  std::uint64_t merged_moves = 0;  ///< moves folded into a previous line by G64 Q
  std::uint64_t blends = 0;        ///< corners replaced by a blend curve
  std::uint64_t smoothed_runs = 0;  ///< runs of short moves replaced by one fitted curve
  std::uint64_t blocks = 0;        ///< blocks published (path blocks and markers)
};

/// The non-real-time half of the trajectory. One planner per run; not thread-safe; the program
/// must outlive the run. See docs/planner.md for the algorithm.
class Planner {
 public:
  /// Checks `limits` and `config`; problems end up in diagnostics() and make start() fail.
  /// Non-real-time.
  explicit Planner(const MachineLimits& limits, const PlannerConfig& config = {});
  ~Planner();
  Planner(const Planner&) = delete;
  Planner& operator=(const Planner&) = delete;

  /// The settings the interpolator must use with this planner's blocks. Any thread.
  traj::InterpolatorConfig interpolator_config() const noexcept;

  /// Checks the whole program, then prepares to plan it. On any error nothing is planned,
  /// diagnostics() holds `file:line: message` entries and false is returned. Non-real-time.
  bool start(const canon::Program& program);

  // --- streaming: the program grows while it is planned (the controller's execution) -------
  /// Prepares to plan `program` as it grows. Nothing is read until stream_readable(); moves are
  /// not checked here (check_move() them before they become readable). Non-real-time.
  bool start_stream(const canon::Program& program);
  /// Moves [0, moves) of the stream are checked and may be planned (with the actions before
  /// and right after them). Non-real-time.
  void stream_readable(std::size_t moves) noexcept;
  /// What is readable ends at a sync point (the interpreter waits for the machine there): plan
  /// it to a stop and publish all of it; reading goes on once it is published. Non-real-time.
  void stream_flush() noexcept;
  /// No more moves will come: the end of what is readable is the program's end. Non-real-time.
  void stream_end() noexcept;
  /// Streaming: every readable move has been read and the look-ahead could use more: the
  /// moment to read further in the program. Non-real-time.
  bool wants_input() const noexcept;
  /// Streaming: the first move and action the planner may still read (the stream may free
  /// what lies before them). Non-real-time.
  std::size_t oldest_move_needed() const noexcept;
  std::size_t oldest_action_needed() const noexcept;

  /// Plans ahead and pushes every block that is final into `queue`, as far as it has room.
  /// The queue's block numbering continues from its pushed() count. Non-real-time.
  PlanStatus pump(traj::BlockQueue& queue);

  /// Problems found so far. Non-real-time.
  const Diagnostics& diagnostics() const noexcept;
  /// Counters of the current run. Non-real-time.
  const PlanStats& stats() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace opencnc::plan
