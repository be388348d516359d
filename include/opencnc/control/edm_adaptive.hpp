// SPDX-License-Identifier: GPL-3.0-or-later
// EdmAdaptive — adaptive control of the sinker EDM's gap: the servo's reference and gain and the
// jump's period and height follow the measured gap state within the condition's bounds. Plain
// data; nothing allocates (docs/edm.md, "Adaptive control").
#pragma once

#include <cstdint>

#include "opencnc/machine/edm.hpp"
#include "opencnc/machine/machine_io.hpp"

namespace opencnc::control {

/// The gap's state over a window of machining periods, and the rule that moves a condition's
/// settings by it. Servo thread only; real-time safe.
class EdmAdaptive {
 public:
  /// Periods of machining (the gap sparking) per window: 25 ms at 1 kHz.
  static constexpr int kWindow = 25;

  /// A new condition: the window starts empty.
  void reset() noexcept;
  /// One machining period with the gap in `state` at `voltage_v`. At the end of a window, moves
  /// `active`'s settings within `base`'s bounds; true when one changed.
  bool sample(machine::GapState state, double voltage_v, const machine::EdmCondition& base,
              machine::EdmCondition& active) noexcept;
  /// The last window's share of arc and short periods, and the voltage's spread over the reference.
  double abnormal_share() const noexcept { return abnormal_; }
  double voltage_spread() const noexcept { return spread_; }

 private:
  int n_ = 0, arcs_ = 0, shorts_ = 0;
  double sum_ = 0, sum2_ = 0;
  double abnormal_ = 0, spread_ = 0;
};

}  // namespace opencnc::control
