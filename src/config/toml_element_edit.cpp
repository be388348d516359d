// SPDX-License-Identifier: GPL-3.0-or-later
// A whole element of an array of tables ([[edm.condition]]) appended as a copy of another or
// removed, in place; the result is checked against the parsed original with only that change.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <vector>

#include "opencnc/config/toml_edit.hpp"
#include "toml_lines.hpp"

namespace opencnc::config {

namespace {

using detail::TomlLine;

bool bare_key_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
}

/// The header lines of the elements of `array_key` (lower case), in the file's order.
std::vector<std::size_t> element_headers(const std::vector<TomlLine>& lines, std::string_view array_key) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (detail::is_array_header(lines[i].text) && detail::array_header_key(lines[i].text) == array_key)
      out.push_back(i);
  return out;
}

/// The array `array_key` of the parsed document (its components compared as written), or nullptr.
toml::array* find_array(toml::table& root, std::string_view array_key) {
  toml::table* t = &root;
  std::string_view rest = array_key;
  while (true) {
    const std::size_t dot = rest.find('.');
    const std::string_view part = rest.substr(0, dot);
    toml::node* n = t->get(part);
    if (dot == std::string_view::npos) return n != nullptr ? n->as_array() : nullptr;
    t = n != nullptr ? n->as_table() : nullptr;
    if (t == nullptr) return nullptr;
    rest.remove_prefix(dot + 1);
  }
}

/// The bare key a `key = value` line assigns ("" for any other line: a comment, a dotted or
/// quoted key, the rest of a value that spans lines).
std::string_view line_key(std::string_view line) {
  const std::string_view t = detail::trim(line);
  std::size_t end = 0;
  while (end < t.size() && bare_key_char(t[end])) ++end;
  if (end == 0) return {};
  const std::string_view after = detail::trim(t.substr(end));
  return !after.empty() && after[0] == '=' ? t.substr(0, end) : std::string_view{};
}

/// A TOML basic string of `s`.
std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\')
      out += fmt::format("\\{}", c);
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
    else
      out += c;
  }
  return out + "\"";
}

/// The value of `node` as TOML text on one line; "" for a kind a copy does not write (an array,
/// a table, a date).
std::string value_text(const toml::node& node) {
  if (const auto* v = node.as_floating_point()) return toml_number(v->get());
  if (const auto* v = node.as_integer()) return std::to_string(v->get());
  if (const auto* v = node.as_boolean()) return v->get() ? "true" : "false";
  if (const auto* v = node.as_string()) return toml_string(v->get());
  return {};
}

/// The copy's lines: `header` (as written, without its comment), then each key of `element` in
/// the order the source's lines give them (`lines`), with `key` set to `value_toml`; a key of the
/// element that no line names (written elsewhere) comes last. False with `error`.
bool copy_lines(std::string_view header, const std::vector<TomlLine>& lines, const toml::table& element,
                std::string_view key, std::string_view value_toml, std::string& out, std::string& error) {
  out += fmt::format("{}\n", header);
  std::vector<std::string> written;
  auto write = [&](std::string_view k, const toml::node& v) {
    const std::string text = k == key ? std::string(value_toml) : value_text(v);
    if (text.empty()) {
      error = fmt::format("{} is not a number, a word or a switch: copy the element by hand", k);
      return false;
    }
    out += fmt::format("{} = {}\n", k, text);
    written.emplace_back(k);
    return true;
  };
  for (const TomlLine& l : lines) {
    const std::string_view k = line_key(l.text);
    const toml::node* v = k.empty() ? nullptr : element.get(k);
    if (v == nullptr || std::find(written.begin(), written.end(), k) != written.end()) continue;
    if (!write(k, *v)) return false;
  }
  for (auto&& [k, v] : element)
    if (std::find(written.begin(), written.end(), k.str()) == written.end() && !write(k.str(), v))
      return false;
  if (std::find(written.begin(), written.end(), key) == written.end())
    out += fmt::format("{} = {}\n", key, value_toml);
  return true;
}

/// `text` parsed, or nullopt with `error`.
std::optional<toml::table> parsed(std::string_view text, std::string_view what, std::string& error) {
  try {
    return toml::parse(text);
  } catch (const toml::parse_error& e) {
    error = fmt::format("{}: {}", what, e.description());
    return std::nullopt;
  }
}

// The profile's lines, its [[array]] headers and its tables as parsed. The edits below change
// the tables as they mean to change the text, and the text must then read back as them.
struct ElementText {
  std::vector<TomlLine> lines;
  std::vector<std::size_t> headers;
  toml::table expected;
  toml::array* array = nullptr;  // in `expected`
};

