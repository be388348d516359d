// SPDX-License-Identifier: GPL-3.0-or-later
// Words, numbers, expressions and O-words of one block, read as LinuxCNC reads them.
#include "parser.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>

#include "gcode_error.hpp"
#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

namespace {

// Binary operators; the precedence of each is below.
enum Op : int {
  kRightBracket, kPower, kTimes, kDivide, kModulo, kPlus, kMinus,
  kLt, kEq, kNe, kLe, kGe, kGt, kAnd, kXor, kOr
};

int precedence(int op) noexcept {
  switch (op) {
    case kRightBracket: return 1;
    case kAnd: case kXor: case kOr: return 2;
    case kLt: case kEq: case kNe: case kLe: case kGe: case kGt: return 3;
    case kPlus: case kMinus: return 4;
    case kTimes: case kDivide: case kModulo: return 5;
    case kPower: return 6;
    default: return 0;
  }
}

// Two numbers compare equal in G-code when they differ by less than this (LinuxCNC's rule).
constexpr double kEqualTolerance = 1e-4;
constexpr long double kPi = 3.141592653589793238462643383279502884L;

double apply_binary(double a, int op, double b, int pos) {
  switch (op) {
    case kPlus: return a + b;
    case kMinus: return a - b;
    case kTimes: return a * b;
    case kDivide:
      if (b == 0.0) fail_at(pos, ErrorCode::DivideByZero, "division by zero: {} / 0", a);
      return a / b;
    case kModulo: {
      // The result takes the sign of the divisor's magnitude: always >= 0 (LinuxCNC).
      double r = std::fmod(a, b);
      if (r < 0.0) r += std::fabs(b);
      return r;
    }
    case kPower:
      if (a < 0.0 && std::floor(b) != b)
        fail_at(pos, ErrorCode::PowerDomain,
                "{} ** {}: a negative number has no power with a fractional exponent", a, b);
      return std::pow(a, b);
    case kAnd: return (a == 0.0 || b == 0.0) ? 0.0 : 1.0;
    case kOr: return (a != 0.0 || b != 0.0) ? 1.0 : 0.0;
    case kXor: return ((a == 0.0) != (b == 0.0)) ? 1.0 : 0.0;
    case kLt: return a < b ? 1.0 : 0.0;
    case kGt: return a > b ? 1.0 : 0.0;
    case kEq: return std::fabs(a - b) < kEqualTolerance ? 1.0 : 0.0;
    case kNe: return std::fabs(a - b) >= kEqualTolerance ? 1.0 : 0.0;
    case kLe: return a <= b ? 1.0 : 0.0;   // rs274 2.9: no tolerance, unlike EQ and NE
    case kGe: return a >= b ? 1.0 : 0.0;
    default: return 0.0;
  }
}

bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }

bool starts_with(std::string_view text, std::size_t pos, std::string_view prefix) noexcept {
  return text.substr(pos, prefix.size()) == prefix;
}

enum Unary { kAbs, kAcos, kAsin, kAtan, kCos, kExp, kExists, kFix, kFup, kLn, kRound, kSin, kSqrt, kTan };

double apply_unary(int op, double x, int pos) {
  const long double xl = x;
  switch (op) {
    case kAbs: return std::fabs(x);
    case kAcos:
      if (x < -1.0 || x > 1.0)
        fail_at(pos, ErrorCode::TrigDomain, "ACOS[{}]: the argument must lie within -1..1", x);
      return static_cast<double>(std::acos(x) * 180.0L / kPi);
    case kAsin:
      if (x < -1.0 || x > 1.0)
        fail_at(pos, ErrorCode::TrigDomain, "ASIN[{}]: the argument must lie within -1..1", x);
      return static_cast<double>(std::asin(x) * 180.0L / kPi);
    case kCos: return static_cast<double>(std::cos(xl * kPi / 180.0L));
    case kSin: return static_cast<double>(std::sin(xl * kPi / 180.0L));
    case kTan: return static_cast<double>(std::tan(xl * kPi / 180.0L));
    case kExp: return std::exp(x);
    case kFix: return std::floor(x);
    case kFup: return std::ceil(x);
    case kLn:
      if (x <= 0.0)
        fail_at(pos, ErrorCode::LnNonPositive, "LN[{}]: the logarithm needs an argument greater than 0", x);
      return std::log(x);
    case kRound: {
      // LinuxCNC rounds half away from zero through an int.
      const double r = x + (x < 0.0 ? -0.5 : 0.5);
      if (!(std::fabs(r) < 2147483647.0)) return std::trunc(r);
      return static_cast<double>(static_cast<int>(r));
    }
    case kSqrt:
      if (x < 0.0) fail_at(pos, ErrorCode::SqrtNegative, "SQRT[{}]: the square root of a negative number", x);
      return std::sqrt(x);
    default: return x;
  }
}

std::string describe_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u < 0x21 || u > 0x7e) return fmt::format("\\{:03o}", static_cast<unsigned>(u));
  return std::string(1, c);
}

// Positions kept in a Block are bytes; lines are shorter than that (kMaxLineLength).
std::uint8_t position_byte(std::size_t pos) noexcept {
  return static_cast<std::uint8_t>(pos < 255 ? pos : 255);
}

constexpr std::string_view kAxisLetters = "xyzabcuvw";
constexpr std::string_view kOwordKeywords =
    "sub endsub call return do while endwhile repeat endrepeat if elseif else endif break continue";

// "X Y Z A B C": the axis letters a line may use.
std::string axis_list(std::uint32_t letters) {
  std::string s;
  for (char a : kAxisLetters) {
    if (!((letters >> (a - 'a')) & 1u)) continue;
    if (!s.empty()) s += ' ';
    s += static_cast<char>(a - 'a' + 'A');
  }
  return s;
}

const char* g_group_name(int group) noexcept {
  switch (group) {
    case kGroupNonModal:
      return "non-modal";
    case kGroupMotion:
      return "motion";
    case kGroupPlane:
      return "plane selection";
    case kGroupDistance:
      return "distance mode";
    case kGroupIjkDistance:
      return "arc centre distance mode";
    case kGroupFeedMode:
      return "feed mode";
    case kGroupUnits:
      return "units";
    case kGroupCutterComp:
      return "cutter compensation";
    case kGroupToolLength:
      return "tool length offset";
    case kGroupRetract:
      return "canned cycle return";
    case kGroupCoordSystem:
      return "coordinate system";
    case kGroupControl:
      return "path control";
    case kGroupSpindleMode:
      return "spindle speed mode";
    case kGroupLatheDiameter:
      return "lathe diameter mode";
    default:
      return "?";
  }
}

