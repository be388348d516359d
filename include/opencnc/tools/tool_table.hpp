// SPDX-License-Identifier: GPL-3.0-or-later
// ToolTable — tools read from a LinuxCNC `.tbl` file: numbers, pockets, offsets, diameters.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::tools {

/// One line of a tool table. Lengths are in the table's units (the machine's user units);
/// angles in degrees.
struct ToolEntry {
  int tool = 0;             ///< T: tool number (0 = no tool)
  int pocket = 0;           ///< P: pocket as written in the table
  Pose offset{};            ///< X Y Z A B C U V W offsets
  double diameter = 0;      ///< D
  double front_angle = 0;   ///< I (lathe tools)
  double back_angle = 0;    ///< J (lathe tools)
  int orientation = 0;      ///< Q: lathe tool orientation 0..9
  std::string comment;      ///< text after ';'

  bool operator==(const ToolEntry&) const = default;
};

/// The tools of a machine in load order. Entry k (1-based) is what LinuxCNC calls the tool's
/// index: the number CHANGE_TOOL reports on a non-random tool changer.
/// Non-real-time; not thread-safe for writes.
class ToolTable {
 public:
  ToolTable() = default;

  /// Parses `.tbl` text. Every problem is reported in `diags` as `file:line:col: message`
  /// with a `tools.*` code; lines with errors are left out. Any thread.
  static ToolTable parse(std::string_view text, std::string_view file_name, Diagnostics& diags);
  /// Reads and parses a file; returns nothing (and a diagnostic) when it cannot be read.
  static std::optional<ToolTable> load(const std::string& path, Diagnostics& diags);

  /// Number of entries.
  std::size_t size() const noexcept { return entries_.size(); }
  bool empty() const noexcept { return entries_.empty(); }
  /// Entry by 1-based index (1..size()).
  const ToolEntry& at_index(std::size_t index) const { return entries_.at(index - 1); }
  /// 1-based index of tool `tool`, if present.
  std::optional<std::size_t> find(int tool) const noexcept;
  /// The entry of tool `tool`, if present.
  const ToolEntry* tool(int tool) const noexcept;

  /// Appends an entry; returns false (and changes nothing) if its tool number is taken.
  bool add(ToolEntry entry);
  /// Replaces the entry at a 1-based index.
  void replace(std::size_t index, ToolEntry entry);

  const std::vector<ToolEntry>& entries() const noexcept { return entries_; }
  /// The table as `.tbl` text that parse() reads back to an equal table (numbers in their
  /// shortest exact form; zero offsets left out, as LinuxCNC writes them). Any thread.
  std::string format() const;
  bool operator==(const ToolTable& other) const noexcept { return entries_ == other.entries_; }

 private:
  void index_tool(int tool, std::size_t index);

  std::vector<ToolEntry> entries_;
  /// (tool, 1-based index) sorted by tool.
  std::vector<std::pair<int, std::size_t>> by_tool_;
};

}  // namespace opencnc::tools
