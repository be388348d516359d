// SPDX-License-Identifier: GPL-3.0-or-later
// Tools with edges (T/D) as LinuxCNC tool-table entries, which the interpreter's G43, G41/G42 and
// G10 L1 read and write: edge D1 of tool T is LinuxCNC tool T, edge D (2..9) is tool D·10000 + T.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "opencnc/tools/tool_data.hpp"
#include "opencnc/tools/tool_table.hpp"

namespace opencnc::tools {

/// LinuxCNC's tool number of edge `d` of tool `t`: T for D1, D·10000 + T for D2..D9
/// (T3 D2 is tool 20003: G43 H20003, G41 D20003). Any thread.
int linuxcnc_number(int t, int d) noexcept;
/// The (T, D) of a LinuxCNC tool number, if it names one. Any thread.
std::optional<std::pair<int, int>> tool_and_edge(int number) noexcept;

/// The entry the interpreter reads for one edge: offset Z = effective length 1 (geometry + wear
/// + base), Y = length 2, X = length 3, diameter = 2 × effective radius, orientation = cutting
/// direction (turning tools), the tool's pocket and comment. Any thread.
ToolEntry linuxcnc_entry(const Tool& tool, const Edge& edge);
/// Every edge as an entry, in T then D order (the order of the service's indices). Any thread.
ToolTable linuxcnc_table(const ToolSet& set);

/// Writes what G10 L1/L10/L11 set for one edge into `edge`: the new effective values become
/// geometry (wear and base stay what they were: effective = geometry + wear + base), the
/// orientation the cutting direction. Returns why it cannot (an offset along A–C or U–W, lathe
/// angles, a cutting direction beyond 9), or nothing. Any thread.
std::optional<std::string> apply_entry(const ToolEntry& entry, Edge& edge);

}  // namespace opencnc::tools
