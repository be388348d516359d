// SPDX-License-Identifier: GPL-3.0-or-later
// Reading Fanuc program files for their program lines, sequence numbers and loop statements.
#include "index.hpp"

#include "lexer.hpp"

namespace opencnc::gcode {

namespace {

bool is_digit(char c) noexcept {
  return c >= '0' && c <= '9';
}
bool is_blank(char c) noexcept {
  return c == ' ' || c == '\t' || c == '\r';
}

std::string_view skip_blanks(std::string_view s) noexcept {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  return s;
}

// The line without blanks, lower case, comments dropped (enough to recognise statements).
void squeeze(std::string_view raw, std::string& out) {
  out.clear();
  int comment = 0;  // nesting depth
  for (char c : raw) {
    if (comment > 0) {
      comment += c == '(' ? 1 : c == ')' ? -1 : 0;
      continue;
    }
    if (c == '(') {
      comment = 1;
    } else if (c == ';') {
      break;
    } else if (!is_blank(c)) {
      out += (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
    }
  }
}

// "while[...]doM", "doM" or "endM" after an optional '/' and N word: the loop number, or 0.
int loop_statement(std::string_view s, bool& end) {
  if (!s.empty() && s.front() == '/') s.remove_prefix(1);
  if (!s.empty() && s.front() == 'n') {
    s.remove_prefix(1);
    while (!s.empty() && (is_digit(s.front()) || s.front() == '.')) s.remove_prefix(1);
  }
  end = false;
  if (s.starts_with("while[")) {
    int depth = 0;
    std::size_t i = 5;
    for (; i < s.size(); ++i) {
      if (s[i] == '[') ++depth;
      if (s[i] == ']' && --depth == 0) break;
    }
    s.remove_prefix(i < s.size() ? i + 1 : s.size());
    if (!s.starts_with("do")) return 0;
    s.remove_prefix(2);
  } else if (s.starts_with("do") && s.size() > 2 && is_digit(s[2])) {
    s.remove_prefix(2);
  } else if (s.starts_with("end") && s.size() > 3 && is_digit(s[3])) {
    s.remove_prefix(3);
    end = true;
  } else {
    return 0;
  }
  int id = 0;
  while (!s.empty() && is_digit(s.front()) && id < 1000) {
    id = id * 10 + (s.front() - '0');
    s.remove_prefix(1);
  }
  return id;
}

}  // namespace

std::optional<std::uint32_t> fanuc_program_number(std::string_view raw) noexcept {
  std::string_view s = skip_blanks(raw);
  if (!s.empty() && s.front() == '%') s.remove_prefix(1);
  if (s.empty() || (s.front() != 'O' && s.front() != 'o' && s.front() != ':')) return std::nullopt;
  s.remove_prefix(1);
  if (s.empty() || !is_digit(s.front())) return std::nullopt;
  std::uint64_t n = 0;
  while (!s.empty() && is_digit(s.front())) {
    n = n * 10 + static_cast<std::uint64_t>(s.front() - '0');
    if (n > 99999999) return std::nullopt;
    s.remove_prefix(1);
  }
  s = skip_blanks(s);
  if (!s.empty() && s.front() != '(' && s.front() != ';') return std::nullopt;
  return static_cast<std::uint32_t>(n);
}

const std::vector<FanucIndex::Program>& FanucIndex::programs(std::uint32_t file, SourceFile& source) {
  auto [it, fresh] = programs_.try_emplace(file);
  if (!fresh) return it->second;
  source.seek(0);
  RawLine line;
  std::uint32_t number = 0;
  while (source.next(line)) {
    ++number;
    if (const auto n = fanuc_program_number(line.text))
      it->second.push_back({*n, {file, line.offset, number}});
  }
  return it->second;
}

const FanucIndex::Region& FanucIndex::region(const SourcePosition& start, SourceFile& source) {
  auto [it, fresh] = regions_.try_emplace(std::make_pair(start.file, start.offset));
  Region& r = it->second;
  if (!fresh) return r;
  source.seek(start.offset);
  RawLine line;
  std::uint32_t number = start.line;
  bool code = false;  // a line other than comments and the program's own number was met
  for (; source.next(line); ++number) {
    const std::string_view text = trim_raw_line(line.text);
    const std::string_view lead = skip_blanks(text);
    if (lead.empty()) continue;
    if (fanuc_program_number(lead)) {
      if (code) break;  // the next program
      code = true;      // its own number
      continue;
    }
    if (lead == "%") {
      if (code) break;
      continue;
    }
    if (lead.front() == '(' || lead.front() == ';') continue;
    code = true;
    const SourcePosition here{start.file, line.offset, number};
    std::string_view digits;
    if (leading_n_digits(text, digits) && !digits.empty() && digits.size() <= 18) {
      std::int64_t n = 0;
      for (char c : digits) n = n * 10 + (c - '0');
      r.first_n.try_emplace(n, here);
    }
    squeeze(text, scratch_);
    bool end = false;
    if (const int id = loop_statement(scratch_, end); id != 0)
      r.loops.push_back({here, {start.file, source.tell(), number + 1}, id, end});
  }
  return r;
}

}  // namespace opencnc::gcode
