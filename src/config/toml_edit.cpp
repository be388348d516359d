// SPDX-License-Identifier: GPL-3.0-or-later
// One key of a TOML text set to a new value in place; the result is checked against the parsed
// original with only that value changed, so nothing else can have moved.
#include "opencnc/config/toml_edit.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <vector>

#include "toml_lines.hpp"

namespace opencnc::config {

namespace {

using detail::TomlLine;

bool bare_key_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Where a `key = value` line's value starts and ends (bytes in the line), or nullopt when the
/// line does not assign `key`. `multi_line` is set when the value goes on past this line.
struct ValueSpan {
  std::size_t begin = 0, end = 0;
  bool multi_line = false;
};

std::optional<ValueSpan> value_span(std::string_view line, std::string_view key) {
  std::size_t at = 0;
  while (at < line.size() && (line[at] == ' ' || line[at] == '\t')) ++at;
  if (line.substr(at, key.size()) != key) return std::nullopt;
  at += key.size();
  if (at < line.size() && (bare_key_char(line[at]) || line[at] == '.')) return std::nullopt;
  while (at < line.size() && (line[at] == ' ' || line[at] == '\t')) ++at;
  if (at >= line.size() || line[at] != '=') return std::nullopt;
  ++at;
  while (at < line.size() && (line[at] == ' ' || line[at] == '\t')) ++at;
  ValueSpan v{at, at, false};
  if (line.substr(at, 3) == "\"\"\"" || line.substr(at, 3) == "'''") {
    v.multi_line = true;
    return v;
  }
  // Scan to a comment outside strings, counting brackets: an array open at the line's end goes on.
  int depth = 0;
  char quote = 0;
  std::size_t i = at;
  for (; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == '\\' && quote == '"')
        ++i;
      else if (c == quote)
        quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == '#') {
      break;
    }
  }
  v.multi_line = depth > 0 || quote != 0;
  v.end = i;
  while (v.end > v.begin && (line[v.end - 1] == ' ' || line[v.end - 1] == '\t')) --v.end;
  return v;
}

/// The table at `path` (components compared in lower case), or nullptr.
toml::table* find_table(toml::table& root, const std::vector<std::string>& path) {
  toml::table* t = &root;
  for (const std::string& part : path) {
    toml::table* next = nullptr;
    for (auto&& [k, v] : *t) {
      if (lower(k.str()) == part && v.is_table()) next = v.as_table();
    }
    if (!next) return nullptr;
    t = next;
  }
  return t;
}

std::vector<std::string> split_key(std::string_view dotted) {
  std::vector<std::string> parts;
  std::size_t at = 0;
  while (true) {
    const std::size_t dot = dotted.find('.', at);
    parts.emplace_back(dotted.substr(at, dot == std::string_view::npos ? std::string_view::npos : dot - at));
    if (dot == std::string_view::npos) break;
    at = dot + 1;
  }
  return parts;
}

/// Which table an edit is in: `[table]`, or with `element` ≥ 0 that element (0 first) of the
/// array of tables `[[table]]`.
struct Target {
  std::string table;
  int element = -1;
  std::string name() const {
    return element < 0 ? fmt::format("[{}]", table) : fmt::format("[[{}]] #{}", table, element + 1);
  }
};