const char* m_group_name(int group) noexcept {
  switch (group) {
    case kGroupStop:
      return "stopping";
    case kGroupIo:
      return "input/output";
    case kGroupToolChange:
      return "tool change";
    case kGroupSpindle:
      return "spindle";
    case kGroupCoolant:
      return "coolant";
    case kGroupOverride:
      return "override";
    case kGroupUser:
      return "user-defined";
    default:
      return "?";
  }
}

}  // namespace

namespace {

constexpr int g_group_by_switch(int code) noexcept {
  switch (code) {
    case 0: case 10: case 20: case 30: case 50: case 51: case 52: case 330: case 331:
    case 382: case 383: case 384: case 385: case 700: case 710: case 711: case 712: case 720:
    case 721: case 722: case 730: case 740: case 760: case 800: case 810: case 820: case 830:
    case 840: case 850: case 860: case 870: case 880: case 890:
      return kGroupMotion;
    case 40: case 53: case 100: case 280: case 281: case 300: case 301: case 520: case 530:
    case 920: case 921: case 922: case 923:
      return kGroupNonModal;
    case 70: case 80: return kGroupLatheDiameter;
    case 170: case 171: case 180: case 181: case 190: case 191: return kGroupPlane;
    case 200: case 210: return kGroupUnits;
    case 400: case 410: case 411: case 420: case 421: return kGroupCutterComp;
    case 430: case 431: case 432: case 490: return kGroupToolLength;
    case 540: case 550: case 560: case 570: case 580: case 590: case 591: case 592: case 593:
      return kGroupCoordSystem;
    case 610: case 611: case 640: return kGroupControl;
    case 900: case 910: return kGroupDistance;
    case 901: case 911: return kGroupIjkDistance;
    case 930: case 940: case 950: return kGroupFeedMode;
    case 960: case 970: return kGroupSpindleMode;
    case 980: case 990: return kGroupRetract;
    default: return -1;
  }
}

// The switch above as a table (read once per G word).
constexpr auto kGGroups = [] {
  std::array<std::int8_t, 1000> t{};
  for (int code = 0; code < 1000; ++code) t[static_cast<std::size_t>(code)] = static_cast<std::int8_t>(g_group_by_switch(code));
  return t;
}();

}  // namespace

int g_group(int code) noexcept {
  return code >= 0 && code < 1000 ? kGGroups[static_cast<std::size_t>(code)] : -1;
}

std::string g_name(int code) {
  return code % 10 ? fmt::format("G{}.{}", code / 10, code % 10) : fmt::format("G{}", code / 10);
}

int m_group(int code) noexcept {
  switch (code) {
    case 0: case 1: case 2: case 30: case 60: case 99: return kGroupStop;
    case 62: case 63: case 64: case 65: case 66: case 67: case 68: return kGroupIo;
    case 6: case 61: return kGroupToolChange;
    case 3: case 4: case 5: case 19: case 70: case 71: case 72: case 73: return kGroupSpindle;
    case 7: case 8: case 9: return kGroupCoolant;
    case 48: case 49: case 50: case 51: case 52: case 53: return kGroupOverride;
    default: return (code >= 100 && code <= 199) ? kGroupUser : -1;
  }
}

void Parser::parse(std::string_view text, const ParseEnv& env, Block& b) {
  b.clear();
  numbered_assignments.clear();
  named_assignments.clear();
  vacant_assignments.clear();
  Cursor c{text, 0, env};
  if (c.at() == '/') ++c.pos;
  const bool numbered = env.syntax.numbered_programs;
  // Numbered programs: "O1000", ":1000" and "%O1000" on the first line of a file.
  if (numbered && c.at() == '%' && (c.at(1) == 'o' || c.at(1) == ':')) ++c.pos;
  if (c.at() == 'n') read_line_number(c, b);

  if (numbered) {
    if (read_fanuc_statement(c, b)) return;
  } else if (read_numbered_statement(c, b)) {
    return;
  }

  if (c.at() == 'o' || (numbered && c.at() == ':')) {
    read_o_word(c, b);
    if (!env.skipping_to.empty()) return;
    while (c.pos < text.size()) {
      if (c.at() == ';') break;
      if (c.at() == '(') {
        read_comment(c, b);
        continue;
      }
      std::size_t end = c.pos + 1;
      while (end < text.size() && (is_digit(text[end]) || text[end] == '.')) ++end;
      std::string word(text.substr(c.pos, end - c.pos));
      if (word[0] >= 'a' && word[0] <= 'z') word[0] = static_cast<char>(word[0] - 'a' + 'A');
      fail_at(static_cast<int>(c.pos), ErrorCode::OwordSyntax,
              "{} after the O-word statement: an O-word line holds only the statement and comments, so put "
              "it on a line "
              "of its own",
              word);
    }
    return;
  }
  if (!env.skipping_to.empty()) return;   // skipped lines are not evaluated
  while (c.pos < text.size()) read_item(c, b);
}

// LinuxCNC's numbered subprograms: a line that starts with M98 is a call, one that starts
// with M99 inside a subprogram its return (M99 in the main program is an M code of the stop
// group). Lines passed over are not read, as in LinuxCNC. The call's line is read as any
// block (P, L and comments; the checks refuse the rest), the return's holds only comments.
bool Parser::read_numbered_statement(Cursor& c, Block& b) {
  if (c.at() != 'm' || !c.env.skipping_to.empty()) return false;
  const bool ret = starts_with(c.text, c.pos + 1, "99") && c.env.call_level > 0;
  if (!starts_with(c.text, c.pos + 1, "98") && !ret) return false;
  Cursor probe{c.text, c.pos + 1, c.env};
  const int m = integer_value(probe, "an M code");
  if (m != 98 && !(m == 99 && ret)) return false;
  b.o_at = position_byte(c.pos);
  c.pos = probe.pos;
  if (m == 98) {
    b.o_type = OWord::M98;
    while (c.pos < c.text.size()) read_item(c, b);
    return true;
  }
  b.o_type = OWord::M99;
  b.o_name.assign(c.env.call_sub);
  while (c.pos < c.text.size()) {
    if (c.at() == ';') break;
    if (c.at() == '(') {
      read_comment(c, b);
      continue;
    }
    const char ch = c.at();
    fail_at(static_cast<int>(c.pos), ErrorCode::OwordSyntax,
            "'{}' after M99: a subprogram's M99 line holds only M99 and comments",
            ch >= 'a' && ch <= 'z' ? static_cast<char>(ch - 'a' + 'A') : ch);
  }
  return true;
}

