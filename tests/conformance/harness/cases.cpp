// SPDX-License-Identifier: GPL-3.0-or-later
// Loading the conformance suite's tab-separated data files.
#include "cases.hpp"

#include <fstream>
#include <regex>
#include <stdexcept>

#include <fmt/format.h>

namespace opencnc::conformance {

namespace {

// Lines of a TSV file that are neither blank nor comments, with their line numbers.
template <typename F>
void for_each_row(const std::filesystem::path& path, F&& f) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    f(split_tabs(line), number);
  }
}

Expect parse_expect(const std::string& s, const std::string& where) {
  if (s == "accept") return Expect::Accept;
  if (s == "reject") return Expect::Reject;
  if (s == "run") return Expect::Run;
  if (s == "unsupported") return Expect::Unsupported;
  if (s == "excluded") return Expect::Excluded;
  throw std::runtime_error(where + ": unknown expect '" + s + "'");
}

}  // namespace

std::vector<std::string> split_tabs(std::string_view line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t tab = line.find('\t', start);
    fields.emplace_back(line.substr(start, tab == std::string_view::npos ? line.npos : tab - start));
    if (tab == std::string_view::npos) break;
    start = tab + 1;
  }
  return fields;
}

std::vector<Case> load_cases(const std::filesystem::path& path) {
  std::vector<Case> cases;
  for_each_row(path, [&](const std::vector<std::string>& f, int number) {
    const std::string where = fmt::format("{}:{}", path.string(), number);
    if (f.size() != 12) throw std::runtime_error(fmt::format("{}: {} fields, expected 12", where, f.size()));
    if (f[0] == "name") return;  // the header row
    cases.push_back({f[0], f[1], f[2], f[3], f[4], f[5], f[6], parse_expect(f[7], where), f[8], f[9], f[10], f[11]});
  });
  return cases;
}

struct ErrorCodeTable::Compiled {
  std::vector<std::regex> patterns;
};

ErrorCodeTable::ErrorCodeTable() : compiled_(std::make_unique<Compiled>()) {}
ErrorCodeTable::~ErrorCodeTable() = default;
ErrorCodeTable::ErrorCodeTable(ErrorCodeTable&&) noexcept = default;
ErrorCodeTable& ErrorCodeTable::operator=(ErrorCodeTable&&) noexcept = default;

ErrorCodeTable ErrorCodeTable::load(const std::filesystem::path& path) {
  ErrorCodeTable table;
  for_each_row(path, [&](const std::vector<std::string>& f, int number) {
    const std::string where = fmt::format("{}:{}", path.string(), number);
    if (f.size() != 3) throw std::runtime_error(where + ": expected pattern, code and description");
    if (!is_problem_code(f[1])) throw std::runtime_error(where + ": '" + f[1] + "' is not a problem code");
    try {
      table.compiled_->patterns.emplace_back(f[0], std::regex::extended);
    } catch (const std::regex_error& e) {
      throw std::runtime_error(where + ": bad pattern: " + e.what());
    }
    table.rows_.push_back({f[0], f[1], f[2]});
  });
  return table;
}

std::string ErrorCodeTable::code_for(std::string_view message) const {
  const std::string text(message);
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    if (std::regex_match(text, compiled_->patterns[i])) return rows_[i].code;
  }
  return {};
}

bool is_problem_code(std::string_view code) {
  static const std::regex form("[a-z]+(\\.[a-z0-9]+(-[a-z0-9]+)*)+");
  return std::regex_match(code.begin(), code.end(), form);
}

namespace {
bool is_code_char(char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '.' || ch == '-'; }
}  // namespace

bool mentions_code(std::string_view line, std::string_view code) {
  if (code.empty()) return false;
  for (std::size_t at = line.find(code); at != std::string_view::npos; at = line.find(code, at + 1)) {
    const bool left = at == 0 || !is_code_char(line[at - 1]);
    const std::size_t end = at + code.size();
    // A full stop right after the code ends a sentence; it does not continue the code.
    const bool right = end == line.size() || !is_code_char(line[end]) ||
                       (line[end] == '.' && (end + 1 == line.size() || !is_code_char(line[end + 1])));
    if (left && right) return true;
  }
  return false;
}

std::vector<Item> load_items(const std::filesystem::path& path) {
  std::vector<Item> items;
  for_each_row(path, [&](const std::vector<std::string>& f, int number) {
    if (f.size() != 3 || (f[1] != "yes" && f[1] != "no")) {
      throw std::runtime_error(fmt::format("{}:{}: expected item, yes/no, description", path.string(), number));
    }
    items.push_back({f[0], f[1] == "yes", f[2]});
  });
  return items;
}

std::vector<std::string> program_items(const std::filesystem::path& program) {
  std::ifstream in(program);
  std::string line;
  static const std::regex items_line("^[;(][ \t]*items:[ \t]*([^)\r]*)\\)?\r?$");
  for (int n = 0; n < 12 && std::getline(in, line); ++n) {
    std::smatch m;
    if (!std::regex_match(line, m, items_line)) continue;
    std::vector<std::string> items;
    const std::string list = m[1];
    std::size_t i = 0;
    while (i < list.size()) {
      while (i < list.size() && list[i] == ' ') ++i;
      const std::size_t b = i;
      while (i < list.size() && list[i] != ' ') ++i;
      if (i > b) items.push_back(list.substr(b, i - b));
    }
    return items;
  }
  return {};
}

}  // namespace opencnc::conformance