/// The text with the value replaced or the key added (`remove`: its line dropped); "" in `error`
/// when done.
std::string edit_lines(std::string_view text, const Target& target, std::string_view key,
                       std::string_view value, std::string& error, bool remove = false) {
  const std::vector<TomlLine> lines = detail::split_lines(text);
  std::size_t header = lines.size(), found = lines.size(), hits = 0;
  ValueSpan span;
  bool inside = false;
  int elements = 0;  // the [[table]] headers seen so far
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (detail::is_array_header(lines[i].text)) {
      inside = target.element >= 0 && detail::array_header_key(lines[i].text) == target.table &&
               elements++ == target.element;
      if (inside) header = i;
      continue;
    }
    if (const std::string h = detail::header_key(lines[i].text); !h.empty()) {
      inside = target.element < 0 && h == target.table;
      if (inside) header = i;
      continue;
    }
    if (!inside) continue;
    if (const auto s = value_span(lines[i].text, key)) {
      found = i;
      span = *s;
      ++hits;
    }
  }
  if (header == lines.size()) {
    error = fmt::format("the profile has no {} table of its own to edit {} in", target.name(), key);
    return {};
  }
  if (hits > 1) {
    error = fmt::format("{} is written more than once in {}", key, target.name());
    return {};
  }
  std::string out;
  if (found < lines.size()) {
    if (span.multi_line) {
      error = fmt::format("{} in {} spans more than one line in the profile: edit it by hand", key,
                          target.name());
      return {};
    }
    if (remove) {
      out.append(text.substr(0, lines[found].begin));
      out.append(text.substr(lines[found].end));
      return out;
    }
    out.append(text.substr(0, lines[found].begin + span.begin));
    out.append(value);
    out.append(text.substr(lines[found].begin + span.end));
    return out;
  }
  if (remove) {
    error = fmt::format("{} has no {} to remove", target.name(), key);
    return {};
  }
  const std::size_t end = detail::table_end(lines, header);
  const std::size_t at = end < lines.size() ? lines[end].begin : text.size();
  out.append(text.substr(0, at));
  if (!out.empty() && out.back() != '\n') out += '\n';
  out += fmt::format("{} = {}\n", key, value);
  out.append(text.substr(at));
  return out;
}

/// The table an edit of `target` changes in the parsed document `root` (`path`: the target's
/// table as components), or nullptr.
toml::table* target_table(toml::table& root, const std::vector<std::string>& path, const Target& target) {
  if (target.element < 0) return find_table(root, path);
  std::vector<std::string> parent(path.begin(), path.end() - 1);
  toml::table* t = find_table(root, parent);
  if (!t) return nullptr;
  for (auto&& [k, v] : *t) {
    toml::array* a = lower(k.str()) == path.back() ? v.as_array() : nullptr;
    if (a && static_cast<std::size_t>(target.element) < a->size())
      return (*a)[static_cast<std::size_t>(target.element)].as_table();
  }
  return nullptr;
}

/// `dotted_key` as the path of its table, the table's dotted name and the key; false (with `error`)
/// when it is not bare words inside a table.
bool parse_key(std::string_view dotted_key, std::vector<std::string>& path, std::string& table,
               std::string& key, std::string& error) {
  path = split_key(lower(dotted_key));
  for (const std::string& part : path) {
    if (part.empty() || !std::all_of(part.begin(), part.end(), bare_key_char)) {
      error = fmt::format("\"{}\" is not a dotted key of bare words", dotted_key);
      return false;
    }
  }
  if (path.size() < 2) {
    error = fmt::format("\"{}\" is not a key inside a table", dotted_key);
    return false;
  }
  key = path.back();
  path.pop_back();
  table = path.front();
  for (std::size_t i = 1; i < path.size(); ++i) table += "." + path[i];
  return true;
}

}  // namespace

