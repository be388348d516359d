// SPDX-License-Identifier: GPL-3.0-or-later
// The 840D subprogram form (written and read exactly), the listing, LinuxCNC tables as edges.
#include "opencnc/tools/tool_text.hpp"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "opencnc/tools/edge_mapping.hpp"
#include "opencnc/tools/tool_check.hpp"

namespace opencnc::tools {

namespace {

constexpr std::string_view kHeader = "; opencnc tool data";

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool eat(std::string_view& s, std::string_view prefix) {
  if (s.substr(0, prefix.size()) != prefix) return false;
  s.remove_prefix(prefix.size());
  return true;
}

template <class T>
bool number(std::string_view& s, T& out) {
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  if (ec != std::errc() || p == s.data()) return false;
  s.remove_prefix(static_cast<std::size_t>(p - s.data()));
  return true;
}

// Reads the parts of the text one line at a time and reports at the line and column.
class Reader840d {
 public:
  Reader840d(std::string_view file, Diagnostics& diags) : file_(file), diags_(diags) {}
  bool line(std::string_view raw, std::uint32_t n, ToolSet& set, SnapshotHeader& header);
  bool finish(std::uint32_t n);

 private:
  bool fail(std::uint32_t n, std::string_view at, std::string_view whole, std::string message) {
    const auto col = static_cast<std::uint32_t>(at.data() - whole.data()) + 1;
    diags_.error(std::string(file_), n, col, std::move(message), "tools.840d-syntax");
    return false;
  }
  bool comment(std::string_view s, std::string_view whole, std::uint32_t n, ToolSet& set,
               SnapshotHeader& header);
  bool block_start(std::string_view s, std::string_view whole, std::uint32_t n, ToolSet& set);
  bool assignments(std::string_view s, std::string_view whole, std::uint32_t n);

