// SPDX-License-Identifier: GPL-3.0-or-later
// Words, numbers, expressions and O-words of one block, read as LinuxCNC reads them.
#include "parser.hpp"

#include <charconv>
#include <cmath>
#include <limits>

#include "gcode_error.hpp"

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
      if (b == 0.0) fail_at(pos, ErrorCode::DivideByZero, "division by zero");
      return a / b;
    case kModulo: {
      // The result takes the sign of the divisor's magnitude: always >= 0 (LinuxCNC).
      double r = std::fmod(a, b);
      if (r < 0.0) r += std::fabs(b);
      return r;
    }
    case kPower:
      if (a < 0.0 && std::floor(b) != b)
        fail_at(pos, ErrorCode::NegativeToNonIntegerPower, "{} ** {}: a negative number raised to a non-integer power", a, b);
      return std::pow(a, b);
    case kAnd: return (a == 0.0 || b == 0.0) ? 0.0 : 1.0;
    case kOr: return (a != 0.0 || b != 0.0) ? 1.0 : 0.0;
    case kXor: return ((a == 0.0) != (b == 0.0)) ? 1.0 : 0.0;
    case kLt: return a < b ? 1.0 : 0.0;
    case kGt: return a > b ? 1.0 : 0.0;
    case kEq: return std::fabs(a - b) < kEqualTolerance ? 1.0 : 0.0;
    case kNe: return std::fabs(a - b) >= kEqualTolerance ? 1.0 : 0.0;
    case kLe: return (std::fabs(a - b) < kEqualTolerance || a <= b) ? 1.0 : 0.0;
    case kGe: return (std::fabs(a - b) < kEqualTolerance || a >= b) ? 1.0 : 0.0;
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
      if (x < -1.0 || x > 1.0) fail_at(pos, ErrorCode::AcosRange, "ACOS of {} (must be within -1..1)", x);
      return static_cast<double>(std::acos(x) * 180.0L / kPi);
    case kAsin:
      if (x < -1.0 || x > 1.0) fail_at(pos, ErrorCode::AsinRange, "ASIN of {} (must be within -1..1)", x);
      return static_cast<double>(std::asin(x) * 180.0L / kPi);
    case kCos: return static_cast<double>(std::cos(xl * kPi / 180.0L));
    case kSin: return static_cast<double>(std::sin(xl * kPi / 180.0L));
    case kTan: return static_cast<double>(std::tan(xl * kPi / 180.0L));
    case kExp: return std::exp(x);
    case kFix: return std::floor(x);
    case kFup: return std::ceil(x);
    case kLn:
      if (x <= 0.0) fail_at(pos, ErrorCode::LnDomain, "LN of {} (must be positive)", x);
      return std::log(x);
    case kRound: {
      // LinuxCNC rounds half away from zero through an int.
      const double r = x + (x < 0.0 ? -0.5 : 0.5);
      if (!(std::fabs(r) < 2147483647.0)) return std::trunc(r);
      return static_cast<double>(static_cast<int>(r));
    }
    case kSqrt:
      if (x < 0.0) fail_at(pos, ErrorCode::SqrtNegative, "SQRT of {} (negative)", x);
      return std::sqrt(x);
    default: return x;
  }
}

std::string describe_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u < 0x21 || u > 0x7e) return fmt::format("\\{:03o}", static_cast<unsigned>(u));
  return std::string(1, c);
}

}  // namespace

int g_group(int code) noexcept {
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
  Cursor c{text, 0, env};
  if (c.at() == '/') ++c.pos;
  if (c.at() == 'n') read_line_number(c, b);

  // M98 / M99 (Fanuc subprograms) start an O-word line in LinuxCNC.
  if (c.at() == 'm' && (starts_with(text, c.pos + 1, "98") || (starts_with(text, c.pos + 1, "99") && env.call_level > 0))) {
    Cursor probe{text, c.pos + 1, env};
    const int m = integer_value(probe);
    if (m == 98 || (m == 99 && env.call_level > 0))
      fail_at(static_cast<int>(c.pos), ErrorCode::Unsupported, "M{} subprograms (Fanuc style) are not supported yet", m);
  }

  if (c.at() == 'o') {
    read_o_word(c, b);
    if (!env.skipping_to.empty()) return;
    while (c.pos < text.size()) {
      if (c.at() == ';') break;
      if (c.at() == '(') {
        read_comment(c, b);
        continue;
      }
      fail_at(static_cast<int>(c.pos), ErrorCode::OWordSyntax, "unexpected '{}' after the O-word statement",
              describe_char(c.at()));
    }
    return;
  }
  if (!env.skipping_to.empty()) return;   // skipped lines are not evaluated
  while (c.pos < text.size()) read_item(c, b);
}

