// SPDX-License-Identifier: GPL-3.0-or-later
// TraceChecker — metrics of a commanded trajectory sampled every servo period: per-axis velocity,
// acceleration and jerk by finite differences, limit violations, contour error against the
// programmed path, path length and time.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>

#include "opencnc/canon/program.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/plan/machine_limits.hpp"

namespace opencnc::analysis {

/// Largest magnitudes seen on one axis (mm or degrees per s, s², s³).
struct AxisStats {
  double max_velocity = 0;
  double max_acceleration = 0;
  double max_jerk = 0;
};

/// The first limit violation, to say where to look.
struct Violation {
  double time_s = 0;
  int axis = 0;
  int derivative = 0;  ///< 1 velocity, 2 acceleration, 3 jerk
  double value = 0, limit = 0;
};

/// What `opencnc run` reports for a trajectory.
struct TraceReport {
  double machining_time_s = 0;      ///< samples × period
  double path_length_mm = 0;        ///< sum of XYZ (and UVW) distances between samples
  double max_contour_error_mm = 0;  ///< largest distance of a sample to the programmed path
  double contour_error_time_s = 0;  ///< when it happened
  /// The other side of the contour: the largest distance from a programmed move's end point (a
  /// corner the path may round off) to the commanded path, the path between two samples taken as
  /// the circular arc through them and the sample before. Over the end points the trace has passed
  /// (a hairpin skipped by a blend between the moves' middles shows here, not in
  /// max_contour_error_mm).
  double max_corner_miss_mm = 0;
  canon::SegmentId corner_miss_segment = 0;  ///< the move whose end point it is
  std::array<AxisStats, kAxisCount> axes{};
  std::uint64_t limit_violations = 0;  ///< samples × axes × derivatives above a limit
  Violation first_violation{};
  std::uint64_t samples = 0;

  /// One line per metric, for logs and test failure messages.
  std::string summary() const;
};

/// Accumulates samples and computes a TraceReport. Finite differences are backward, one servo
/// period apart: v = (x₀ − x₁)/T, a = (x₀ − 2x₁ + x₂)/T², j = (x₀ − 3x₁ + 3x₂ − x₃)/T³; before the
/// first sample the machine is taken to be at rest there. A value counts as a violation when it
/// exceeds the limit by more than `relative_tolerance` (jerk only where a jerk limit is set).
/// The contour error of a sample is its distance to the nearest programmed move within one move
/// of the segments the sample's block covers; the corner miss of a move is the distance from its
/// end point to the nearest chord between two samples on the blocks around it. Non-real-time; one checker per
/// run.
class TraceChecker {
 public:
  TraceChecker(const canon::Program& program, const plan::MachineLimits& limits, double period_s,
               double relative_tolerance = 1e-6);
  /// Without a program yet (set_program()): no contour error until there is one.
  TraceChecker(const plan::MachineLimits& limits, double period_s, double relative_tolerance = 1e-6);

  /// The program the next samples' segment ids refer to (a stream's window, a new leg of a run;
  /// null: none). The moves within one of the samples' segments must still be held.
  void set_program(const canon::Program* program) noexcept {
    program_ = program;
    nearest_ = 0;
    corners_.clear();  // end points of the old program not yet passed: not measured
  }
  const canon::Program* program() const noexcept { return program_; }

  /// Where the machine rests before the first sample (the origin unless said). Before add().
  void start_at(const Pose& position) {
    past_.fill(position);
    jerk_unknown_ = false;
  }
  /// The two samples before the first one, newest first, when the trajectory was already moving.
  /// The sample before them is unknown, so the first sample's jerk (a third difference) is not
  /// measured; its velocity and acceleration are. Before add().
  void start_moving(const Pose& newest, const Pose& previous) {
    past_ = {newest, previous, previous};
    jerk_unknown_ = true;
  }
  /// The acceleration and jerk limits of the next samples, times `scale` (≥ 1: a power-fail stop
  /// short of energy brakes harder than planned, up to the axes' peak deceleration).
  void set_acceleration_scale(double scale) noexcept { accel_scale_ = scale < 1 ? 1.0 : scale; }
  /// One commanded sample; `first`..`last` are the segment ids of the block it lies on.
  void add(const Pose& position, canon::SegmentId first, canon::SegmentId last);
  /// The metrics so far.
  const TraceReport& report() const noexcept { return report_; }

  /// Distance from `p` (linear axes) to programmed move `id`. Non-real-time.
  double distance_to_move(canon::SegmentId id, const Pose& p) const;

 private:
  void check_limits(const Pose& x);
  double box_distance(canon::SegmentId id, const Pose& p) const;

  const canon::Program* program_;
  plan::MachineLimits limits_;
  double period_s_;
  double tolerance_;
  double accel_scale_ = 1;        ///< set_acceleration_scale
  void track_corners(const Pose& position, canon::SegmentId first, canon::SegmentId last);

  std::array<Pose, 3> past_{};    ///< the three previous samples, newest first
  /// Distance so far from the end point of moves corner_base_, corner_base_ + 1, … to the path.
  std::deque<double> corners_;
  canon::SegmentId corner_base_ = 0;
  bool jerk_unknown_ = false;     ///< the oldest of them is not known (start_moving)
  canon::SegmentId nearest_ = 0;  ///< the move nearest to the last sample
  TraceReport report_;
};

}  // namespace opencnc::analysis