  std::string_view file_;
  Diagnostics& diags_;
  Edge* edge_ = nullptr;  ///< inside IF … ENDIF
  bool ended_ = false;    ///< after M17
  std::uint32_t if_line_ = 0;
};

bool Reader840d::line(std::string_view raw, std::uint32_t n, ToolSet& set, SnapshotHeader& header) {
  const std::string_view s = trim(raw);
  if (s.empty()) return true;
  if (ended_) return fail(n, s, raw, "nothing may follow M17");
  if (s.front() == ';') return comment(s, raw, n, set, header);
  if (s.starts_with("IF ")) return block_start(s, raw, n, set);
  if (s == "ENDIF") {
    if (edge_ == nullptr) return fail(n, s, raw, "ENDIF without IF");
    edge_ = nullptr;
    return true;
  }
  if (s == "M17") {
    if (edge_ != nullptr) return fail(n, s, raw, fmt::format("M17 inside the IF of line {}", if_line_));
    ended_ = true;
    return true;
  }
  if (s.front() == 'R') return assignments(s, raw, n);
  return fail(n, s, raw, "expected IF (R90==T) AND (R91==D), R<n>=value, ENDIF, M17 or a ; comment");
}

// "; opencnc tool data: backup 3 taken 2026-…Z" and "; T3 pocket 3: comment"; other comments are free.
bool Reader840d::comment(std::string_view s, std::string_view whole, std::uint32_t n, ToolSet& set,
                         SnapshotHeader& header) {
  std::string_view r = s;
  if (eat(r, kHeader)) {
    if (eat(r, ": backup ") && number(r, header.backup) && eat(r, " taken "))
      header.taken_utc = std::string(r);
    else if (eat(r, ": live table exported "))
      header.taken_utc = std::string(r);
    return true;
  }
  r = s.substr(1);
  int t = 0, pocket = 0;
  if (!eat(r, " T") || !number(r, t)) return true;
  if (!eat(r, " pocket ") || !number(r, pocket) || !(r.empty() || r.starts_with(": ")))
    return fail(n, s, whole, "a tool line reads '; T<n> pocket <p>: <comment>'");
  if (t < 1 || t > kMaxToolNumber)
    return fail(n, s, whole, fmt::format("T{}: tool numbers go from 1 to {}", t, kMaxToolNumber));
  if (set.tool(t) != nullptr) return fail(n, s, whole, fmt::format("T{} is described twice", t));
  Tool& tool = set.tool_or_add(t);
  tool.pocket = pocket;
  if (r.size() > 2) tool.comment = std::string(r.substr(2));
  return true;
}

bool Reader840d::block_start(std::string_view s, std::string_view whole, std::uint32_t n, ToolSet& set) {
  if (edge_ != nullptr)
    return fail(n, s, whole, fmt::format("IF inside the IF of line {} (ENDIF missing)", if_line_));
  std::string_view r = s;
  int t = 0, d = 0;
  if (!eat(r, "IF (R90==") || !number(r, t) || !eat(r, ") AND (R91==") || !number(r, d) || !eat(r, ")") ||
      !r.empty())
    return fail(n, s, whole, "a block starts 'IF (R90==<T>) AND (R91==<D>)'");
  if (t < 1 || t > kMaxToolNumber || d < 1 || d > kMaxEdge)
    return fail(n, s, whole,
                fmt::format("T{} D{}: tools go from T1 to T{}, edges from D1 to D{}", t, d, kMaxToolNumber,
                            kMaxEdge));
  Tool* tool = set.tool(t);
  if (tool == nullptr)
    return fail(n, s, whole, fmt::format("T{}: its '; T{} pocket …' line must come first", t, t));
  if (tool->edge(d) != nullptr) return fail(n, s, whole, fmt::format("T{} D{} is set twice", t, d));
  edge_ = &set.edge_or_add(t, d);
  if_line_ = n;
  return true;
}

bool Reader840d::assignments(std::string_view s, std::string_view whole, std::uint32_t n) {
  if (edge_ == nullptr) return fail(n, s, whole, "R parameters are set inside an IF block only");
  std::string_view r = s;
  while (!r.empty()) {
    const std::string_view at = r;
    int rn = 0;
    double v = 0;
    if (!eat(r, "R") || !number(r, rn) || !eat(r, "=")) return fail(n, at, whole, "expected R<n>=<value>");
    const auto p = param_of_r(rn);
    if (!p) return fail(n, at, whole, fmt::format("R{} is no edge parameter (R1–R6, R12–R15, R21–R23)", rn));
    if (!number(r, v) || !std::isfinite(v)) return fail(n, at, whole, fmt::format("R{}: not a number", rn));
    if (!r.empty() && r.front() != ' ') return fail(n, r, whole, "a space separates the assignments");
    edge_->set(*p, v);
    r = trim(r);
  }
  return true;
}

bool Reader840d::finish(std::uint32_t n) {
  if (edge_ != nullptr) {
    diags_.error(std::string(file_), if_line_, 1, "this IF has no ENDIF", "tools.840d-syntax");
    return false;
  }
  if (!ended_) {
    diags_.error(std::string(file_), n, 1, "the subprogram ends without M17", "tools.840d-syntax");
    return false;
  }
  return true;
}

}  // namespace

std::string format_840d(const ToolSet& set, const SnapshotHeader& header) {
  std::string out;
  if (header.backup > 0)
    out += fmt::format("{}: backup {} taken {}\n", kHeader, header.backup, header.taken_utc);
  else
    out += fmt::format("{}: live table exported {}\n", kHeader, header.taken_utc);
  out +=
      "; R90 = tool T, R91 = cutting edge D; R<n> = $TC_DP<n>: R1 type, R2 cutting direction, R3-R5 length "
      "1-3,\n";
  out += "; R6 radius, R12-R14 wear of length 1-3, R15 wear of radius, R21-R23 base length 1-3 (mm)\n";
  for (const Tool& t : set.tools) {
    out += fmt::format("; T{} pocket {}{}{}\n", t.tool, t.pocket, t.comment.empty() ? "" : ": ", t.comment);
    for (const Edge& e : t.edges) {
      out += fmt::format("IF (R90=={}) AND (R91=={})\n ", t.tool, e.edge);
      for (const ParamInfo& p : param_table())
        out += fmt::format(" R{}={}", p.tc_dp, format_value(e.get(p.param)));
      out += "\nENDIF\n";
    }
  }
  out += "M17\n";
  return out;
}

std::optional<ToolSet> parse_840d(std::string_view text, std::string_view file, Diagnostics& diags,
                                  SnapshotHeader* header) {
  ToolSet set;
  SnapshotHeader h;
  Reader840d reader(file, diags);
  std::uint32_t n = 0;
  bool ok = true;
  while (!text.empty() && ok) {
    const std::size_t eol = text.find('\n');
    ++n;
    ok = reader.line(text.substr(0, eol), n, set, h);
    text = eol == std::string_view::npos ? std::string_view() : text.substr(eol + 1);
  }
  if (!ok || !reader.finish(n)) return std::nullopt;
  if (const auto why = invalid(set)) {
    diags.error(std::string(file), 0, 0, *why, "tools.840d-value");
    return std::nullopt;
  }
  if (header != nullptr) *header = h;
  return set;
}

bool looks_like_840d(std::string_view text) noexcept {
  return text.find("IF (R90==") != std::string_view::npos || text.find(kHeader) != std::string_view::npos;
}

std::string format_listing(const ToolSet& set) {
  std::string out;
  for (const Tool& t : set.tools) {
    out += fmt::format("T{:<4} pocket {:<3} {}\n", t.tool, t.pocket, t.comment);
    for (const Edge& e : t.edges) {
      out += fmt::format("  D{}  length1 {} (effective {})  radius {} (effective {})", e.edge,
                         format_value(e.get(Param::Length1)), format_value(e.effective_length(1)),
                         format_value(e.get(Param::Radius)), format_value(e.effective_radius()));
      for (const ParamInfo& p : param_table()) {
        if (p.param == Param::Length1 || p.param == Param::Radius || e.get(p.param) == 0) continue;
        out += fmt::format("  {} {}", p.name, format_value(e.get(p.param)));
      }
      out += '\n';
    }
  }
  return out;
}

std::optional<ToolSet> from_linuxcnc(const ToolTable& table, std::string_view file, Diagnostics& diags) {
  ToolSet set;
  const std::size_t before = diags.error_count();
  for (std::size_t i = 1; i <= table.size(); ++i) {
    const ToolEntry& entry = table.at_index(i);
    const auto td = tool_and_edge(entry.tool);
    if (!td) {
      diags.error(
          std::string(file), 0, 0,
          fmt::format("T{}: names no tool and edge (T1–T9999 for D1, D·10000+T for D2–D9)", entry.tool),
          "tools.import");
      continue;
    }
    auto& [t, d] = *td;
    if (set.edge(t, d) != nullptr) {
      diags.error(std::string(file), 0, 0, fmt::format("T{} D{} is in the table twice", t, d),
                  "tools.import");
      continue;
    }
    Tool& tool = set.tool_or_add(t);
    Edge& e = set.edge_or_add(t, d);
    if (const auto why = apply_entry(entry, e)) {
      diags.error(std::string(file), 0, 0, fmt::format("T{}: {} cannot be kept", entry.tool, *why),
                  "tools.import");
      continue;
    }
    if (d == 1 || tool.pocket == 0) tool.pocket = entry.pocket;
    if (d == 1) tool.comment = entry.comment;
  }
  if (diags.error_count() > before) return std::nullopt;
  return set;
}

}  // namespace opencnc::tools