void Parser::read_line_number(Cursor& c, Block& b) {
  ++c.pos;
  const std::size_t start = c.pos;
  while (is_digit(c.at())) ++c.pos;
  if (c.pos == start) fail_at(static_cast<int>(start), ErrorCode::BadLineNumber, "N must be followed by digits");
  if (c.at() == '.') {   // fractional line numbers are read and ignored
    const std::size_t frac = ++c.pos;
    while (is_digit(c.at())) ++c.pos;
    if (c.pos == frac) fail_at(static_cast<int>(frac), ErrorCode::BadLineNumber, "N number has no digits after '.'");
  }
  b.n_present = true;
}

void Parser::read_item(Cursor& c, Block& b) {
  const char ch = c.at();
  const int pos = static_cast<int>(c.pos);
  if (ch >= 'a' && ch <= 'z') {
    if (!((c.env.letters >> (ch - 'a')) & 1u)) fail_at(pos, ErrorCode::BadCharacter, "unexpected '{}' here", ch);
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
      return;
    case '^':
      ++c.pos;
      b.theta = real_value(c);
      b.theta_flag = true;
      return;
    case '$':
      ++c.pos;
      if (b.dollar_flag) fail_at(pos, ErrorCode::RepeatedWord, "more than one $ word on the line");
      b.dollar = real_value(c);
      b.dollar_flag = true;
      return;
    default:
      fail_at(pos, ErrorCode::BadCharacter, "unexpected '{}' here", describe_char(ch));
  }
}

void Parser::read_comment(Cursor& c, Block& b) {
  const std::size_t start = ++c.pos;
  while (c.pos < c.text.size() && c.text[c.pos] != ')') ++c.pos;
  b.comment = c.text.substr(start, c.pos - start);
  b.has_comment = true;
  ++c.pos;   // the lexer guarantees the ')'
}

void Parser::read_word(Cursor& c, Block& b, char letter) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;
  const bool seen = b.has(letter);
  // P and Q count as repeated only when the earlier value is > -1 (LinuxCNC's rule).
  if (seen && ((letter != 'p' && letter != 'q') || b.get(letter) > -1.0))
    fail_at(pos, ErrorCode::RepeatedWord, "more than one {} word on the line", static_cast<char>(letter - 32));
  double v;
  switch (letter) {
    case 'h':
    case 'l':
    case 't': {
      const int i = integer_value(c);
      if ((letter == 'h' && i < -1) || (letter != 'h' && i < 0))
        fail_at(pos, ErrorCode::NegativeValue, "{} word must not be negative", static_cast<char>(letter - 32));
      v = i;
      break;
    }
    default:
      v = real_value(c);
      if ((letter == 'f' || letter == 's') && v < 0.0)
        fail_at(pos, ErrorCode::NegativeValue, "{} word must not be negative", static_cast<char>(letter - 32));
      if (letter == 'x' && c.env.lathe_diameter) v /= 2.0;
      break;
  }
  b.value[static_cast<std::size_t>(letter - 'a')] = v;
  b.at[static_cast<std::size_t>(letter - 'a')] = static_cast<std::uint8_t>(pos < 255 ? pos : 255);
  b.words |= 1u << (letter - 'a');
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
    if (!(v10 < 1e4)) fail_at(pos, ErrorCode::GCodeOutOfRange, "G{} is out of range", v10 / 10.0);
    if (v10 <= -1e4) fail_at(pos, ErrorCode::GCodeOutOfRange, "G code must not be negative");
    code = static_cast<int>(std::floor(v10));
    if (v10 - code > 0.999) code = static_cast<int>(std::ceil(v10));
    else if (v10 - code > 0.001) fail_at(pos, ErrorCode::GCodeOutOfRange, "G{} is not a G code (at most one decimal)", v10 / 10.0);
    if (code > 999) fail_at(pos, ErrorCode::GCodeOutOfRange, "G{} is out of range", v10 / 10.0);
    if (code < 0) fail_at(pos, ErrorCode::GCodeOutOfRange, "G code must not be negative");
  }
  const int group = g_group(code);
  if (group < 0) {
    if (code % 10) fail_at(pos, ErrorCode::UnknownGCode, "G{}.{} is not a known G code", code / 10, code % 10);
    fail_at(pos, ErrorCode::UnknownGCode, "G{} is not a known G code", code / 10);
  }
  auto& slot = b.g[static_cast<std::size_t>(group)];
  if (code == 800 && slot != -1) return;   // G80 beside another motion code is ignored
  if (slot != -1 && slot != 800) fail_at(pos, ErrorCode::TwoGCodesSameGroup, "two G codes of the same modal group");
  slot = static_cast<std::int16_t>(code);
}