void Parser::read_line_number(Cursor& c, Block& b) {
  ++c.pos;
  const std::size_t start = c.pos;
  std::int64_t n = 0;
  while (is_digit(c.at())) {
    if (c.pos - start < 18) n = n * 10 + (c.at() - '0');
    ++c.pos;
  }
  if (c.pos == start)
    fail_at(static_cast<int>(start), ErrorCode::BadLineNumber,
            "N without digits: a line number is N followed by digits");
  b.n_number = c.pos - start <= 18 ? n : -1;
  if (c.at() == '.') {   // fractional line numbers are read and ignored
    const std::size_t frac = ++c.pos;
    while (is_digit(c.at())) ++c.pos;
    if (c.pos == frac)
      fail_at(static_cast<int>(frac), ErrorCode::BadLineNumber,
              "the line number has no digits after its '.'");
  }
  b.n_present = true;
}

void Parser::read_item(Cursor& c, Block& b) {
  const char ch = c.at();
  const int pos = static_cast<int>(c.pos);
  if (ch >= 'a' && ch <= 'z') {
    if (!((c.env.letters >> (ch - 'a')) & 1u)) {
      if ((c.env.mapped_away >> (ch - 'a')) & 1u)
        fail_at(pos, ErrorCode::AxisNotAvailable, "{} word: the axis map sends {} to an axis this machine does not have",
                static_cast<char>(ch - 32), static_cast<char>(ch - 32));
      letter_without_word(c, ch);
    }
    if (ch == 'g') return read_g(c, b);
    if (ch == 'm') return read_m(c, b);
    return read_word(c, b, ch);
  }
  switch (ch) {
    case '(': return read_comment(c, b);
    case '#': return read_assignment(c);
    case ';': c.pos = c.text.size(); return;
    case '@':
      ++c.pos;
      b.radius = real_value(c);
      b.radius_flag = true;
      b.radius_at = position_byte(static_cast<std::size_t>(pos));
      return;
    case '^':
      ++c.pos;
      b.theta = real_value(c);
      b.theta_flag = true;
      b.theta_at = position_byte(static_cast<std::size_t>(pos));
      return;
    case '$':
      ++c.pos;
      if (b.dollar_flag)
        fail_at(pos, ErrorCode::RepeatedWord, "a second $ word on this line: give the spindle number once");
      b.dollar = real_value(c);
      b.dollar_flag = true;
      b.dollar_at = position_byte(static_cast<std::size_t>(pos));
      return;
    case '%':
      if (c.text == "%")
        fail_at(pos, ErrorCode::PercentMisplaced,
                "a '%' line in a program whose first line is not '%': delete it, or open the program with a "
                "'%' line too");
      fail_at(pos, ErrorCode::PercentMisplaced,
              "'%' must stand alone on its line (it opens or closes a program)");
    case ']':
      fail_at(pos, ErrorCode::BadCharacter,
              "this ']' closes no '[': remove it or add the '[' that opens the expression");
    default:
      fail_at(pos, ErrorCode::BadCharacter, "'{}' starts no word: remove it or put it in a comment",
              describe_char(ch));
  }
}

// "o1 callsub": a keyword with more letters after it (blanks are gone, so "o1 endif g1" reads
// "endifg1": one letter and a number after the keyword is the next word, not a misspelling).
void Parser::misspelt_keyword(const Cursor& c, std::size_t keyword_at) {
  std::size_t end = c.pos;
  while (end < c.text.size() && c.text[end] >= 'a' && c.text[end] <= 'z') ++end;
  if (end == c.pos) return;
  const char after = end < c.text.size() ? c.text[end] : '\0';
  if (end - c.pos == 1 && (is_digit(after) || after == '.' || after == '[' || after == '#' || after == '-'))
    return;
  fail_at(static_cast<int>(keyword_at), ErrorCode::OwordSyntax, "'{}' is a misspelt O-word keyword ({})",
          c.text.substr(keyword_at, end - keyword_at), kOwordKeywords);
}

void Parser::letter_without_word(const Cursor& c, char letter) {
  const int pos = static_cast<int>(c.pos);
  const char upper = static_cast<char>(letter - 'a' + 'A');
  if (kAxisLetters.find(letter) != std::string_view::npos)
    fail_at(pos, ErrorCode::AxisNotAvailable, "{} word: this machine has no {} axis (its axes are {})", upper,
            upper, axis_list(c.env.letters));
  if (letter == 'n')
    fail_at(pos, ErrorCode::LineNumberNotFirst,
            "N word after other words: a line number must be the first word of its line");
  if (letter == 'o')
    fail_at(pos, ErrorCode::BadCharacter,
            "O-word after other words: an O-word statement must begin its line");
  fail_at(pos, ErrorCode::BadCharacter, "'{}' starts no word: remove it or put it in a comment", letter);
}

void Parser::read_comment(Cursor& c, Block& b) {
  const std::size_t start = ++c.pos;
  int depth = 1;  // comments may nest in some dialects (the lexer checked the parentheses)
  const bool nested = c.env.syntax.nested_comments;
  for (; c.pos < c.text.size(); ++c.pos) {
    const char ch = c.text[c.pos];
    if (ch == '(' && nested) ++depth;
    if (ch == ')' && --depth == 0) break;
  }
  b.comment = c.text.substr(start, c.pos - start);
  b.has_comment = true;
  ++c.pos;   // the lexer guarantees the ')'
}

void Parser::read_word(Cursor& c, Block& b, char letter) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;
  if (b.has(letter)) repeated_word(b, letter, pos);
  value_vacant_ = false;
  double v;
  constexpr std::uint32_t kIntegerLetters = (1u << ('h' - 'a')) | (1u << ('l' - 'a')) | (1u << ('t' - 'a'));
  if ((kIntegerLetters >> (letter - 'a')) & 1u) {
    v = integer_word(c, letter, pos);
    if (value_vacant_) return;  // only macro variables are vacant
  } else {
    const std::size_t start = c.pos;
    // A plain number (what real_value would pass on to real_number) read directly.
    const char c0 = c.at(), c1 = c.at(1);
    const bool plain = is_digit(c0) || c0 == '.' || ((c0 == '-' || c0 == '+') && (is_digit(c1) || c1 == '.'));
    v = plain ? real_number(c) : real_value(c);
    if (value_vacant_) return;  // a word whose value is a vacant variable (macro variables only) is left out
    if (c.env.syntax.decimal_points) note_decimal_point(c, b, letter, start);
    if (v < 0.0 && (letter == 'f' || letter == 's')) negative_rate(letter, v, pos);
    if (letter == 'x' && c.env.lathe_diameter) v /= 2.0;
  }
  b.value[static_cast<std::size_t>(letter - 'a')] = v;
  b.at[static_cast<std::size_t>(letter - 'a')] = position_byte(static_cast<std::size_t>(pos));
  b.words |= 1u << (letter - 'a');
}

