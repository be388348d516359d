// SPDX-License-Identifier: GPL-3.0-or-later
// A TOML text as lines: finding table headers and where a table's own lines end.
#include "toml_lines.hpp"

#include <cctype>

namespace opencnc::config::detail {

std::vector<TomlLine> split_lines(std::string_view text) {
  std::vector<TomlLine> out;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t nl = text.find('\n', at);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl + 1;
    std::string_view t = text.substr(at, (nl == std::string_view::npos ? text.size() : nl) - at);
    if (!t.empty() && t.back() == '\r') t.remove_suffix(1);
    out.push_back({t, at, end});
    at = end;
  }
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string header_key(std::string_view line) {
  std::string_view t = trim(line);
  if (t.size() < 3 || t[0] != '[' || t[1] == '[') return "";
  const std::size_t close = t.find(']');
  if (close == std::string_view::npos) return "";
  const std::string_view rest = trim(t.substr(close + 1));
  if (!rest.empty() && rest[0] != '#') return "";
  std::string key;
  for (char c : t.substr(1, close - 1)) {
    if (c == ' ' || c == '\t' || c == '"' || c == '\'') continue;
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return "";
    key += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return key.empty() || !std::isalpha(static_cast<unsigned char>(key[0])) ? "" : key;
}

bool is_array_header(std::string_view line) {
  const std::string_view t = trim(line);
  return t.size() > 4 && t.substr(0, 2) == "[[";
}

std::string array_header_key(std::string_view line) {
  const std::string_view t = trim(line);
  if (!is_array_header(t)) return "";
  const std::size_t close = t.find("]]");
  if (close == std::string_view::npos) return "";
  // "[[a.b]] # …" read as the table header "[a.b] # …" without the outer brackets.
  return header_key(std::string(t.substr(1, close)) + std::string(t.substr(close + 2)));
}

bool is_blank_or_comment(std::string_view line) {
  const std::string_view t = trim(line);
  return t.empty() || t[0] == '#';
}

std::size_t table_end(const std::vector<TomlLine>& lines, std::size_t header) {
  std::size_t next = header + 1;
  while (next < lines.size() && header_key(lines[next].text).empty() && !is_array_header(lines[next].text))
    ++next;
  std::size_t end = next;
  while (end > header + 1 && is_blank_or_comment(lines[end - 1].text)) --end;
  return end;
}

}  // namespace opencnc::config::detail