void Parser::read_m(Cursor& c, Block& b) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;
  const int code = integer_value(c);
  if (code < 0) fail_at(pos, ErrorCode::MCodeOutOfRange, "M code must not be negative");
  if (code > 199) fail_at(pos, ErrorCode::MCodeOutOfRange, "M{} is above M199", code);
  const int group = m_group(code);
  if (group < 0) fail_at(pos, ErrorCode::UnknownMCode, "M{} is not a known M code", code);
  auto& slot = b.m[static_cast<std::size_t>(group)];
  if (slot != -1) fail_at(pos, ErrorCode::TwoMCodesSameGroup, "two M codes of the same modal group");
  slot = static_cast<std::int16_t>(code);
  ++b.m_count;
}

std::string Parser::read_name(Cursor& c) {
  const std::size_t start = ++c.pos;   // after '<'
  while (c.pos < c.text.size() && c.text[c.pos] != '>') ++c.pos;
  if (c.pos >= c.text.size())
    fail_at(static_cast<int>(start - 1), ErrorCode::NameNotTerminated, "name started with '<' has no closing '>'");
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
    if (c.at() != '=') fail_at(static_cast<int>(c.pos), ErrorCode::EqualSignMissing, "'=' expected after #<{}>", name);
    ++c.pos;
    const double v = real_value(c);
    named_assignments.emplace_back(std::move(name), v);
    return;
  }
  const int index = integer_value(c);
  if (index < 1 || index >= kParameterCount)
    fail_at(pos, ErrorCode::ParameterOutOfRange, "parameter #{} does not exist (1..{})", index, kParameterCount - 1);
  if ((index >= 5400 && index <= 5413) || (index >= 5420 && index <= 5428))
    fail_at(pos, ErrorCode::ParameterReadOnly, "parameter #{} is read-only", index);
  if (c.at() != '=') fail_at(static_cast<int>(c.pos), ErrorCode::EqualSignMissing, "'=' expected after #{}", index);
  ++c.pos;
  const double v = real_value(c);
  numbered_assignments.emplace_back(index, v);
}

double Parser::real_value(Cursor& c) {
  const char ch = c.at();
  const int pos = static_cast<int>(c.pos);
  if (ch == '\0') fail_at(pos, ErrorCode::MissingValue, "a value is missing at the end of the line");
  const char next = c.at(1);
  double v;
  if (ch == '[') {
    v = expression(c);
  } else if (ch == '#') {
    v = parameter(c, false);
  } else if ((ch == '+' || ch == '-') && next != '\0' && !is_digit(next) && next != '.') {
    ++c.pos;
    v = real_value(c);
    if (ch == '-') v = -v;
  } else if (ch >= 'a' && ch <= 'z') {
    v = unary(c);
  } else {
    return real_number(c);   // finite: no exponent, and overlong digit strings are refused
  }
  if (std::isnan(v)) fail_at(pos, ErrorCode::NotANumber, "the calculation gives 'not a number'");
  if (std::isinf(v)) fail_at(pos, ErrorCode::Infinity, "the calculation gives infinity");
  return v;
}

namespace {

// Reads digits from p (not past `limit`) into `value`, which wraps after 19 digits (callers
// only use it for short numbers). Returns the end.
const char* read_digits(const char* p, const char* limit, std::uint64_t& value) noexcept {
  while (p < limit && is_digit(*p)) value = value * 10 + static_cast<std::uint64_t>(*p++ - '0');
  return p;
}

}  // namespace