// A second word of a letter: P and Q count as repeated only when the earlier value is > -1
// (LinuxCNC's rule), and are then overwritten.
void Parser::repeated_word(const Block& b, char letter, int pos) {
  if ((letter != 'p' && letter != 'q') || b.get(letter) > -1.0)
    fail_at(pos, ErrorCode::RepeatedWord, "a second {} word on this line: give each word once",
            static_cast<char>(letter - 32));
}

// H, L and T: integers with their own lower bounds.
double Parser::integer_word(Cursor& c, char letter, int pos) {
  const char name[2] = {static_cast<char>(letter - 32), '\0'};
  const double v = integer_value(c, name);
  if (value_vacant_) return v;  // only macro variables are vacant
  if (letter == 'h' && v < -1) fail_at(pos, ErrorCode::HWordNegative, "H{}: the tool number of an offset is 0 or more", v);
  if (letter == 'l' && v < 0) fail_at(pos, ErrorCode::LWordNegative, "L{}: an L number cannot be negative", v);
  if (letter == 't' && v < 0) fail_at(pos, ErrorCode::ToolNegative, "T{}: tool numbers are 0 or more", v);
  return v;
}

void Parser::negative_rate(char letter, double v, int pos) {
  if (letter == 'f') fail_at(pos, ErrorCode::FeedNegative, "F{}: a feed rate cannot be negative", v);
  fail_at(pos, ErrorCode::SpeedNegative, "S{}: a spindle speed cannot be negative", v);
}

// Fanuc: notes a number written with a decimal point (Block::decimal), which some words read
// differently (G4 P counts milliseconds without one).
void Parser::note_decimal_point(const Cursor& c, Block& b, char letter, std::size_t start) {
  const char first = c.text[start];
  if ((is_digit(first) || first == '.' || first == '-' || first == '+') &&
      c.text.substr(start, c.pos - start).find('.') != std::string_view::npos)
    b.decimal |= 1u << (letter - 'a');
}

// A plain code like "1", "17.1" or "64" read directly (code ten times the number), as the
// general path below would read it; -1 when the text has any other form.
int Parser::plain_code(Cursor& c) noexcept {
  const std::string_view t = c.text;
  std::size_t i = c.pos;
  int code = 0;
  const std::size_t first = i;
  while (i < t.size() && is_digit(t[i]) && i - first < 2) code = code * 10 + (t[i++] - '0');
  if (i == first) return -1;
  code *= 10;
  if (i < t.size() && t[i] == '.') {
    if (i + 1 >= t.size() || !is_digit(t[i + 1])) return -1;
    code += t[i + 1] - '0';
    i += 2;
  }
  if (i < t.size() && (is_digit(t[i]) || t[i] == '.')) return -1;
  c.pos = i;
  return code;
}

void Parser::read_g(Cursor& c, Block& b) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;
  int code = plain_code(c);
  if (code < 0) {
    const double v10 = 10.0 * real_value(c);
    // (range first: only then does the value fit an int)
    if (!(v10 < 1e4))
      fail_at(pos, ErrorCode::GCodeOutOfRange, "G{}: G numbers go from 0 to 99.9", v10 / 10.0);
    if (v10 <= -1e4)
      fail_at(pos, ErrorCode::GCodeOutOfRange, "G{}: G numbers cannot be negative", v10 / 10.0);
    code = static_cast<int>(std::floor(v10));
    if (v10 - code > 0.999) code = static_cast<int>(std::ceil(v10));
    else if (v10 - code > 0.001)
      fail_at(pos, ErrorCode::GCodeOutOfRange, "G{}: a G number has at most one decimal", v10 / 10.0);
    if (code > 999) fail_at(pos, ErrorCode::GCodeOutOfRange, "G{}: G numbers go from 0 to 99.9", v10 / 10.0);
    if (code < 0) fail_at(pos, ErrorCode::GCodeOutOfRange, "G{}: G numbers cannot be negative", v10 / 10.0);
  }
  const int group = code_group(code, false, c.env);
  if (group < 0) fail_at(pos, ErrorCode::UnknownGCode, "{} is not a G code of this dialect", g_name(code));
  auto& slot = b.g[static_cast<std::size_t>(group)];
  b.extension_groups = b.extension_groups || group >= kGroupScaling;
  if (code == 800 && slot != -1) return;   // G80 beside another motion code is ignored
  if (slot != -1 && slot != 800)
    fail_at(pos, ErrorCode::ModalGroupConflict,
            "{} and {} are both {} codes: a line may hold only one of them", g_name(slot), g_name(code),
            g_group_name(group));
  slot = static_cast<std::int16_t>(code);
  b.g_at[static_cast<std::size_t>(group)] = position_byte(static_cast<std::size_t>(pos));
}

// The modal group of a G (×10) or M code: the core's, M98 where it is a call (SyntaxRules::
// m98_calls), or the one an extension gives a code the core does not know.
int Parser::code_group(int code, bool m_code, const ParseEnv& env) const noexcept {
  const int group = m_code ? m_group(code) : g_group(code);
  if (group >= 0) return group;
  if (m_code && code == 98 && env.syntax.m98_calls) return kGroupStop;
  if (env.ext == nullptr || code < 0) return -1;
  const CodeHandler* h = nullptr;
  if (m_code && code < static_cast<int>(env.ext->m.size())) h = env.ext->m[static_cast<std::size_t>(code)].get();
  if (!m_code && code < static_cast<int>(env.ext->g.size())) h = env.ext->g[static_cast<std::size_t>(code)].get();
  if (h == nullptr) return -1;
  const int own = h->traits(code).group;
  if (own >= 0) return own;
  return m_code ? kGroupUser : -1;
}

void Parser::read_m(Cursor& c, Block& b) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;
  const int code = integer_value(c, "an M code");
  if (code < 0) fail_at(pos, ErrorCode::MCodeOutOfRange, "M{}: M numbers cannot be negative", code);
  if (code > 199) fail_at(pos, ErrorCode::MCodeOutOfRange, "M{}: M numbers go from 0 to 199", code);
  const int group = code_group(code, true, c.env);
  if (group < 0) fail_at(pos, ErrorCode::UnknownMCode, "M{} is not an M code of this dialect", code);
  auto& slot = b.m[static_cast<std::size_t>(group)];
  if (slot != -1)
    fail_at(pos, ErrorCode::ModalGroupConflict,
            "M{} and M{} are both {} codes: a line may hold only one of them", slot, code,
            m_group_name(group));
  slot = static_cast<std::int16_t>(code);
  b.m_at[static_cast<std::size_t>(group)] = position_byte(static_cast<std::size_t>(pos));
  ++b.m_count;
}

