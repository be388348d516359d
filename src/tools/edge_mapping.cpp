// SPDX-License-Identifier: GPL-3.0-or-later
// T/D edges ↔ LinuxCNC tool entries (numbers, offsets, diameters).
#include "opencnc/tools/edge_mapping.hpp"

#include <fmt/format.h>

namespace opencnc::tools {

namespace {
constexpr int kEdgeStride = 10000;
}

int linuxcnc_number(int t, int d) noexcept {
  return d <= 1 ? t : d * kEdgeStride + t;
}

std::optional<std::pair<int, int>> tool_and_edge(int number) noexcept {
  if (number < 1) return std::nullopt;
  const int d = number / kEdgeStride, t = number % kEdgeStride;
  if (t < 1 || d == 1 || d > kMaxEdge) return std::nullopt;
  return std::pair{t, d == 0 ? 1 : d};
}

ToolEntry linuxcnc_entry(const Tool& tool, const Edge& edge) {
  ToolEntry e;
  e.tool = linuxcnc_number(tool.tool, edge.edge);
  e.pocket = tool.pocket;
  e.offset[2] = edge.effective_length(1);
  e.offset[1] = edge.effective_length(2);
  e.offset[0] = edge.effective_length(3);
  e.diameter = 2 * edge.effective_radius();
  const double dir = edge.get(Param::CuttingDirection);
  e.orientation = dir >= 0 && dir <= 9 ? static_cast<int>(dir) : 0;
  e.comment = edge.edge == 1
                  ? tool.comment
                  : fmt::format("{}{}D{}", tool.comment, tool.comment.empty() ? "" : " ", edge.edge);
  return e;
}

ToolTable linuxcnc_table(const ToolSet& set) {
  ToolTable table;
  for (const Tool& t : set.tools) {
    for (const Edge& e : t.edges) table.add(linuxcnc_entry(t, e));
  }
  return table;
}

std::optional<std::string> apply_entry(const ToolEntry& entry, Edge& edge) {
  for (int i = 3; i < kAxisCount; ++i) {
    if (entry.offset[i] != 0)
      return fmt::format("an offset along {} (the tool store keeps lengths along X, Y and Z only)",
                         kAxisLetters[static_cast<std::size_t>(i)]);
  }
  if (entry.front_angle != 0 || entry.back_angle != 0) return std::string("lathe tool angles (I, J)");
  if (entry.orientation < 0 || entry.orientation > 9) return fmt::format("orientation {}", entry.orientation);
  // Only what G10 changed: an unchanged value must not move by a rounding of geometry = effective − wear −
  // base.
  const std::size_t w = static_cast<std::size_t>(Param::WearLength1),
                    b = static_cast<std::size_t>(Param::BaseLength1);
  const double effective[3] = {entry.offset[2], entry.offset[1], entry.offset[0]};
  for (std::size_t k = 0; k < 3; ++k) {
    if (effective[k] == edge.effective_length(static_cast<int>(k) + 1)) continue;
    edge.values[static_cast<std::size_t>(Param::Length1) + k] =
        effective[k] - edge.values[w + k] - edge.values[b + k];
  }
  if (entry.diameter != 2 * edge.effective_radius())
    edge.set(Param::Radius, entry.diameter / 2 - edge.get(Param::WearRadius));
  const double dir = edge.get(Param::CuttingDirection);
  if (entry.orientation != (dir >= 0 && dir <= 9 ? static_cast<int>(dir) : 0))
    edge.set(Param::CuttingDirection, entry.orientation);
  return std::nullopt;
}

}  // namespace opencnc::tools
