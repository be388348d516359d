// SPDX-License-Identifier: GPL-3.0-or-later
// Fanuc coordinate transforms as plain functions over TransformState: programmable mirror
// image (G51.1), scaling (G51) and coordinate rotation (G68), in Fanuc's order.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/canon/types.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

/// Which stages of the transform to apply: stages are applied in this order.
enum class TransformStage : std::uint8_t { Mirror = 1, Scale = 2, Rotate = 4, All = 7 };

/// `p` (program coordinates) through the active stages of `t` up to and including `last`:
/// mirror each flagged axis about its line, scale X Y Z about the centre, rotate in the
/// rotation plane about the centre. Any thread; real-time safe.
Pose transform_point(const TransformState& t, const Pose& p, TransformStage last = TransformStage::All) noexcept;

enum class ArcTransform : std::uint8_t {
  Ok,
  NonUniformScale,   ///< the plane's two axes scale differently: the arc would be an ellipse
  OtherPlane,        ///< rotation in another plane than the arc's
};

/// Transforms an arc in place: end point and centre like points, the turn direction reversed
/// when the transform mirrors the arc's plane (an odd number of its two axes mirrored or
/// scaled by a negative factor). Leaves the arc unchanged unless the result is Ok.
/// Any thread; real-time safe.
ArcTransform transform_arc(const TransformState& t, canon::ArcFeed& arc) noexcept;

/// sin and cos of an angle in degrees, exact at multiples of 90 degrees (so that a quarter
/// turn does not leave 6e-17 residues in coordinates).
void sin_cos_deg(double degrees, double& s, double& c) noexcept;

}  // namespace opencnc::gcode