std::string Parser::read_name(Cursor& c) {
  const std::size_t start = ++c.pos;   // after '<'
  while (c.pos < c.text.size() && c.text[c.pos] != '>') ++c.pos;
  if (c.pos >= c.text.size())
    fail_at(static_cast<int>(start - 1), ErrorCode::NameNotTerminated,
            "the name after '<' is not closed: add '>' after it");
  std::string name(c.text.substr(start, c.pos - start));
  ++c.pos;
  return name;
}

void Parser::read_assignment(Cursor& c) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;
  if (c.at() == '<') {
    std::string name = read_name(c);
    c.env.host->declare_named(name);
    if (c.at() != '=')
      fail_at(static_cast<int>(c.pos), ErrorCode::EqualSignMissing,
              "#<{}> is not followed by '=': write #<{}>=value", name, name);
    ++c.pos;
    const double v = real_value(c);
    named_assignments.emplace_back(std::move(name), v);
    return;
  }
  const int index = integer_value(c, "a parameter number");
  if (macro_variables(c)) {
    check_fanuc_assignment(index, pos);
  } else {
    if (index < 1 || index >= kParameterCount)
      fail_at(pos, ErrorCode::ParameterOutOfRange, "parameter #{} does not exist (1..{})", index, kParameterCount - 1);
    if ((index >= 5400 && index <= 5413) || (index >= 5420 && index <= 5428))
      fail_at(pos, ErrorCode::ParameterReadOnly, "parameter #{} is read-only: it reports the current {}", index,
              index < 5420 ? "tool" : "position");
  }
  if (c.at() != '=')
    fail_at(static_cast<int>(c.pos), ErrorCode::EqualSignMissing,
            "#{} is not followed by '=': write #{}=value", index, index);
  ++c.pos;
  if (c.env.syntax.open_assignments) {
    // The right-hand side is an expression without brackets (#1 = #1 + 1); a bare vacant
    // variable makes the target vacant too.
    const double v = expression(c, true);
    numbered_assignments.emplace_back(index, v);
    if (value_vacant_) vacant_assignments.push_back(index);
    return;
  }
  const double v = real_value(c);
  numbered_assignments.emplace_back(index, v);
}

double Parser::real_value(Cursor& c) {
  const char ch = c.at();
  const int pos = static_cast<int>(c.pos);
  if (ch == '\0') {
    const char before = pos > 0 ? c.text[static_cast<std::size_t>(pos - 1)] : '\0';
    if (before >= 'a' && before <= 'z')
      fail_at(pos - 1, ErrorCode::MissingValue, "{} has no value: the line ends right after the letter",
              static_cast<char>(before - 'a' + 'A'));
    fail_at(pos, ErrorCode::MissingValue, "the line ends where a value should follow");
  }
  const char next = c.at(1);
  double v;
  bool vacant = false;
  if (ch == '[') {
    v = expression(c);
  } else if (ch == '#') {
    v = parameter(c, false);
    vacant = value_vacant_;
  } else if ((ch == '+' || ch == '-') && next != '\0' && !is_digit(next) && next != '.') {
    ++c.pos;
    v = real_value(c);
    if (ch == '-') v = -v;
  } else if (ch >= 'a' && ch <= 'z') {
    v = unary(c);
  } else {
    value_vacant_ = false;
    return real_number(c);   // finite: no exponent, and overlong digit strings are refused
  }
  if (std::isnan(v))
    fail_at(pos, ErrorCode::ResultNotANumber, "this value is not a number (its calculation is undefined)");
  if (std::isinf(v))
    fail_at(pos, ErrorCode::ResultInfinite, "this value is infinite (its calculation overflows)");
  value_vacant_ = vacant;
  return v;
}

namespace {

// Reads digits from p (not past `limit`) into `value`, which wraps after 19 digits (callers
// only use it for short numbers). Returns the end.
const char* read_digits(const char* p, const char* limit, std::uint64_t& value) noexcept {
  for (; p < limit; ++p) {
    const unsigned digit = static_cast<unsigned char>(*p) - unsigned{'0'};   // (wraps for bytes below '0')
    if (digit > 9) break;
    value = value * 10 + digit;
  }
  return p;
}

}  // namespace

double Parser::real_number(Cursor& c) {
  const char* const text = c.text.data();
  const char* const limit = text + c.text.size();
  const char* const start = text + c.pos;
  // One sign, taken without a branch (signs are as random as the coordinates); a second one
  // leaves the mantissa without digits.
  const bool sign = start < limit && (*start == '+' || *start == '-');
  const bool negative = start < limit && *start == '-';
  const char* const mant = start + sign;
  // Mantissa: digits, at most one '.', at least one digit. Accumulated on the way for the
  // common short number (exact below 2^53 with at most 15 digits: one correctly rounded
  // division gives the same double as any correct conversion).
  std::uint64_t value = 0;
  const char* const int_end = read_digits(mant, limit, value);
  const char* end = int_end;   // end of the mantissa
  if (end < limit && *end == '.') end = read_digits(end + 1, limit, value);
  const auto decimals = end - int_end - (end != int_end);   // (the point is not a digit)
  const auto digits = (int_end - mant) + decimals;
  if (digits == 0 || (end < limit && *end == '.')) bad_number(start, limit, text, false);
  c.pos = static_cast<std::size_t>(end - text);
  static constexpr double kPow10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  double v;
  if (digits <= 15) {
    v = static_cast<double>(value) / kPow10[decimals];
  } else {   // `value` may have wrapped: let the library convert
    const auto [ptr, ec] = std::from_chars(mant, end, v);
    if (ec != std::errc() || ptr != end) bad_number(start, limit, text, true);
  }
  static constexpr double kSign[] = {1.0, -1.0};   // (exact: the same as negating)
  return v * kSign[negative];
}

