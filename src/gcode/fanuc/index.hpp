// SPDX-License-Identifier: GPL-3.0-or-later
// FanucIndex — where things are in Fanuc program files, read from the file on first use: the
// O-numbered programs of a file, and in one program its sequence numbers and DO/END lines.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "opencnc/gcode/state.hpp"
#include "source_file.hpp"

namespace opencnc::gcode {

/// The program number of a program line ("O1000", ":1000", "%O1000(NAME)"), if `raw` is one.
std::optional<std::uint32_t> fanuc_program_number(std::string_view raw) noexcept;

/// A cache of file contents for GOTO, WHILE and M98: what it returns depends only on the
/// bytes of the files, so it never changes what a run does (and is not interpreter state).
/// Reading moves the SourceFile: the caller seeks back before its next line.
class FanucIndex {
 public:
  struct Program {
    std::uint32_t number = 0;
    SourcePosition at;  ///< its program line
  };
  /// A WHILE..DO m or DO m line (end = false) or an END m line.
  struct LoopMark {
    SourcePosition at;     ///< the line
    SourcePosition after;  ///< the line after it
    int id = 0;
    bool end = false;
  };
  /// One program: from its start to the next program line (or a '%' line, or the end).
  struct Region {
    std::unordered_map<std::int64_t, SourcePosition> first_n;  ///< first line with each N number
    std::vector<LoopMark> loops;                               ///< in file order
  };

  /// The program lines of `file` in file order (read once).
  const std::vector<Program>& programs(std::uint32_t file, SourceFile& source);
  /// The program that starts at `start` (its program line or the first line of a file).
  const Region& region(const SourcePosition& start, SourceFile& source);

 private:
  std::map<std::uint32_t, std::vector<Program>> programs_;
  std::map<std::pair<std::uint32_t, std::uint64_t>, Region> regions_;
  std::string scratch_;
};

}  // namespace opencnc::gcode
