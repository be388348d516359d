// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect's statements: GOTO n, IF [..] GOTO n, IF [..] THEN #i = .., WHILE [..] DO m,
// DO m, END m and G65 macro calls, read into Block::o_type like LinuxCNC's O-words.
#include <string_view>

#include "gcode_error.hpp"
#include "parser.hpp"
#include "variables.hpp"

namespace opencnc::gcode {

namespace {

bool is_digit(char c) noexcept {
  return c >= '0' && c <= '9';
}
bool starts_value(char c) noexcept {
  return is_digit(c) || c == '#' || c == '[';
}

// The local variable (1-based) a G65 argument letter sets (Fanuc's argument specification I);
// 0 for letters that are not arguments (G, L, N, O, P).
int argument_variable(char letter) noexcept {
  static constexpr int kVariable[26] = {1, 2, 3, 7,  8,  9,  0,  11, 4,  5,  6,  0,  13,
                                        0, 0, 0, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26};
  return kVariable[letter - 'a'];
}

}  // namespace

bool Parser::read_fanuc_statement(Cursor& c, Block& b) {
  const std::string_view rest = c.text.substr(c.pos);
  auto at = [&](std::size_t k) { return k < rest.size() ? rest[k] : '\0'; };
  if (rest.starts_with("goto")) {
    c.pos += 4;
    read_goto(c, b);
  } else if (rest.starts_with("if[")) {
    c.pos += 2;
    read_if(c, b);
  } else if (rest.starts_with("while[")) {
    c.pos += 5;
    read_while(c, b, true);
  } else if (rest.starts_with("do") && starts_value(at(2))) {
    c.pos += 2;
    read_while(c, b, false);
  } else if (rest.starts_with("end") && starts_value(at(3))) {
    c.pos += 3;
    b.o_type = OWord::FanucEnd;
    b.loop_id = loop_number(c);
    read_statement_tail(c, b);
  } else if (rest.starts_with("g65") && !is_digit(at(3)) && at(3) != '.') {
    c.pos += 3;
    read_macro_call(c, b);
  } else {
    return false;
  }
  return true;
}

// After a statement only comments may follow.
void Parser::read_statement_tail(Cursor& c, Block& b) {
  while (c.pos < c.text.size()) {
    if (c.at() == ';') return;
    if (c.at() != '(')
      fail_at(static_cast<int>(c.pos), ErrorCode::FanucStatementSyntax, "unexpected '{}' after the statement",
              c.at());
    read_comment(c, b);
  }
}

void Parser::read_goto(Cursor& c, Block& b) {
  const int pos = static_cast<int>(c.pos);
  const int target = integer_value(c, "a GOTO target");
  if (target < 1 || target > 99999)
    fail_at(pos, ErrorCode::FanucGotoTargetMissing, "GOTO {}: sequence numbers are 1..99999", target);
  b.o_type = OWord::Goto;
  b.o_value = target;
  read_statement_tail(c, b);
}

// IF [condition] GOTO n and IF [condition] THEN #i = value. The condition is evaluated while
// reading (as LinuxCNC evaluates O-word conditions); the rest of a false IF is not read.
void Parser::read_if(Cursor& c, Block& b) {
  const double condition = expression(c);
  const std::string_view rest = c.text.substr(c.pos);
  const bool holds = condition != 0.0;
  if (rest.starts_with("goto")) {
    c.pos += 4;
    if (holds) read_goto(c, b);
    return;
  }
  if (!rest.starts_with("then"))
    fail_at(static_cast<int>(c.pos), ErrorCode::FanucIfSyntax, "IF [..] must be followed by GOTO n or THEN");
  c.pos += 4;
  if (!holds) return;
  const int start = static_cast<int>(c.pos);
  while (c.pos < c.text.size()) {
    const char ch = c.at();
    if (ch == ';') break;
    if (ch == '(') {
      read_comment(c, b);
    } else if (ch == '#') {
      read_assignment(c);
    } else {
      fail_at(static_cast<int>(c.pos), ErrorCode::FanucIfSyntax,
              "only macro assignments (#i = ..) may follow THEN");
    }
  }
  if (numbered_assignments.empty() && named_assignments.empty())
    fail_at(start, ErrorCode::FanucIfSyntax, "THEN must be followed by an assignment (#i = ..)");
}

void Parser::read_while(Cursor& c, Block& b, bool with_condition) {
  double condition = 1.0;  // DO m alone loops until a GOTO leaves it
  if (with_condition) {
    condition = expression(c);
    if (!c.text.substr(c.pos).starts_with("do"))
      fail_at(static_cast<int>(c.pos), ErrorCode::FanucLoopStructure, "WHILE [..] must be followed by DO m");
    c.pos += 2;
  }
  b.o_type = OWord::FanucWhile;
  b.o_value = condition;
  b.o_has_value = true;
  b.loop_id = loop_number(c);
  read_statement_tail(c, b);
}

int Parser::loop_number(Cursor& c) {
  const int pos = static_cast<int>(c.pos);
  const int id = integer_value(c, "a loop number");
  if (id < 1 || id > 3)
    fail_at(pos, ErrorCode::FanucLoopStructure, "DO and END numbers are 1, 2 or 3 (not {})", id);
  return id;
}

// G65 P<program> L<count> with arguments: every other letter sets a local variable of the
// macro (A = #1, B = #2, C = #3, I = #4, J = #5, K = #6, D = #7, ... Z = #26). An argument
// whose value is a vacant variable is not passed.
void Parser::read_macro_call(Cursor& c, Block& b) {
  b.o_type = OWord::MacroCall;
  bool has_p = false;
  std::uint32_t seen = 0;
  while (c.pos < c.text.size()) {
    const char ch = c.at();
    const int pos = static_cast<int>(c.pos);
    if (ch == ';') break;
    if (ch == '(') {
      read_comment(c, b);
      continue;
    }
    if (ch < 'a' || ch > 'z') fail_at(pos, ErrorCode::BadCharacter, "unexpected '{}' in a G65 call", ch);
    const std::uint32_t bit = 1u << (ch - 'a');
    if ((seen & bit) != 0)
      fail_at(pos, ErrorCode::RepeatedWord, "more than one {} word on the line", static_cast<char>(ch - 32));
    seen |= bit;
    ++c.pos;
    if (ch == 'p') {
      const int program = integer_value(c, "P");
      if (program < 1)
        fail_at(pos, ErrorCode::FanucCallProgramMissing, "G65 P{}: program numbers start at 1", program);
      b.o_value = program;
      has_p = true;
    } else if (ch == 'l') {
      b.repeat = integer_value(c, "L");
      if (b.repeat < 0) fail_at(pos, ErrorCode::LWordNegative, "L word must not be negative");
    } else if (const int var = argument_variable(ch); var != 0) {
      const double v = real_value(c);
      if (value_vacant_) continue;
      b.args[static_cast<std::size_t>(var - 1)] = v;
      b.arg_given |= 1u << (var - 1);
    } else {
      fail_at(pos, ErrorCode::UnusedWord, "{} is not a G65 argument (arguments are A-Z except G, L, N, O, P)",
              static_cast<char>(ch - 32));
    }
  }
  if (!has_p) fail(ErrorCode::FanucCallProgramMissing, "G65 needs P (the macro's program number)");
}

// Assignments the Fanuc variable map refuses: #0, variables that do not exist, read-only and
// unavailable system variables.
void Parser::check_fanuc_assignment(int index, int pos) const {
  if (index < 0 || index >= kParameterCount)
    fail_at(pos, ErrorCode::ParameterOutOfRange, "variable #{} does not exist", index);
  switch (fanuc_variable_kind(index)) {
    case FanucVariable::Null:
      fail_at(pos, ErrorCode::FanucReadOnlyVariable,
              "#0 is the null variable: it is always vacant and cannot be set");
    case FanucVariable::Missing:
      fail_at(pos, ErrorCode::ParameterOutOfRange,
              "variable #{} does not exist (locals are #1-#33, common variables #100-#999)", index);
    case FanucVariable::Computed:
      fail_at(pos, ErrorCode::FanucReadOnlyVariable, "system variable #{} is read-only", index);
    case FanucVariable::Unavailable:
      fail_at(pos, ErrorCode::FanucVariableUnavailable, "system variable #{} is not available here", index);
    default:
      return;
  }
}

}  // namespace opencnc::gcode