// Says why the text at `start` is not a number, reading it again as real_number did (which
// keeps nothing it does not need on the way). `unreadable`: the digits could not be converted.
void Parser::bad_number(const char* start, const char* limit, const char* text, bool unreadable) {
  const char* p = start;
  while (p < limit && (*p == '+' || *p == '-')) ++p;
  const bool signs = p - start > 1;
  std::size_t digits = 0;
  for (; p < limit && is_digit(*p); ++p) ++digits;
  if (p < limit && *p == '.') {
    for (++p; p < limit && is_digit(*p); ++p) ++digits;
  }
  const char* after = p;
  while (after < limit && (is_digit(*after) || *after == '.')) ++after;
  const std::string_view span(start, static_cast<std::size_t>(after - start));
  const auto at = static_cast<int>(start - text);
  if (span.empty()) fail_at(at, ErrorCode::BadNumber, "a number is missing here");
  if (unreadable || digits == 0 || signs)
    fail_at(at, ErrorCode::BadNumber,
            "'{}' is not a number (digits with at most one point, after at most one sign)", span);
  fail_at(at, ErrorCode::BadNumber, "'{}' is not a number: a number has at most one decimal point", span);
}

int Parser::integer_value(Cursor& c, const char* what) {
  const int pos = static_cast<int>(c.pos);
  {
    // Fast path: up to nine plain digits, the common "M3" or "T12".
    std::size_t i = c.pos;
    int v = 0;
    while (i < c.text.size() && is_digit(c.text[i]) && i - c.pos < 9) v = v * 10 + (c.text[i++] - '0');
    if (i > c.pos && (i >= c.text.size() || (!is_digit(c.text[i]) && c.text[i] != '.'))) {
      c.pos = i;
      return v;
    }
  }
  const double v = real_value(c);
  if (!(std::fabs(v) < 2147483647.0))
    fail_at(pos, ErrorCode::NotAnInteger, "{} is too large for {}", v, what);
  int i = static_cast<int>(std::floor(v));
  if (v - i > 0.9999) i = static_cast<int>(std::ceil(v));
  else if (v - i > 0.0001)
    fail_at(pos, ErrorCode::NotAnInteger, "{} is not a whole number, which {} must be", v, what);
  return i;
}

double Parser::expression(std::string_view text, std::size_t& pos, const ParseEnv& env) {
  Cursor c{text, pos, env};
  const double v = expression(c);
  pos = c.pos;
  return v;
}

double Parser::expression(Cursor& c, bool open) {
  // Operator-precedence evaluation with an explicit stack, left to right within a level;
  // operands are evaluated as they are read, exactly in LinuxCNC's order. The Fanuc dialect
  // compares vacant values with EQ/NE as unequal to any number (they are 0 elsewhere).
  double values[8];
  bool vacant[8];
  int ops[8];
  int op_pos[8];
  const bool vacancy = macro_variables(c);
  if (!open) ++c.pos;   // '['
  values[0] = real_value(c);
  vacant[0] = value_vacant_;
  op_pos[0] = static_cast<int>(c.pos);
  ops[0] = binary_operator(c, open);
  const bool single = ops[0] == kRightBracket;
  int top = 1;
  while (ops[0] != kRightBracket) {
    values[top] = real_value(c);
    vacant[top] = value_vacant_;
    op_pos[top] = static_cast<int>(c.pos);
    ops[top] = binary_operator(c, open);
    if (precedence(ops[top]) > precedence(ops[top - 1])) {
      ++top;
      continue;
    }
    for (;;) {
      const int op = ops[top - 1];
      if (vacancy && (op == kEq || op == kNe) && (vacant[top - 1] || vacant[top])) {
        const bool same = vacant[top - 1] && vacant[top];
        values[top - 1] = (op == kEq) == same ? 1.0 : 0.0;
      } else {
        values[top - 1] = apply_binary(values[top - 1], op, values[top], op_pos[top - 1]);
      }
      vacant[top - 1] = false;
      ops[top - 1] = ops[top];
      op_pos[top - 1] = op_pos[top];
      if (top > 1 && precedence(ops[top - 1]) <= precedence(ops[top - 2])) --top;
      else break;
    }
  }
  value_vacant_ = open && single && vacant[0];
  return values[0];
}

int Parser::binary_operator(Cursor& c, bool open) {
  const int pos = static_cast<int>(c.pos);
  const char ch = c.at();
  const char n1 = c.at(1), n2 = c.at(2);
  // An open expression ends with the line or at a comment (nothing is consumed).
  if (open && (ch == '\0' || ch == '(' || ch == ';')) return kRightBracket;
  if (open && ch == ']') fail_at(pos, ErrorCode::UnknownOperator, "']' without its '['");
  ++c.pos;
  auto word = [&](int op, std::size_t extra) {
    c.pos += extra;
    return op;
  };
  switch (ch) {
    case '+': return kPlus;
    case '-': return kMinus;
    case '/': return kDivide;
    case '*': return n1 == '*' ? word(kPower, 1) : kTimes;
    case ']': return kRightBracket;
    case 'a': if (n1 == 'n' && n2 == 'd') return word(kAnd, 2); break;
    case 'm': if (n1 == 'o' && n2 == 'd') return word(kModulo, 2); break;
    case 'o': if (n1 == 'r') return word(kOr, 1); break;
    case 'x': if (n1 == 'o' && n2 == 'r') return word(kXor, 2); break;
    case 'e': if (n1 == 'q') return word(kEq, 1); break;
    case 'n': if (n1 == 'e') return word(kNe, 1); break;
    case 'g': if (n1 == 'e') return word(kGe, 1); if (n1 == 't') return word(kGt, 1); break;
    case 'l': if (n1 == 'e') return word(kLe, 1); if (n1 == 't') return word(kLt, 1); break;
    case '\0':
      fail_at(pos, ErrorCode::UnclosedExpression, "the line ends inside an expression: close it with ']'");
    default:
      if (ch < 'a' || ch > 'z')
        fail_at(pos, ErrorCode::UnknownOperator,
                "'{}' is not an operator (+ - * / ** MOD AND OR XOR EQ NE GT GE LT LE) nor ']'",
                describe_char(ch));
      break;
  }
  // A letter with a value after it is the next word of the line: the ']' before it is missing.
  if (is_digit(n1) || n1 == '.' || n1 == '[' || n1 == '#' || n1 == '-' || n1 == '+')
    fail_at(pos, ErrorCode::UnclosedExpression,
            "the expression is not closed before the {} word: add ']' before it",
            static_cast<char>(ch - 'a' + 'A'));
  fail_at(pos, ErrorCode::UnknownOperator,
          "no operator starts with '{}' (+ - * / ** MOD AND OR XOR EQ NE GT GE LT LE)", ch);
}

