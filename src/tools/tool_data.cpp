// SPDX-License-Identifier: GPL-3.0-or-later
// The 840D edge parameters: names, kinds, $TC_DP numbers; lookups in a tool set.
#include "opencnc/tools/tool_data.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace opencnc::tools {

namespace {

constexpr std::array<ParamInfo, kParamCount> kParams{{
    {Param::Type, "type", ParamKind::Identity, 1},
    {Param::CuttingDirection, "cutting_direction", ParamKind::Identity, 2},
    {Param::Length1, "length1", ParamKind::Geometry, 3},
    {Param::Length2, "length2", ParamKind::Geometry, 4},
    {Param::Length3, "length3", ParamKind::Geometry, 5},
    {Param::Radius, "radius", ParamKind::Geometry, 6},
    {Param::WearLength1, "wear_length1", ParamKind::Wear, 12},
    {Param::WearLength2, "wear_length2", ParamKind::Wear, 13},
    {Param::WearLength3, "wear_length3", ParamKind::Wear, 14},
    {Param::WearRadius, "wear_radius", ParamKind::Wear, 15},
    {Param::BaseLength1, "base_length1", ParamKind::Base, 21},
    {Param::BaseLength2, "base_length2", ParamKind::Base, 22},
    {Param::BaseLength3, "base_length3", ParamKind::Base, 23},
}};

template <class Vec>
auto* find_tool(Vec& tools, int t) noexcept {
  auto it = std::lower_bound(tools.begin(), tools.end(), t, [](const Tool& a, int n) { return a.tool < n; });
  return it != tools.end() && it->tool == t ? &*it : nullptr;
}

}  // namespace

const std::array<ParamInfo, kParamCount>& param_table() noexcept {
  return kParams;
}

const ParamInfo& info(Param p) noexcept {
  return kParams[static_cast<std::size_t>(p)];
}

std::optional<Param> param_named(std::string_view name) noexcept {
  for (const ParamInfo& i : kParams) {
    if (name == i.name) return i.param;
  }
  return std::nullopt;
}

std::optional<Param> param_of_r(int r) noexcept {
  for (const ParamInfo& i : kParams) {
    if (i.tc_dp == r) return i.param;
  }
  return std::nullopt;
}

const char* to_string(ParamKind k) noexcept {
  switch (k) {
    case ParamKind::Identity:
      return "identity";
    case ParamKind::Geometry:
      return "geometry";
    case ParamKind::Wear:
      return "wear";
    case ParamKind::Base:
      return "base";
  }
  return "";
}

double Edge::effective_length(int i) const noexcept {
  const auto k = static_cast<std::size_t>(std::clamp(i, 1, 3) - 1);
  return values[static_cast<std::size_t>(Param::Length1) + k] +
         values[static_cast<std::size_t>(Param::WearLength1) + k] +
         values[static_cast<std::size_t>(Param::BaseLength1) + k];
}

double Edge::effective_radius() const noexcept {
  return get(Param::Radius) + get(Param::WearRadius);
}

const Edge* Tool::edge(int d) const noexcept {
  for (const Edge& e : edges) {
    if (e.edge == d) return &e;
  }
  return nullptr;
}

Edge* Tool::edge(int d) noexcept {
  for (Edge& e : edges) {
    if (e.edge == d) return &e;
  }
  return nullptr;
}

const Tool* ToolSet::tool(int t) const noexcept {
  return find_tool(tools, t);
}
Tool* ToolSet::tool(int t) noexcept {
  return find_tool(tools, t);
}

const Edge* ToolSet::edge(int t, int d) const noexcept {
  const Tool* x = tool(t);
  return x != nullptr ? x->edge(d) : nullptr;
}

Tool& ToolSet::tool_or_add(int t) {
  auto it = std::lower_bound(tools.begin(), tools.end(), t, [](const Tool& a, int n) { return a.tool < n; });
  if (it != tools.end() && it->tool == t) return *it;
  Tool fresh;
  fresh.tool = t;
  return *tools.insert(it, std::move(fresh));
}

Edge& ToolSet::edge_or_add(int t, int d) {
  Tool& x = tool_or_add(t);
  auto it =
      std::lower_bound(x.edges.begin(), x.edges.end(), d, [](const Edge& a, int n) { return a.edge < n; });
  if (it != x.edges.end() && it->edge == d) return *it;
  Edge fresh;
  fresh.edge = d;
  return *x.edges.insert(it, fresh);
}

std::size_t ToolSet::edge_count() const noexcept {
  std::size_t n = 0;
  for (const Tool& t : tools) n += t.edges.size();
  return n;
}

std::optional<std::string> invalid_comment(std::string_view comment) {
  if (comment.size() > kMaxCommentBytes)
    return fmt::format("a comment is at most {} bytes (this one has {})", kMaxCommentBytes, comment.size());
  for (const char ch : comment) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f)
      return fmt::format("a comment is one line of text without control characters (it holds byte 0x{:02x})",
                         c);
  }
  return std::nullopt;
}

std::optional<std::string> invalid(const ToolSet& set) {
  int last = 0;
  for (const Tool& t : set.tools) {
    if (t.tool < 1 || t.tool > kMaxToolNumber)
      return fmt::format("T{}: tool numbers go from 1 to {}", t.tool, kMaxToolNumber);
    if (t.tool <= last) return fmt::format("T{} is listed twice or out of order", t.tool);
    last = t.tool;
    if (t.pocket < 0) return fmt::format("T{}: pocket {} is negative", t.tool, t.pocket);
    if (const auto why = invalid_comment(t.comment)) return fmt::format("T{}: {}", t.tool, *why);
    int last_edge = 0;
    for (const Edge& e : t.edges) {
      if (e.edge < 1 || e.edge > kMaxEdge)
        return fmt::format("T{} D{}: edges go from D1 to D{}", t.tool, e.edge, kMaxEdge);
      if (e.edge <= last_edge) return fmt::format("T{} D{} is listed twice or out of order", t.tool, e.edge);
      last_edge = e.edge;
      for (const ParamInfo& p : param_table()) {
        const double v = e.get(p.param);
        if (!std::isfinite(v) || std::fabs(v) > 1e6)
          return fmt::format("T{} D{} {}: {} is not a length a tool has", t.tool, e.edge, p.name, v);
        if (p.kind == ParamKind::Identity && (v != std::floor(v) || v < 0 || v > 999))
          return fmt::format("T{} D{} {}: {} must be a whole number from 0 to 999", t.tool, e.edge, p.name,
                             v);
      }
    }
  }
  return std::nullopt;
}

}  // namespace opencnc::tools
