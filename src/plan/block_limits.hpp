// SPDX-License-Identifier: GPL-3.0-or-later
// Per-block speed cap and acceleration budget along the path from the per-axis limits.
#pragma once

#include "opencnc/plan/machine_limits.hpp"
#include "opencnc/traj/motion_block.hpp"

namespace opencnc::plan::detail {

/// What the limit computation needs besides the axis limits.
struct LimitParams {
  MachineLimits machine;
  double normal_share = 0.95;  ///< α: share of A_i the centripetal term may use
  double step_share = 0.5;     ///< η: share of J_i reserved for curvature steps
  double filter_s = 0;         ///< moving-average length T (0 = jerk not limited)
  double period_s = 1e-3;
};

/// The block may never go faster than `cap` along s, and its acceleration along s stays within
/// ±`accel`; together they keep every axis within its velocity, acceleration and (with the
/// moving average) jerk limit.
struct RawLimits {
  double cap = 0;
  double accel = 0;
};

/// Limits of a path block whose speed will never be commanded above `v_commanded_max`.
RawLimits block_limits(const traj::MotionBlock& b, double v_commanded_max, const LimitParams& p) noexcept;

/// Per-axis |Δg''| where `prev` ends and `next` starts: the step of curvature that makes the
/// acceleration jump by v²·|Δg''| there.
Pose curvature_step(const traj::MotionBlock& prev, const traj::MotionBlock& next) noexcept;

}  // namespace opencnc::plan::detail