double Parser::unary(Cursor& c) {
  const int pos = static_cast<int>(c.pos);
  const char ch = c.at();
  ++c.pos;
  int op = -1;
  auto take = [&](std::string_view rest, int which) {
    if (op < 0 && starts_with(c.text, c.pos, rest)) {
      op = which;
      c.pos += rest.size();
    }
  };
  switch (ch) {
    case 'a': take("bs", kAbs); take("cos", kAcos); take("sin", kAsin); take("tan", kAtan); break;
    case 'c': take("os", kCos); break;
    case 'e': take("xp", kExp); take("xists", kExists); break;
    case 'f': take("ix", kFix); take("up", kFup); break;
    case 'l': take("n", kLn); break;
    case 'r': take("ound", kRound); break;
    case 's': take("in", kSin); take("qrt", kSqrt); break;
    case 't': take("an", kTan); break;
    default:
      break;
  }
  if (op < 0) {
    // "X F100": the letter before has no value, and the next word follows at once.
    const char before = pos > 0 ? c.text[static_cast<std::size_t>(pos - 1)] : '\0';
    const char after =
        c.text.size() > static_cast<std::size_t>(pos) + 1 ? c.text[static_cast<std::size_t>(pos) + 1] : '\0';
    if (before >= 'a' && before <= 'z' && (is_digit(after) || after == '.'))
      fail_at(pos - 1, ErrorCode::MissingValue,
              "{} has no value: a number, [expression] or #parameter must follow the letter",
              static_cast<char>(before - 'a' + 'A'));
    std::size_t end = static_cast<std::size_t>(pos);
    while (end < c.text.size() && c.text[end] >= 'a' && c.text[end] <= 'z') ++end;
    if (end - static_cast<std::size_t>(pos) > 1) {
      std::string name(c.text.substr(static_cast<std::size_t>(pos), end - static_cast<std::size_t>(pos)));
      for (char& k : name) k = static_cast<char>(k - 'a' + 'A');
      fail_at(pos, ErrorCode::UnknownWord,
              "{} is not a function (ABS ACOS ASIN ATAN COS EXISTS EXP FIX FUP LN ROUND SIN SQRT TAN)", name);
    }
    fail_at(pos, ErrorCode::UnknownWord,
            "'{}' cannot start a value: write a number, [expression], #parameter or a function", ch);
  }
  if (c.at() != '[') {
    std::string name(c.text.substr(static_cast<std::size_t>(pos), c.pos - static_cast<std::size_t>(pos)));
    for (char& k : name) k = static_cast<char>(k - 'a' + 'A');
    fail_at(static_cast<int>(c.pos), ErrorCode::FunctionBracketMissing,
            "{} takes its argument in brackets: {}[...]", name, name);
  }
  if (op == kExists) {
    ++c.pos;
    if (c.at() != '#')
      fail_at(static_cast<int>(c.pos), ErrorCode::ExistsSyntax, "EXISTS takes a parameter: EXISTS[#<name>]");
    const double v = parameter(c, true);
    if (c.at() != ']')
      fail_at(static_cast<int>(c.pos), ErrorCode::ExistsSyntax,
              "EXISTS takes one parameter only: EXISTS[#<name>]");
    ++c.pos;
    return v;
  }
  const bool own = c.env.syntax.own_functions;
  if (op == kAtan && own && c.at() == '[') {
    // ATAN[y,x] too: read the two halves as open expressions.
    std::size_t depth = 0, comma = std::string_view::npos, close = c.pos;
    for (; close < c.text.size(); ++close) {
      const char ch2 = c.text[close];
      if (ch2 == '[') ++depth;
      else if (ch2 == ']' && --depth == 0) break;
      else if (ch2 == ',' && depth == 1 && comma == std::string_view::npos) comma = close;
    }
    if (comma != std::string_view::npos && close < c.text.size()) {
      Cursor y_part{c.text.substr(0, comma), c.pos + 1, c.env};
      const double y = expression(y_part, true);
      Cursor x_part{c.text.substr(0, close), comma + 1, c.env};
      const double x = expression(x_part, true);
      c.pos = close + 1;
      return fanuc_unary(kAtan, static_cast<double>(std::atan2(y, x) * 180.0L / kPi), pos);
    }
  }
  const double arg = expression(c);
  if (op == kAtan) {
    if (c.at() != '/')
      fail_at(static_cast<int>(c.pos), ErrorCode::AtanSyntax, "ATAN takes two arguments: write ATAN[y]/[x]");
    ++c.pos;
    if (c.at() != '[')
      fail_at(static_cast<int>(c.pos), ErrorCode::AtanSyntax,
              "ATAN's second argument goes in brackets: ATAN[y]/[x]");
    const double x = expression(c);
    const double angle = static_cast<double>(std::atan2(arg, x) * 180.0L / kPi);   // double atan2, long double scaling
    return own ? fanuc_unary(kAtan, angle, pos) : angle;
  }
  return own ? fanuc_unary(op, arg, pos) : apply_unary(op, arg, pos);
}

// The Fanuc functions that differ from LinuxCNC's (Fanuc's defaults): FIX drops the fraction
// and FUP raises the magnitude (both toward and away from zero, not floor and ceiling);
// ATAN answers 0..360 degrees and ASIN 270..90 (through 0) instead of negative angles.
// `x` is the argument, or for ATAN the angle LinuxCNC's rule gives.
double Parser::fanuc_unary(int op, double x, int pos) const {
  switch (op) {
    case kFix: return std::trunc(x);
    case kFup: return x < 0.0 ? -std::ceil(-x) : std::ceil(x);
    case kAtan: return x < 0.0 ? x + 360.0 : x;
    case kAsin: {
      const double a = apply_unary(kAsin, x, pos);
      return a < 0.0 ? a + 360.0 : a;
    }
    default: return apply_unary(op, x, pos);
  }
}

