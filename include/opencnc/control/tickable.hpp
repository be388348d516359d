// SPDX-License-Identifier: GPL-3.0-or-later
// Tickable — what a clock advances by one servo period; no standard-library header, so the tick's
// public header (servo.hpp) does not pull <string> or <vector> into the real-time core.
#pragma once

namespace opencnc::control {

/// Something advanced by one servo period per call. The control code does not know which clock
/// drives it (the virtual clock, RealtimeClock or a HAL thread). `tick()` is called from the
/// clock's thread only and must be real-time safe.
class Tickable {
 public:
  virtual ~Tickable() = default;
  /// Advances by one period. Returns false to ask the clock to stop after this tick.
  virtual bool tick() noexcept = 0;
};

}  // namespace opencnc::control