double Parser::real_number(Cursor& c) {
  const char* const text = c.text.data();
  const char* const limit = text + c.text.size();
  const char* const start = text + c.pos;
  const char* p = start;
  while (p < limit && (*p == '+' || *p == '-')) ++p;
  const auto signs = p - start;
  const char* const mant = p;
  // Mantissa: digits, at most one '.', at least one digit. Accumulated on the way for the
  // common short number (exact below 2^53 with at most 22 decimals: one correctly rounded
  // division gives the same double as any correct conversion).
  std::uint64_t value = 0;
  const char* const int_end = read_digits(p, limit, value);
  const char* end = int_end;   // end of the mantissa
  std::ptrdiff_t decimals = 0;
  if (end < limit && *end == '.') {
    end = read_digits(end + 1, limit, value);
    decimals = end - (int_end + 1);
  }
  const auto digits = (int_end - mant) + decimals;
  const char* after = end;
  while (after < limit && (is_digit(*after) || *after == '.')) ++after;
  c.pos = static_cast<std::size_t>(after - text);
  if (signs > 1 || digits == 0 || end < after) bad_number(start, after, text, digits == 0 || signs > 1);
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                      1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  double v;
  if (digits <= 15 && decimals <= 22) {
    v = static_cast<double>(value) / kPow10[decimals];
  } else {   // `value` may have wrapped: let the library convert
    const auto [ptr, ec] = std::from_chars(mant, end, v);
    if (ec != std::errc() || ptr != end) bad_number(start, after, text, true);
  }
  return (signs == 1 && *start == '-') ? -v : v;
}

void Parser::bad_number(const char* start, const char* after, const char* text, bool malformed) {
  const std::string_view span(start, static_cast<std::size_t>(after - start));
  const auto at = static_cast<int>(start - text);
  if (malformed) fail_at(at, ErrorCode::BadNumber, "'{}' is not a number", span);
  fail_at(at, ErrorCode::BadNumber, "'{}' is not a number (extra characters after it)", span);
}

int Parser::integer_value(Cursor& c) {
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
  if (!(std::fabs(v) < 2147483647.0)) fail_at(pos, ErrorCode::NotAnInteger, "{} is too large for a whole number", v);
  int i = static_cast<int>(std::floor(v));
  if (v - i > 0.9999) i = static_cast<int>(std::ceil(v));
  else if (v - i > 0.0001) fail_at(pos, ErrorCode::NotAnInteger, "{} is not a whole number", v);
  return i;
}

double Parser::expression(std::string_view text, std::size_t& pos, const ParseEnv& env) {
  Cursor c{text, pos, env};
  const double v = expression(c);
  pos = c.pos;
  return v;
}

double Parser::expression(Cursor& c) {
  // Operator-precedence evaluation with an explicit stack, left to right within a level;
  // operands are evaluated as they are read, exactly in LinuxCNC's order.
  double values[8];
  int ops[8];
  int op_pos[8];
  ++c.pos;   // '['
  values[0] = real_value(c);
  op_pos[0] = static_cast<int>(c.pos);
  ops[0] = binary_operator(c);
  int top = 1;
  while (ops[0] != kRightBracket) {
    values[top] = real_value(c);
    op_pos[top] = static_cast<int>(c.pos);
    ops[top] = binary_operator(c);
    if (precedence(ops[top]) > precedence(ops[top - 1])) {
      ++top;
      continue;
    }
    for (;;) {
      values[top - 1] = apply_binary(values[top - 1], ops[top - 1], values[top], op_pos[top - 1]);
      ops[top - 1] = ops[top];
      op_pos[top - 1] = op_pos[top];
      if (top > 1 && precedence(ops[top - 1]) <= precedence(ops[top - 2])) --top;
      else break;
    }
  }
  return values[0];
}

