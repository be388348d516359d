// SPDX-License-Identifier: GPL-3.0-or-later
// The first error of a profile load as code and line:col, and all its messages: what the config
// tests of one section compare a bad profile against.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config::test {

struct Where {
  std::string code;
  std::uint32_t line = 0, col = 0;
  bool operator==(const Where&) const = default;
};
inline std::ostream& operator<<(std::ostream& os, const Where& w) {
  return os << w.code << " at " << w.line << ":" << w.col;
}
inline Where first_error(const ProfileLoad& load) {
  for (const auto& d : load.diagnostics.items()) {
    if (d.severity == Severity::Error) return {d.code, d.line, d.col};
  }
  return {};
}
inline std::string all_messages(const Diagnostics& d) {
  std::string s;
  for (const auto& i : d.items()) s += i.format() + "\n";
  return s;
}

}  // namespace opencnc::config::test
