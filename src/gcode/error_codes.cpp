// SPDX-License-Identifier: GPL-3.0-or-later
// Stable ids of the interpreter's error codes.
#include "opencnc/gcode/error_codes.hpp"

namespace opencnc::gcode {

std::string_view error_id(ErrorCode code) noexcept {
  switch (code) {
#define OPENCNC_GCODE_ID(e, id) \
  case ErrorCode::e:            \
    return id;
    OPENCNC_GCODE_ERRORS(OPENCNC_GCODE_ID)
#undef OPENCNC_GCODE_ID
  }
  return "gcode.unknown";
}

}  // namespace opencnc::gcode