int Parser::binary_operator(Cursor& c) {
  const int pos = static_cast<int>(c.pos);
  const char ch = c.at();
  const char n1 = c.at(1), n2 = c.at(2);
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
    case '\0': fail_at(pos, ErrorCode::UnclosedExpression, "expression not closed with ']'");
    default: fail_at(pos, ErrorCode::UnknownOperation, "'{}' is not an operator", describe_char(ch));
  }
  fail_at(pos, ErrorCode::UnknownOperation, "unknown operator starting with '{}'", ch);
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
      fail_at(pos, ErrorCode::UnknownWord, "'{}' cannot start a value (expected a number, [, # or a function)", ch);
  }
  if (op < 0) fail_at(pos, ErrorCode::UnknownWord, "unknown function starting with '{}'", ch);
  if (c.at() != '[') fail_at(static_cast<int>(c.pos), ErrorCode::BracketMissing, "'[' expected after the function name");
  if (op == kExists) {
    ++c.pos;
    if (c.at() != '#') fail_at(static_cast<int>(c.pos), ErrorCode::BracketedParameter, "EXISTS needs a parameter: EXISTS[#<name>]");
    const double v = parameter(c, true);
    if (c.at() != ']') fail_at(static_cast<int>(c.pos), ErrorCode::BracketedParameter, "']' expected after the EXISTS parameter");
    ++c.pos;
    return v;
  }
  const double arg = expression(c);
  if (op == kAtan) {
    if (c.at() != '/') fail_at(static_cast<int>(c.pos), ErrorCode::AtanSlashMissing, "ATAN needs two arguments: ATAN[y]/[x]");
    ++c.pos;
    if (c.at() != '[') fail_at(static_cast<int>(c.pos), ErrorCode::BracketMissing, "'[' expected after 'ATAN[...]/'");
    const double x = expression(c);
    return static_cast<double>(std::atan2(arg, x) * 180.0L / kPi);   // double atan2, long double scaling

  }
  return apply_unary(op, arg, pos);
}

double Parser::parameter(Cursor& c, bool exists_only) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;   // '#'
  if (c.at() == '<') {
    const std::string name = read_name(c);
    double v = 0;
    const bool found = c.env.host->named_value(name, v);
    if (exists_only) return found ? 1.0 : 0.0;
    if (!found) fail_at(pos, ErrorCode::NamedParameterUndefined, "#<{}> is used before it is given a value", name);
    return v;
  }
  const int index = integer_value(c);
  if (exists_only) return (index >= 1 && index < kParameterCount) ? 1.0 : 0.0;
  if (index < 1 || index >= kParameterCount)
    fail_at(pos, ErrorCode::ParameterOutOfRange, "parameter #{} does not exist (1..{})", index, kParameterCount - 1);
  if (index >= 5420 && index <= 5428 && c.env.comp_on)
    fail_at(pos, ErrorCode::ModalContext, "#{} (current position) cannot be read while cutter compensation is on", index);
  return c.env.parameters[index];
}

void Parser::read_o_word(Cursor& c, Block& b) {
  const int pos = static_cast<int>(c.pos);
  ++c.pos;
  std::string name;
  if (c.at() == '<') {
    name = read_name(c);
  } else {
    name = std::to_string(integer_value(c));
  }
  static constexpr std::pair<std::string_view, OWord> kKeywords[] = {
      {"sub", OWord::Sub}, {"endsub", OWord::EndSub}, {"call", OWord::Call}, {"do", OWord::Do},
      {"while", OWord::While}, {"repeat", OWord::Repeat}, {"if", OWord::If}, {"elseif", OWord::ElseIf},
      {"else", OWord::Else}, {"endif", OWord::EndIf}, {"break", OWord::Break}, {"continue", OWord::Continue},
      {"endwhile", OWord::EndWhile}, {"endrepeat", OWord::EndRepeat}, {"return", OWord::Return}};
  OWord type = OWord::None;
  for (const auto& [word, kind] : kKeywords) {
    if (starts_with(c.text, c.pos, word)) {
      type = kind;
      c.pos += word.size();
      break;
    }
  }
  if (type == OWord::None) {
    const char next = c.at();
    if (next != '(' && next != ';' && next != '\0')
      fail_at(static_cast<int>(c.pos), ErrorCode::OWordSyntax, "unknown O-word statement after o{}", name);
    type = OWord::Program;   // "O1234" alone: a program number
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
      if (env.defining_sub) fail_at(pos, ErrorCode::NestedSub, "o<{}> sub inside the definition of o<{}>", b.o_name, env.defining_name);
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
          fail_at(static_cast<int>(c.pos), ErrorCode::TooManyArguments, "a call takes at most {} arguments", kSubArgumentCount);
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
        fail_at(static_cast<int>(c.pos), ErrorCode::BracketMissing, "'[' expected after '{}'", kNames[static_cast<int>(type)]);
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
