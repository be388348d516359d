// SPDX-License-Identifier: GPL-3.0-or-later
// Blank removal, lower-casing and comment checks on one line of G-code.
#include "lexer.hpp"

#include <array>
#include <cstring>

#include "gcode_error.hpp"

namespace opencnc::gcode {

namespace {
bool is_c_space(char c) noexcept { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

std::string_view trim_raw_line(std::string_view raw) noexcept {
  while (!raw.empty() && is_c_space(raw.back())) raw.remove_suffix(1);
  return raw;
}

namespace {
// Normalisation of a byte outside comments: the byte it becomes and whether it is kept.
// ('(', ';' and NUL stop the fast loop.)
struct CharMap {
  std::array<char, 256> to{};
  std::array<unsigned char, 256> keep{};
  std::array<unsigned char, 256> stop{};
};
constexpr CharMap make_map() {
  CharMap m;
  for (int c = 0; c < 256; ++c) {
    m.to[static_cast<std::size_t>(c)] = static_cast<char>(c >= 'A' && c <= 'Z' ? c + ('a' - 'A') : c);
    m.keep[static_cast<std::size_t>(c)] = (c == ' ' || c == '\t' || c == '\r') ? 0 : 1;
  }
  m.stop[static_cast<unsigned char>('(')] = 1;
  m.stop[static_cast<unsigned char>(';')] = 1;
  m.stop[0] = 1;
  return m;
}
constexpr CharMap kMap = make_map();

// LinuxCNC reads lines as C strings, so a NUL byte silently cuts the rest of the line off
// (`G1 X1<NUL>Y2` moves X only). A NUL byte has no place in a program: the file is damaged or
// not text. `index` is the byte's place in the normalised line.
[[noreturn]] void nul_byte(std::size_t index) {
  fail_at(static_cast<int>(index), ErrorCode::BadCharacter,
          "a NUL byte (\\0) in the line: the file is damaged or not a text file");
}
}  // namespace

std::size_t normalize_line(std::string_view raw, char* out, bool nested_comments) {
  std::size_t n = 0;
  const std::size_t size = raw.size();
  for (std::size_t i = 0; i < size; ++i) {
    const auto u = static_cast<unsigned char>(raw[i]);
    if (!kMap.stop[u]) {
      // Branch-free: letters, digits and blanks alternate unpredictably in G-code.
      out[n] = kMap.to[u];
      n += kMap.keep[u];
      continue;
    }
    if (u == 0) nul_byte(n);
    if (u == ';') {
      // Everything after ';' is a comment and kept verbatim.
      if (const void* nul = std::memchr(raw.data() + i, '\0', size - i))
        nul_byte(n + static_cast<std::size_t>(static_cast<const char*>(nul) - (raw.data() + i)));
      std::memcpy(out + n, raw.data() + i, size - i);
      return n + (size - i);
    }
    // A ( ) comment: copied as is; '(' may not appear inside it unless comments nest.
    const int open = static_cast<int>(n);
    out[n++] = '(';
    int depth = 1;
    for (++i;; ++i) {
      if (i >= size)
        fail_at(open, ErrorCode::UnclosedComment,
                "this '(' opens a comment that is not closed on its line: add ')'");
      const char d = raw[i];
      if (d == '\0') nul_byte(n);
      if (d == '(') {
        if (!nested_comments)
          fail_at(static_cast<int>(n), ErrorCode::NestedComment, "'(' inside a comment: comments do not nest");
        ++depth;
      }
      out[n++] = d;
      if (d == ')' && --depth == 0) break;
    }
  }
  return n;
}

std::uint32_t raw_column(std::string_view raw, int index, bool nested_comments) noexcept {
  if (index < 0) return 0;
  int n = 0;
  int depth = 0;   // comment nesting (at most 1 unless comments nest)
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const char c = raw[i];
    const bool dropped = depth == 0 && (c == ' ' || c == '\t' || c == '\r');
    if (dropped) continue;
    if (n == index) return static_cast<std::uint32_t>(i + 1);
    if (depth == 0 && c == ';') return static_cast<std::uint32_t>(i + 1 + static_cast<std::size_t>(index - n));
    if (depth > 0 && c == ')') --depth;
    else if (c == '(' && (depth == 0 || nested_comments)) ++depth;
    ++n;
  }
  return static_cast<std::uint32_t>(raw.size() + 1);
}

bool leading_n_digits(std::string_view raw, std::string_view& digits) noexcept {
  std::size_t k = 0;
  while (k < raw.size() && (raw[k] == ' ' || raw[k] == '\t' || raw[k] == '/')) ++k;
  if (k >= raw.size() || (raw[k] != 'n' && raw[k] != 'N')) return false;
  const std::size_t start = ++k;
  while (k < raw.size() && raw[k] >= '0' && raw[k] <= '9') ++k;
  digits = raw.substr(start, k - start);
  return true;
}

}  // namespace opencnc::gcode
