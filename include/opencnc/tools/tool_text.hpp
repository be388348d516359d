// SPDX-License-Identifier: GPL-3.0-or-later
// Tools with edges as text: the 840D-style subprogram (IF (R90==T) AND (R91==D) … M17) written
// and read back exactly, a readable listing, and LinuxCNC `.tbl` tables read into edges.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "opencnc/core/diagnostic.hpp"
#include "opencnc/tools/tool_data.hpp"
#include "opencnc/tools/tool_table.hpp"

namespace opencnc::tools {

/// What the first line of an 840D export says about the snapshot it holds.
struct SnapshotHeader {
  std::int64_t backup = 0;  ///< the backup's number (0: the live table)
  std::string taken_utc;    ///< when it was taken ("2026-11-26T03:10:56Z"), or exported
  bool operator==(const SnapshotHeader&) const = default;
};

/// The set as an 840D subprogram: the header as comments at the top, each tool's pocket and
/// comment as a comment line, per edge a block `IF (R90==T) AND (R91==D)` setting R<n> to
/// $TC_DP<n> (R3 length 1, R6 radius, R12.. wear, R21.. base), `ENDIF`, and `M17` at the end.
/// Numbers in their shortest exact decimal form. Any thread.
std::string format_840d(const ToolSet& set, const SnapshotHeader& header);
/// Reads format_840d's text back to the same set (and header). Problems go to `diags` as
/// `file:line:col: message` (`tools.840d-*`); nothing is returned then. Any thread.
std::optional<ToolSet> parse_840d(std::string_view text, std::string_view file, Diagnostics& diags,
                                  SnapshotHeader* header = nullptr);
/// True when `text` looks like format_840d's (an `IF (R90==` block or `M17`). Any thread.
bool looks_like_840d(std::string_view text) noexcept;

/// A readable listing: one line per tool, one per edge with its non-zero parameters. Any thread.
std::string format_listing(const ToolSet& set);

/// The edges of a LinuxCNC table (tools/edge_mapping.hpp numbering: T, or D·10000+T): geometry
/// from Z, Y, X and the diameter, cutting direction from the orientation, wear and base 0.
/// Entries it cannot hold (offsets along A–W, lathe angles, a number that names no edge) are
/// errors at their line in `diags`; nothing is returned then. Any thread.
std::optional<ToolSet> from_linuxcnc(const ToolTable& table, std::string_view file, Diagnostics& diags);

}  // namespace opencnc::tools
