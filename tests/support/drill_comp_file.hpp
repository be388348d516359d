// SPDX-License-Identifier: GPL-3.0-or-later
// The drill's profile with Y's pitch table moved into a LinuxCNC comp file (type 0: the positions
// reached moving up and moving down), the same table as the profile's own, with comment lines.
#pragma once

#include <string>

namespace opencnc::test {

/// The comp file's name, beside the profile.
inline constexpr const char* kDrillYCompName = "drill-y.comp";

/// Y's table of configs/drill-retrofit.toml as a comp file: nominal, reached moving +, moving −.
inline constexpr const char* kDrillYComp =
    "# Y's lead screw by laser: nominal, reached moving up, reached moving down (mm)\n"
    "0 0 0.015\n"
    "50 49.998 50.013\n"
    "100 99.996 100.011\n"
    "150 149.9955 150.0105\n"
    "# the middle of the screw\n"
    "200 199.995 200.01\n"
    "250 249.993 250.008\n"
    "300 299.991 300.006\n"
    "350 349.9895 350.0045\n"
    "400 399.988 400.003\n";

/// `profile` (the text of configs/drill-retrofit.toml) with Y's start, interval, forward and
/// reverse replaced by `comp_file = "drill-y.comp"` of type 0; "" when the lines are not there.
inline std::string drill_with_y_comp_file(std::string profile) {
  const std::string first = "[axis.y.compensation]\n";
  std::size_t at = profile.find(first);
  if (at == std::string::npos) return "";
  at = profile.find("start = 0\n", at);
  const std::size_t end = profile.find("backlash = ", at);
  if (at == std::string::npos || end == std::string::npos) return "";
  profile.replace(at, end - at, "comp_file = \"drill-y.comp\"\ncomp_file_type = 0\n");
  return profile;
}

}  // namespace opencnc::test
