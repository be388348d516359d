// SPDX-License-Identifier: GPL-3.0-or-later
// Live table against backup: per-kind tolerances, the wear band, edges added and removed.
#include "opencnc/tools/tool_check.hpp"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

namespace opencnc::tools {

namespace {

double allowed(ParamKind k, const CheckTolerances& t) {
  switch (k) {
    case ParamKind::Identity:
      return 0;
    case ParamKind::Geometry:
      return t.geometry_mm;
    case ParamKind::Wear:
      return t.wear_band_mm;
    case ParamKind::Base:
      return t.base_mm;
  }
  return 0;
}

void compare_edges(int tool, const Edge& b, const Edge& l, const CheckTolerances& t,
                   std::vector<Difference>& out) {
  for (const ParamInfo& p : param_table()) {
    const double bv = b.get(p.param), lv = l.get(p.param);
    if (bv == lv) continue;
    Difference d;
    d.tool = tool;
    d.edge = b.edge;
    d.param = p.param;
    d.backup = bv;
    d.live = lv;
    d.tolerance = allowed(p.kind, t);
    // A small slack for the decimal a person typed: 0.1 mm must pass a band of 0.1 mm.
    d.tolerated = p.kind != ParamKind::Identity && std::fabs(lv - bv) <= d.tolerance * (1 + 1e-9) + 1e-12;
    out.push_back(d);
  }
}

void edge_only(Difference::What what, int tool, const Edge& e, std::vector<Difference>& out) {
  Difference d;
  d.what = what;
  d.tool = tool;
  d.edge = e.edge;
  out.push_back(d);
}

}  // namespace

std::string format_value(double v) {
  if (v == 0) return "0";  // no "-0"
  // Shortest exact decimal without an exponent (an 840D R value cannot have one).
  char buf[400];
  const auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  return ec == std::errc() ? std::string(buf, p) : fmt::format("{}", v);
}

std::string Difference::text() const {
  switch (what) {
    case What::Added:
      return fmt::format("T{} D{}: live, not in the backup (a new edge: accept it to back it up)", tool,
                         edge);
    case What::Removed:
      return fmt::format("T{} D{}: in the backup, missing from the live table", tool, edge);
    case What::Changed:
      break;
  }
  const ParamInfo& p = info(*param);
  std::string why;
  if (p.kind == ParamKind::Identity) {
    why = "must be equal";
  } else {
    const double delta = live - backup;
    const char* band = p.kind == ParamKind::Wear       ? "wear band"
                       : p.kind == ParamKind::Geometry ? "geometry tolerance"
                                                       : "base tolerance";
    why = fmt::format("{}{} mm; {} {} mm", delta > 0 ? "+" : "", format_value(std::round(delta * 1e6) / 1e6),
                      band, format_value(tolerance));
  }
  return fmt::format("T{} D{} {}: backup {}, live {} ({})", tool, edge, p.name, format_value(backup),
                     format_value(live), why);
}

std::vector<Difference> compare(const ToolSet& backup, const ToolSet& live,
                                const CheckTolerances& tolerances) {
  std::vector<Difference> out;
  // Both sets are sorted by T and D: one merge.
  std::size_t i = 0, j = 0;
  while (i < backup.tools.size() || j < live.tools.size()) {
    const Tool* b = i < backup.tools.size() ? &backup.tools[i] : nullptr;
    const Tool* l = j < live.tools.size() ? &live.tools[j] : nullptr;
    if (l == nullptr || (b != nullptr && b->tool < l->tool)) {
      for (const Edge& e : b->edges) edge_only(Difference::What::Removed, b->tool, e, out);
      ++i;
      continue;
    }
    if (b == nullptr || l->tool < b->tool) {
      for (const Edge& e : l->edges) edge_only(Difference::What::Added, l->tool, e, out);
      ++j;
      continue;
    }
    std::size_t p = 0, q = 0;
    while (p < b->edges.size() || q < l->edges.size()) {
      const Edge* be = p < b->edges.size() ? &b->edges[p] : nullptr;
      const Edge* le = q < l->edges.size() ? &l->edges[q] : nullptr;
      if (le == nullptr || (be != nullptr && be->edge < le->edge)) {
        edge_only(Difference::What::Removed, b->tool, *be, out);
        ++p;
      } else if (be == nullptr || le->edge < be->edge) {
        edge_only(Difference::What::Added, l->tool, *le, out);
        ++q;
      } else {
        compare_edges(b->tool, *be, *le, tolerances, out);
        ++p;
        ++q;
      }
    }
    ++i;
    ++j;
  }
  return out;
}

std::vector<Difference> check(const ToolSet& backup, const ToolSet& live, const CheckTolerances& tolerances,
                              std::optional<int> tool, std::optional<int> edge) {
  std::vector<Difference> out;
  for (Difference& d : compare(backup, live, tolerances)) {
    if (d.tolerated) continue;
    if (tool && d.tool != *tool) continue;
    if (edge && d.edge != *edge) continue;
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace opencnc::tools
