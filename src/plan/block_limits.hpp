// SPDX-License-Identifier: GPL-3.0-or-later
// Per-block speed cap, acceleration budget and jerk budget along the path from the per-axis limits.
#pragma once

#include "opencnc/plan/machine_limits.hpp"
#include "opencnc/traj/motion_block.hpp"

namespace opencnc::plan::detail {

/// What the limit computation needs besides the axis limits.
struct LimitParams {
  MachineLimits machine;
  double normal_share = 0.95;  ///< α: share of A_i the centripetal term may use
  double step_share = 0.5;     ///< η: share of J_i reserved where a curvature step is sampled
  double filter_s = 0;         ///< moving-average length T (0 = jerk not limited)
  double period_s = 1e-3;
};

/// The block may never go faster than `cap` along s, its acceleration along s stays within
/// ±`accel` and changes at most at `jerk` (s-units/s³, +∞ without jerk limits); together they
/// keep every axis within its velocity, acceleration and jerk limit. With jerk limits
/// accel ≤ jerk·T, so that the moving average of length T can always reverse the acceleration
/// (docs/planner.md, "Jerk").
struct RawLimits {
  double cap = 0;
  double accel = 0;
  double jerk = 0;
};

/// Limits of a path block whose speed will never be commanded above `v_commanded_max`; with
/// `jerk_scale` < 1 the axes' jerk limits count that much (next to a curvature step, which takes
/// the rest). Non-real-time.
RawLimits block_limits(const traj::MotionBlock& b, double v_commanded_max, const LimitParams& p,
                       double jerk_scale = 1.0) noexcept;

/// Per-axis largest |g'|, |g''|, |g'''| along a cubic or quintic Bézier block (its derivatives'
/// extrema). Non-real-time.
void derivative_bounds(const traj::MotionBlock& b, double d1[kAxisCount], double d2[kAxisCount],
                       double d3[kAxisCount]) noexcept;

/// Per-axis |Δg''| where `prev` ends and `next` starts: the step of curvature that makes the
/// acceleration jump by v²·|Δg''| there.
Pose curvature_step(const traj::MotionBlock& prev, const traj::MotionBlock& next) noexcept;

}  // namespace opencnc::plan::detail
