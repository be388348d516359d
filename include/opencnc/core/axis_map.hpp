// SPDX-License-Identifier: GPL-3.0-or-later
// Axis exchange: which machine axis each program axis letter drives ("X=Y,Y=X").
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "opencnc/core/axes.hpp"

namespace opencnc {

/// Program axis letter (index) → machine axis.
using AxisMap = std::array<Axis, kAxisCount>;

/// The identity map. Any thread; real-time safe.
constexpr AxisMap identity_axis_map() noexcept {
  return {Axis::X, Axis::Y, Axis::Z, Axis::A, Axis::B, Axis::C, Axis::U, Axis::V, Axis::W};
}

/// Reads "X=Y,Y=X" (program letter = machine axis, comma-separated, any case, blanks allowed)
/// into `map`, starting from the identity; letters not named keep their own axis. The result
/// must be a one-to-one exchange of linear axes with linear axes and rotary with rotary.
/// Returns a message saying what is wrong, or an empty string. Non-real-time.
std::string parse_axis_map(std::string_view text, AxisMap& map);

/// The map written back as text ("X=Y,Y=X"; empty for the identity). Non-real-time.
std::string format_axis_map(const AxisMap& map);

}  // namespace opencnc
