// SPDX-License-Identifier: GPL-3.0-or-later
// Parsing and lookup of LinuxCNC tool tables.
#include "opencnc/tools/tool_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "opencnc/core/atomic_file.hpp"

namespace opencnc::tools {

namespace {

struct LineParser {
  std::string_view file;
  std::uint32_t line_no;
  Diagnostics& diags;
  bool ok = true;

  void fail(std::size_t col, std::string message, const char* code) {
    diags.error(std::string(file), line_no, static_cast<std::uint32_t>(col + 1), std::move(message), code);
    ok = false;
  }
};

bool parse_double(std::string_view s, double& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(out);
}

bool parse_int(std::string_view s, int& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && ptr == s.data() + s.size();
}

int axis_of(char letter) {
  switch (letter) {
    case 'X': return 0;
    case 'Y': return 1;
    case 'Z': return 2;
    case 'A': return 3;
    case 'B': return 4;
    case 'C': return 5;
    case 'U': return 6;
    case 'V': return 7;
    case 'W': return 8;
    default: return -1;
  }
}

// Applies one `letter value` word to `e`; returns false (after reporting) on a bad word.
void apply_word(LineParser& p, std::size_t col, std::string_view word, ToolEntry& e, bool& has_tool, bool& has_pocket,
                std::uint32_t& seen) {
  const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(word.front())));
  const std::string_view number = word.substr(1);
  if (letter < 'A' || letter > 'Z') {
    p.fail(col, fmt::format("unexpected '{}' in tool table (words are a letter and a number)", word), "tools.bad-word");
    return;
  }
  const std::uint32_t bit = 1u << (letter - 'A');
  if (seen & bit) {
    p.fail(col, fmt::format("{} appears twice on this line", letter), "tools.duplicate-word");
    return;
  }
  seen |= bit;
  if (letter == 'T' || letter == 'P' || letter == 'Q') {
    int v = 0;
    if (!parse_int(number, v)) {
      p.fail(col, fmt::format("{} needs a whole number, found '{}'", letter, number), "tools.bad-number");
      return;
    }
    if (letter == 'T') {
      if (v < 0) return p.fail(col, fmt::format("tool number {} is negative", v), "tools.negative-tool");
      e.tool = v;
      has_tool = true;
    } else if (letter == 'P') {
      if (v < 0) return p.fail(col, fmt::format("pocket {} is negative", v), "tools.negative-pocket");
      e.pocket = v;
      has_pocket = true;
    } else {
      if (v < 0 || v > 9) return p.fail(col, fmt::format("orientation Q{} is outside 0..9", v), "tools.bad-orientation");
      e.orientation = v;
    }
    return;
  }
  double v = 0;
  if (!parse_double(number, v)) {
    p.fail(col, fmt::format("{} needs a number, found '{}'", letter, number), "tools.bad-number");
    return;
  }
  if (const int axis = axis_of(letter); axis >= 0) {
    e.offset[axis] = v;
  } else if (letter == 'D') {
    e.diameter = v;
  } else if (letter == 'I') {
    e.front_angle = v;
  } else if (letter == 'J') {
    e.back_angle = v;
  } else {
    p.fail(col, fmt::format("unknown tool table word '{}'", letter), "tools.unknown-word");
  }
}

}  // namespace

ToolTable ToolTable::parse(std::string_view text, std::string_view file_name, Diagnostics& diags) {
  ToolTable table;
  std::uint32_t line_no = 0;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
    ++line_no;

    ToolEntry e;
    if (const std::size_t semi = line.find(';'); semi != std::string_view::npos) {
      std::string_view c = line.substr(semi + 1);
      while (!c.empty() && std::isspace(static_cast<unsigned char>(c.back()))) c.remove_suffix(1);
      e.comment = std::string(c);
      line = line.substr(0, semi);
    }
    LineParser p{file_name, line_no, diags};
    bool has_tool = false, has_pocket = false;
    std::uint32_t seen = 0;
    std::size_t i = 0;
    bool any = false;
    while (i < line.size()) {
      if (std::isspace(static_cast<unsigned char>(line[i]))) {
        ++i;
        continue;
      }
      const std::size_t start = i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      any = true;
      apply_word(p, start, line.substr(start, i - start), e, has_tool, has_pocket, seen);
    }
    if (!any || !p.ok) continue;
    if (!has_tool) {
      p.fail(0, "tool table line has no T word", "tools.missing-tool");
      continue;
    }
    if (!has_pocket) e.pocket = static_cast<int>(table.size() + 1);
    const int tool = e.tool;
    if (!table.add(std::move(e))) {
      p.fail(0, fmt::format("tool {} is listed twice", tool), "tools.duplicate-tool");
    }
  }
  return table;
}

std::optional<ToolTable> ToolTable::load(const std::string& path, Diagnostics& diags) {
  std::string text, why;
  if (!read_file(path, text, &why)) {
    diags.error(path, 0, 0, "cannot read the tool table: " + why, "tools.cannot-open");
    return std::nullopt;
  }
  return parse(text, path, diags);
}

std::string ToolTable::format() const {
  std::string out;
  for (const ToolEntry& e : entries_) {
    out += fmt::format("T{} P{}", e.tool, e.pocket);
    for (int i = 0; i < kAxisCount; ++i) {
      if (e.offset[i] != 0) out += fmt::format(" {}{}", kAxisLetters[static_cast<std::size_t>(i)], e.offset[i]);
    }
    if (e.diameter != 0) out += fmt::format(" D{}", e.diameter);
    if (e.front_angle != 0) out += fmt::format(" I{}", e.front_angle);
    if (e.back_angle != 0) out += fmt::format(" J{}", e.back_angle);
    if (e.orientation != 0) out += fmt::format(" Q{}", e.orientation);
    if (!e.comment.empty()) out += fmt::format(" ;{}", e.comment);
    out += '\n';
  }
  return out;
}

std::optional<std::size_t> ToolTable::find(int tool) const noexcept {
  auto it = std::lower_bound(by_tool_.begin(), by_tool_.end(), std::pair<int, std::size_t>{tool, 0});
  if (it == by_tool_.end() || it->first != tool) return std::nullopt;
  return it->second;
}

const ToolEntry* ToolTable::tool(int tool) const noexcept {
  const auto index = find(tool);
  return index ? &entries_[*index - 1] : nullptr;
}

void ToolTable::index_tool(int tool, std::size_t index) {
  auto it = std::lower_bound(by_tool_.begin(), by_tool_.end(), std::pair<int, std::size_t>{tool, 0});
  by_tool_.insert(it, {tool, index});
}

bool ToolTable::add(ToolEntry entry) {
  if (find(entry.tool)) return false;
  entries_.push_back(std::move(entry));
  index_tool(entries_.back().tool, entries_.size());
  return true;
}

void ToolTable::replace(std::size_t index, ToolEntry entry) {
  ToolEntry& slot = entries_.at(index - 1);
  const bool renumbered = slot.tool != entry.tool;
  slot = std::move(entry);
  if (!renumbered) return;
  by_tool_.clear();
  for (std::size_t i = 0; i < entries_.size(); ++i) index_tool(entries_[i].tool, i + 1);
}

}  // namespace opencnc::tools
