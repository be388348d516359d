// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect's macro variable map: which numbers are locals, commons, stored or computed
// system variables, and which the dialect does not provide (docs/dialects.md).
#pragma once

namespace opencnc::gcode {

enum class FanucVariable : unsigned char {
  Null,         ///< #0: always vacant, read-only
  Local,        ///< #1..#33: local to a G65 macro level
  Missing,      ///< numbers Fanuc controls do not have (#34..#99)
  Common,       ///< #100..#999
  Stored,       ///< kept as written (timers, parts count, offsets and LinuxCNC's parameters)
  Alarm,        ///< #3000: writing it stops the program with an alarm
  StopMessage,  ///< #3006: writing it stops the program with a message
  Computed,     ///< read-only, computed from the state (modal codes, positions)
  Unavailable,  ///< a Fanuc system variable this controller does not provide
};

/// What #index is in the Fanuc dialect (0 <= index < kParameterCount).
constexpr FanucVariable fanuc_variable_kind(int index) noexcept {
  using V = FanucVariable;
  if (index == 0) return V::Null;
  if (index <= 33) return V::Local;
  if (index <= 99) return V::Missing;
  if (index <= 999) return V::Common;
  if (index < 3000) return V::Unavailable;  // interface signals, tool offsets
  if (index == 3000) return V::Alarm;
  if (index <= 3005) return V::Stored;  // clocks, single-block/feed-hold control, settings
  if (index == 3006) return V::StopMessage;
  if (index == 3007) return V::Computed;  // mirror image status
  if (index == 3011 || index == 3012 || index == 3901 || index == 3902)
    return V::Stored;  // date, time, parts
  if (index < 4001) return V::Unavailable;
  const int modal = index >= 4201 ? index - 200 : index;  // #42xx: this block, #40xx: the one before
  if (modal <= 4030) return V::Computed;                  // modal G codes by group
  if (modal == 4109 || modal == 4119 || modal == 4120) return V::Computed;  // F, S, T
  if (index < 5001) return V::Unavailable;
  if ((index <= 5009) || (index >= 5021 && index <= 5029) || (index >= 5041 && index <= 5049) ||
      (index >= 5081 && index <= 5089) || (index >= 5101 && index <= 5109))
    return V::Computed;  // end point, machine and work position, tool length offset, servo lag
  if (index >= 5401 && index <= 5600) return V::Computed;  // Haas tool timers
  return V::Stored;
}

}  // namespace opencnc::gcode