std::string toml_number(double v) {
  std::string s = fmt::format("{}", v == 0 ? 0.0 : v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // "n": inf, nan
  return s;
}

namespace {

std::optional<std::string> remove_key(std::string_view text, const std::vector<std::string>& path,
                                      const Target& target, const std::string& key, std::string& error) {
  std::string out = edit_lines(text, target, key, {}, error, true);
  if (!error.empty()) return std::nullopt;
  try {  // the original less this one key, nothing else
    toml::table expected = toml::parse(text);
    const toml::table after = toml::parse(out);
    toml::table* t = target_table(expected, path, target);
    if (!t || !t->erase(key) || !(expected == after)) {
      error = fmt::format(
          "{} in {} is also set elsewhere in the profile (a dotted key or an inline table): edit it by hand",
          key, target.name());
      return std::nullopt;
    }
  } catch (const toml::parse_error& e) {
    error = fmt::format("the profile would not read back without {} in {}: {}", key, target.name(),
                        e.description());
    return std::nullopt;
  }
  return out;
}

std::optional<std::string> set_value(std::string_view text, const std::vector<std::string>& path,
                                     const Target& target, const std::string& key,
                                     std::string_view value_toml, std::string& error) {
  toml::table value_doc;
  try {
    value_doc = toml::parse(fmt::format("v = {}", value_toml));
  } catch (const toml::parse_error& e) {
    error = fmt::format("\"{}\" is not a TOML value: {}", value_toml, e.description());
    return std::nullopt;
  }
  if (value_doc.size() != 1 || value_toml.find('\n') != std::string_view::npos) {
    error = fmt::format("\"{}\" is not one TOML value on one line", value_toml);
    return std::nullopt;
  }
  std::string out = edit_lines(text, target, key, value_toml, error);
  if (!error.empty()) return std::nullopt;
  // The edit must read back as the original with this one value set, and nothing else changed.
  try {
    toml::table expected = toml::parse(text);
    const toml::table after = toml::parse(out);
    toml::table* t = target_table(expected, path, target);
    if (!t) {
      error = fmt::format("{} is not a table in the profile", target.name());
      return std::nullopt;
    }
    value_doc.get("v")->visit([&](auto& node) { t->insert_or_assign(key, node); });
    if (!(expected == after)) {
      error = fmt::format(
          "{} in {} is also set elsewhere in the profile (a dotted key or an inline table): edit it by hand",
          key, target.name());
      return std::nullopt;
    }
  } catch (const toml::parse_error& e) {
    error = fmt::format("the profile would not read back after setting {} in {}: {}", key, target.name(),
                        e.description());
    return std::nullopt;
  }
  return out;
}

/// `dotted_key` of a plain table as its path, target and key; false with `error`.
bool plain_target(std::string_view dotted_key, std::vector<std::string>& path, Target& target,
                  std::string& key, std::string& error) {
  return parse_key(dotted_key, path, target.table, key, error);
}

/// `array_key` ("edm.condition") and `key` as the path, target and key of element `element`.
bool element_target(std::string_view array_key, int element, std::string_view key,
                    std::vector<std::string>& path, Target& target, std::string& name, std::string& error) {
  if (element < 0) {
    error = fmt::format("element {} of [[{}]] does not exist", element + 1, array_key);
    return false;
  }
  if (!parse_key(fmt::format("{}.{}", array_key, key), path, target.table, name, error)) return false;
  target.element = element;
  return true;
}

}  // namespace

std::optional<std::string> without_toml_key(std::string_view text, std::string_view dotted_key,
                                            std::string& error) {
  std::vector<std::string> path;
  Target target;
  std::string key;
  if (!plain_target(dotted_key, path, target, key, error)) return std::nullopt;
  return remove_key(text, path, target, key, error);
}

std::optional<std::string> with_toml_value(std::string_view text, std::string_view dotted_key,
                                           std::string_view value_toml, std::string& error) {
  std::vector<std::string> path;
  Target target;
  std::string key;
  if (!plain_target(dotted_key, path, target, key, error)) return std::nullopt;
  return set_value(text, path, target, key, value_toml, error);
}

std::optional<std::string> with_toml_element_value(std::string_view text, std::string_view array_key,
                                                   int element, std::string_view key,
                                                   std::string_view value_toml, std::string& error) {
  std::vector<std::string> path;
  Target target;
  std::string name;
  if (!element_target(array_key, element, key, path, target, name, error)) return std::nullopt;
  return set_value(text, path, target, name, value_toml, error);
}

std::optional<std::string> without_toml_element_key(std::string_view text, std::string_view array_key,
                                                    int element, std::string_view key, std::string& error) {
  std::vector<std::string> path;
  Target target;
  std::string name;
  if (!element_target(array_key, element, key, path, target, name, error)) return std::nullopt;
  return remove_key(text, path, target, name, error);
}

}  // namespace opencnc::config
