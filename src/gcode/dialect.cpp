// SPDX-License-Identifier: GPL-3.0-or-later
// Dialect names, dialect markers in programs, and the lathe-or-mill guess for Fanuc programs.
#include "opencnc/gcode/dialect.hpp"

#include <cstdint>
#include <fstream>
#include <sstream>

#include "opencnc/core/atomic_file.hpp"

namespace opencnc::gcode {

namespace {

/// The first `bytes` of a program file, read only from a regular file (a FIFO would block, a
/// device such as /dev/zero never end): these guesses look at the head of a program; the
/// program itself is read by SourceFile, which says what is wrong with the file.
std::istringstream program_head(const std::string& path, std::size_t bytes) {
  std::string head;
  if (unreadable_input(path, SIZE_MAX).empty()) {
    std::ifstream in(path, std::ios::binary);
    head.resize(bytes);
    in.read(head.data(), static_cast<std::streamsize>(bytes));
    head.resize(static_cast<std::size_t>(in.gcount()));
  }
  return std::istringstream(head);
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }

}  // namespace

std::optional<Dialect> dialect_from_name(std::string_view name) noexcept {
  if (name.size() == 8 && lower(name) == "linuxcnc") return Dialect::LinuxCnc;
  if (name.size() == 5 && lower(name) == "fanuc") return Dialect::Fanuc;
  return std::nullopt;
}

std::string_view dialect_name(Dialect dialect) noexcept { return dialect == Dialect::Fanuc ? "fanuc" : "linuxcnc"; }

std::optional<MachineKind> machine_kind_from_name(std::string_view name) noexcept {
  if (name.size() == 4 && lower(name) == "mill") return MachineKind::Mill;
  if (name.size() == 5 && lower(name) == "lathe") return MachineKind::Lathe;
  return std::nullopt;
}

std::optional<Dialect> dialect_marker(const std::string& path) {
  std::istringstream in = program_head(path, 64 << 10);
  std::string line;
  for (int n = 0; n < 20 && std::getline(in, line); ++n) {
    const std::string text = lower(line);
    std::size_t at = text.find("dialect");
    if (at == std::string::npos) continue;
    const std::size_t comment = text.find_first_of("(;");
    if (comment == std::string::npos || comment > at) continue;   // only inside a comment
    at += 7;
    while (at < text.size() && (text[at] == ' ' || text[at] == ':' || text[at] == '=')) ++at;
    std::size_t end = at;
    while (end < text.size() && text[end] >= 'a' && text[end] <= 'z') ++end;
    if (auto d = dialect_from_name(std::string_view(text).substr(at, end - at))) return d;
  }
  return std::nullopt;
}

MachineKind guess_machine_kind(const std::string& path) {
  std::istringstream in = program_head(path, 4 << 20);
  std::string line;
  bool x = false, z = false;
  while (std::getline(in, line)) {
    int comment = 0;   // nesting depth (Fanuc comments may nest)
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (comment > 0 || c == '(') {
        comment += c == '(' ? 1 : c == ')' ? -1 : 0;
        continue;
      }
      if (c == ';') break;
      // An axis word: the letter, then a number, a sign, a bracket or a variable.
      const char next = i + 1 < line.size() ? line[i + 1] : '\0';
      if (!(is_digit(next) || next == '.' || next == '-' || next == '+' || next == '[' || next == '#' || next == ' ')) continue;
      const bool letter_before = i > 0 && ((line[i - 1] >= 'a' && line[i - 1] <= 'z') || (line[i - 1] >= 'A' && line[i - 1] <= 'Z'));
      if (letter_before) continue;   // part of a keyword (GOTO, WHILE, ...)
      switch (c) {
        case 'Y': case 'y': return MachineKind::Mill;
        case 'X': case 'x': case 'U': case 'u': x = true; break;
        case 'Z': case 'z': z = true; break;
        default: break;
      }
    }
  }
  return x && z ? MachineKind::Lathe : MachineKind::Mill;
}

}  // namespace opencnc::gcode