double Parser::parameter(Cursor& c, bool exists_only) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;   // '#'
  if (c.at() == '<') {
    const std::string name = read_name(c);
    double v = 0;
    const bool found = c.env.host->named_value(name, v);
    if (exists_only) return found ? 1.0 : 0.0;
    // Lines of a subprogram definition are read, not run (an `o#<n> call` in the body names its
    // sub by a value the call gives it): LinuxCNC does not require their names to be defined.
    if (!found && c.env.defining_sub) return 0.0;
    if (!found) {
      // LinuxCNC reads HAL pins and INI entries through these names; this interpreter has neither.
      if (name.starts_with("_hal[") || name.starts_with("_ini["))
        fail_at(pos, ErrorCode::NamedParameterUndefined,
                "#<{}> reads LinuxCNC's {} here, which this interpreter has no access to", name,
                name[1] == 'h' ? "HAL" : "INI file");
      fail_at(pos, ErrorCode::NamedParameterUndefined, "#<{}> is read before any value is assigned to it",
              name);
    }
    return v;
  }
  const int index = integer_value(c, "a parameter number");
  if (exists_only) return (index >= 1 && index < kParameterCount) ? 1.0 : 0.0;
  if (macro_variables(c)) {
    // #0 and unassigned locals and commons are vacant (0 in arithmetic); some system
    // variables are computed from the state.
    if (index < 0 || index >= kParameterCount)
      fail_at(pos, ErrorCode::ParameterOutOfRange, "variable #{} does not exist", index);
    if (index < kFanucVariableCount && (index == 0 || (c.env.vacant != nullptr && (*c.env.vacant)[static_cast<std::size_t>(index)]))) {
      value_vacant_ = true;
      return 0.0;
    }
    value_vacant_ = false;
    double v = 0;
    try {
      if (c.env.host->computed_variable(index, v)) return v;
    } catch (GcodeError& e) {
      e.set_position(pos);
      throw;
    }
    return c.env.parameters[index];
  }
  if (index < 1 || index >= kParameterCount)
    fail_at(pos, ErrorCode::ParameterOutOfRange, "parameter #{} does not exist (1..{})", index, kParameterCount - 1);
  if (index >= 5420 && index <= 5428 && c.env.comp_on)
    fail_at(pos, ErrorCode::CompPositionRead,
            "#{} (the current position) cannot be read while cutter compensation is on: G40 first", index);
  return c.env.parameters[index];
}

void Parser::read_o_word(Cursor& c, Block& b) {
  const int pos = static_cast<int>(c.pos);
  b.o_at = position_byte(c.pos);
  ++c.pos;
  std::string name;
  if (c.at() == '<') {
    if (c.env.syntax.numbered_programs)
      fail_at(pos, ErrorCode::DialectUnsupported, "o<name> is LinuxCNC syntax: Fanuc programs are numbered (O1000)");
    name = read_name(c);
  } else {
    name = std::to_string(integer_value(c, "an O-word number"));
  }
  static constexpr std::pair<std::string_view, OWord> kKeywords[] = {
      {"sub", OWord::Sub}, {"endsub", OWord::EndSub}, {"call", OWord::Call}, {"do", OWord::Do},
      {"while", OWord::While}, {"repeat", OWord::Repeat}, {"if", OWord::If}, {"elseif", OWord::ElseIf},
      {"else", OWord::Else}, {"endif", OWord::EndIf}, {"break", OWord::Break}, {"continue", OWord::Continue},
      {"endwhile", OWord::EndWhile}, {"endrepeat", OWord::EndRepeat}, {"return", OWord::Return}};
  OWord type = OWord::None;
  const std::size_t keyword_at = c.pos;
  for (const auto& [word, kind] : kKeywords) {
    if (starts_with(c.text, c.pos, word)) {
      type = kind;
      c.pos += word.size();
      break;
    }
  }
  if (type == OWord::None) {
    const char next = c.at();
    if (next != '(' && next != ';' && next != '\0') {
      std::size_t end = c.pos;
      while (end < c.text.size() && c.text[end] >= 'a' && c.text[end] <= 'z') ++end;
      fail_at(static_cast<int>(c.pos), ErrorCode::OwordUnknownKeyword,
              "'{}' after o{} is not an O-word keyword ({})",
              end > c.pos ? c.text.substr(c.pos, end - c.pos) : c.text.substr(c.pos, 1), name,
              kOwordKeywords);
    }
    type = OWord::Program;   // "O1234" alone: a program number
  } else if (c.env.syntax.numbered_programs) {
    fail_at(pos, ErrorCode::DialectUnsupported,
            "O-word statements are LinuxCNC syntax: the Fanuc dialect uses M98/M99, G65, GOTO, IF and WHILE");
  } else if (c.env.skipping_to.empty()) {  // lines passed over are not checked further (LinuxCNC)
    misspelt_keyword(c, keyword_at);
  }
  const ParseEnv& env = c.env;
  const bool global = type == OWord::Sub || type == OWord::EndSub || type == OWord::Call || type == OWord::Return ||
                      type == OWord::Program;
  if (global) {
    b.o_name = std::move(name);
  } else {
    const std::string_view scope = env.call_level > 0 ? env.call_sub : (env.defining_sub ? env.defining_name : "");
    b.o_name.assign(scope);
    b.o_name += '#';
    b.o_name += name;
  }
  b.o_type = type;
  const bool skipping_other = !env.skipping_to.empty() && env.skipping_to != b.o_name;
  switch (type) {
    case OWord::Sub:
    case OWord::Program:
      if (env.defining_sub)
        fail_at(pos, ErrorCode::OwordSubNested,
                "o<{}> sub inside the definition of o<{}>: end that one with endsub first", b.o_name,
                env.defining_name);
      return;
    case OWord::EndSub:
    case OWord::Return:
      if (skipping_other || env.defining_sub) return;   // values are evaluated when run
      if (c.at() == '[') {
        b.o_value = expression(c);
        b.o_has_value = true;
      }
      return;
    default:
      break;
  }
  if (env.defining_sub) {
    b.o_type = OWord::None;
    return;
  }
  switch (type) {
    case OWord::Call:
      if (!env.skipping_to.empty()) {
        b.o_type = OWord::None;
        return;
      }
      while (c.at() == '[' || c.at() == '(') {
        if (c.at() == '(') {
          read_comment(c, b);
          continue;
        }
        if (b.arg_count >= kSubArgumentCount)
          fail_at(static_cast<int>(c.pos), ErrorCode::OwordTooManyArgs,
                  "o<{}> call passes more than {} arguments", b.o_name, kSubArgumentCount);
        b.args[static_cast<std::size_t>(b.arg_count++)] = expression(c);
      }
      return;
    case OWord::While:
    case OWord::Repeat:
    case OWord::If:
    case OWord::ElseIf: {
      if (skipping_other) return;
      if (c.at() != '[') {
        static constexpr const char* kNames[] = {"", "", "", "", "", "while", "if", "elseif", "", "", "", "", "", "", "repeat"};
        fail_at(static_cast<int>(c.pos), ErrorCode::OwordConditionMissing,
                "'{}' needs its {} in brackets: o{} {} [...]", kNames[static_cast<int>(type)],
                type == OWord::Repeat ? "count" : "condition", name, kNames[static_cast<int>(type)]);
      }
      b.o_value = expression(c);
      b.o_has_value = true;
      return;
    }
    default:
      return;
  }
}

}  // namespace opencnc::gcode