/// Reads `text` into `e`, checking that element `element` of [[array_key]] is a table written under
/// a header of its own; false with `error` if not.
bool open_element(std::string_view text, std::string_view array_key, int element, ElementText& e,
                  std::string& error) {
  e.lines = detail::split_lines(text);
  e.headers = element_headers(e.lines, array_key);
  std::optional<toml::table> tables = parsed(text, "the profile does not read", error);
  if (!tables) return false;
  e.expected = std::move(*tables);
  e.array = find_array(e.expected, array_key);
  if (e.array == nullptr || element < 0 || static_cast<std::size_t>(element) >= e.headers.size() ||
      e.headers.size() != e.array->size() || !(*e.array)[static_cast<std::size_t>(element)].is_table()) {
    error = fmt::format("element {} of [[{}]] is not written under a [[{}]] header of its own", element + 1,
                        array_key, array_key);
    return false;
  }
  return true;
}

/// True if `out` reads back as `e.expected`; else false with `error` (`mismatch` if it reads).
bool reads_back(const std::string& out, const ElementText& e, std::string_view what, std::string mismatch,
                std::string& error) {
  const std::optional<toml::table> after = parsed(out, what, error);
  if (!after) return false;
  if (!(e.expected == *after)) {
    error = std::move(mismatch);
    return false;
  }
  return true;
}

}  // namespace

std::optional<std::string> with_toml_element_copy(std::string_view text, std::string_view array_key,
                                                  int element, std::string_view key,
                                                  std::string_view value_toml, std::string_view comment,
                                                  std::string& error) {
  ElementText e;
  if (!open_element(text, array_key, element, e, error)) return std::nullopt;
  const std::vector<TomlLine>& lines = e.lines;
  toml::array* array = e.array;
  const std::optional<toml::table> value_doc =
      parsed(fmt::format("v = {}", value_toml), "not a TOML value", error);
  if (!value_doc || value_toml.find('\n') != std::string_view::npos) {
    error = fmt::format("\"{}\" is not one TOML value on one line", value_toml);
    return std::nullopt;
  }
  const std::size_t from = e.headers[static_cast<std::size_t>(element)];
  const std::size_t from_end = detail::table_end(lines, from);
  std::string_view header = lines[from].text.substr(0, lines[from].text.find('#'));
  const std::vector<TomlLine> body(lines.begin() + static_cast<std::ptrdiff_t>(from + 1),
                                   lines.begin() + static_cast<std::ptrdiff_t>(from_end));
  std::string copy = "\n";
  if (!comment.empty()) copy += fmt::format("# {}\n", comment);
  toml::table element_copy = *(*array)[static_cast<std::size_t>(element)].as_table();
  if (!copy_lines(detail::trim(header), body, element_copy, key, value_toml, copy, error))
    return std::nullopt;
  // After the array's last element, before whatever comments lead into the next table.
  const std::size_t end = detail::table_end(lines, e.headers.back());
  const std::size_t at = end < lines.size() ? lines[end].begin : text.size();
  std::string out(text.substr(0, at));
  if (!out.empty() && out.back() != '\n') out += '\n';
  out += copy;
  out.append(text.substr(at));
  // The original with this one element appended, and nothing else changed.
  value_doc->get("v")->visit([&](auto& node) { element_copy.insert_or_assign(key, node); });
  array->push_back(std::move(element_copy));
  if (!reads_back(out, e, "the copy would not read back",
                  fmt::format("a copy of element {} of [[{}]] would not read back as written: copy it by hand",
                              element + 1, array_key),
                  error))
    return std::nullopt;
  return out;
}

std::optional<std::string> without_toml_element(std::string_view text, std::string_view array_key,
                                                int element, std::string& error) {
  ElementText e;
  if (!open_element(text, array_key, element, e, error)) return std::nullopt;
  const std::vector<TomlLine>& lines = e.lines;
  // The element's lines, the comment right above its header (what it is) and the blank line before.
  const std::size_t header = e.headers[static_cast<std::size_t>(element)];
  const std::size_t end = detail::table_end(lines, header);
  std::size_t begin = header;
  while (begin > 0 && !detail::trim(lines[begin - 1].text).empty() &&
         detail::is_blank_or_comment(lines[begin - 1].text))
    --begin;
  if (begin > 0 && detail::trim(lines[begin - 1].text).empty()) --begin;
  const std::size_t from = lines[begin].begin;
  const std::size_t to = end < lines.size() ? lines[end].begin : text.size();
  std::string out(text.substr(0, from));
  out.append(text.substr(to));
  e.array->erase(e.array->begin() + element);
  if (!reads_back(out, e, "the profile would not read back",
                  fmt::format("element {} of [[{}]] is also written elsewhere in the profile: remove it by hand",
                              element + 1, array_key),
                  error))
    return std::nullopt;
  return out;
}

}  // namespace opencnc::config
