// SPDX-License-Identifier: GPL-3.0-or-later
// Reading blocks: blanks and case, comments, numbers, words, G/M groups, parameters,
// expressions (with a seeded random comparison against a reference evaluator), O-words.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <string>

#include "gcode_error.hpp"
#include "lexer.hpp"
#include "parser.hpp"

using namespace opencnc::gcode;

namespace {

std::string normalize(std::string_view raw) {
  std::string out(raw.size() + 1, '\0');
  out.resize(normalize_line(raw, out.data()));
  return out;
}

ErrorCode error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const GcodeError& e) {
    return e.code();
  }
  ADD_FAILURE() << "no error";
  return ErrorCode::NoProgram;
}

class Host : public ParamHost {
 public:
  bool named_value(std::string_view name, double& v) override {
    auto it = named.find(std::string(name));
    if (it == named.end()) return false;
    v = it->second;
    return true;
  }
  void declare_named(std::string_view name) override { named.emplace(std::string(name), 0.0); }
  std::map<std::string, double> named;
};

class ParserTest : public ::testing::Test {
 protected:
  ParserTest() {
    params_.resize(kParameterCount, 0.0);
    env_.parameters = params_.data();
    env_.host = &host_;
    for (char c : std::string_view("abcdefghijklmpqrstuvwxyz")) env_.letters |= 1u << (c - 'a');
  }
  Block parse(std::string_view raw) {
    const std::string text = normalize(raw);
    text_ = text;
    parser_.parse(text_, env_, block_);
    return block_;
  }
  double eval(std::string_view raw) {
    const Block b = parse(std::string("x") + std::string(raw));
    return b.get('x');
  }
  ErrorCode fails(std::string_view raw) {
    return error_of([&] { parse(raw); });
  }

  std::vector<double> params_;
  Host host_;
  ParseEnv env_;
  Parser parser_;
  Block block_;
  std::string text_;
};

}  // namespace

TEST(Lexer, DropsBlanksLowersCaseAndKeepsComments) {
  EXPECT_EQ(normalize("G1 X 1 . 5\tY2 (Keep This) Z3"), "g1x1.5y2(Keep This)z3");
  EXPECT_EQ(normalize("G0 X1 ; Rest (as is)"), "g0x1; Rest (as is)");
  EXPECT_EQ(normalize("N10 G1\r"), "n10g1");
  EXPECT_EQ(error_of([] { normalize("G1 (a (b) c)"); }), ErrorCode::NestedComment);
  EXPECT_EQ(error_of([] { normalize("G1 (open"); }), ErrorCode::UnclosedComment);
}

// Lines of random bytes (blanks, letters of both cases, bytes above 0x7F, comments) of every
// length normalise exactly as a plain reading of the rules says.
TEST(Lexer, RandomLinesNormaliseByTheRules) {
  auto reference = [](std::string_view raw) {
    std::string out;
    bool comment = false;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const char c = raw[i];
      if (!comment && c == ';') return out + std::string(raw.substr(i));
      if (comment || c == '(') {
        comment = c != ')';
        out += c;
      } else if (c != ' ' && c != '\t' && c != '\r') {
        out += (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
      }
    }
    return out;
  };
  const std::string alphabet = "GXYZgxyz0123456789.-  \t\r@[]#\x7f\x80\xc3\xff\x1a";
  std::mt19937_64 rng(11);
  for (int i = 0; i < 20000; ++i) {
    std::string raw;
    const std::size_t length = rng() % 70;
    for (std::size_t k = 0; k < length; ++k) raw += alphabet[rng() % alphabet.size()];
    if (rng() % 4 == 0) raw.insert(rng() % (raw.size() + 1), rng() % 2 ? "(Com Ment)" : "; Tail ( X");
    ASSERT_EQ(normalize(raw), reference(raw)) << raw;
  }
}

TEST(Lexer, TrimsTheRawLine) {
  EXPECT_EQ(trim_raw_line("G1 X1  \r"), "G1 X1");
  // A NUL byte is kept (LinuxCNC would cut the line there): normalize_line refuses it.
  EXPECT_EQ(trim_raw_line(std::string_view("G1\0X2", 5)), std::string_view("G1\0X2", 5));
}

TEST(Lexer, RefusesANulByteAtItsPlace) {
  const std::string_view raw("G1 X1\0Y2", 8);
  try {
    normalize(raw);
    ADD_FAILURE() << "no error";
  } catch (const GcodeError& e) {
    EXPECT_EQ(e.code(), ErrorCode::BadCharacter);
    EXPECT_EQ(raw_column(raw, e.position()), 6u);
  }
}

TEST(Lexer, MapsNormalisedPositionsToRawColumns) {
  const std::string_view raw = "  G1 X 1 (a b) Y2";
  // normalised: g1x1(a b)y2 ; 'x' is index 2 -> raw column 6, 'y' index 9 -> column 17
  EXPECT_EQ(raw_column(raw, 0), 3u);
  EXPECT_EQ(raw_column(raw, 2), 6u);
  EXPECT_EQ(raw_column(raw, 9), 16u);
}

TEST(Lexer, FindsTheLeadingLineNumberAsRs274PrintsIt) {
  std::string_view d;
  ASSERT_TRUE(leading_n_digits(" /N0010 G1", d));
  EXPECT_EQ(d, "0010");
  ASSERT_TRUE(leading_n_digits("n 3 0", d));
  EXPECT_EQ(d, "");
  EXPECT_FALSE(leading_n_digits("G1 N10", d));
}

TEST_F(ParserTest, ReadsNumbersTheLinuxCncWay) {
  EXPECT_DOUBLE_EQ(eval("1.5"), 1.5);
  EXPECT_DOUBLE_EQ(eval("-.5"), -0.5);
  EXPECT_DOUBLE_EQ(eval("+.5"), 0.5);
  EXPECT_DOUBLE_EQ(eval("1."), 1.0);
  EXPECT_DOUBLE_EQ(eval("--1"), 1.0);   // unary minus applied to "-1"
  EXPECT_DOUBLE_EQ(eval("-+2"), -2.0);
  EXPECT_EQ(fails("x1.2.3"), ErrorCode::BadNumber);
  EXPECT_EQ(fails("x*2"), ErrorCode::BadNumber);
  EXPECT_EQ(fails("x"), ErrorCode::MissingValue);
  EXPECT_EQ(fails("g1 xf1"), ErrorCode::MissingValue);  // X has no value; F1 follows
  EXPECT_EQ(fails("g1 xfoo"), ErrorCode::UnknownWord);
}

// Numbers of every length, wherever they stand on the line (the reader looks at eight bytes at
// a time and must not look past the line), convert to exactly the double strtod gives.
TEST_F(ParserTest, RandomNumbersReadBitIdenticalToStrtod) {
  std::mt19937_64 rng(7);
  auto digits = [&](std::size_t n) {
    std::string d;
    for (std::size_t i = 0; i < n; ++i) d += static_cast<char>('0' + rng() % 10);
    return d;
  };
  for (int i = 0; i < 20000; ++i) {
    std::string number = rng() % 2 ? "-" : (rng() % 4 ? "" : "+");
    const std::size_t whole = rng() % 21, fraction = rng() % 21;
    number += digits(whole);
    if (fraction > 0 || rng() % 2) number += "." + digits(fraction);
    if (whole + fraction == 0) number += "0";
    const std::string tail = rng() % 2 ? "" : (rng() % 2 ? " y1" : " g1 f100.5 s12345678");
    const Block b = parse("x" + number + tail);
    const double expected = std::strtod(number.c_str(), nullptr);
    ASSERT_EQ(std::memcmp(&expected, &b.value['x' - 'a'], sizeof(double)), 0) << number << tail;
  }
}

TEST_F(ParserTest, StoresWordsAndRejectsRepeats) {
  const Block b = parse("N10 G1 X1 Y-2 F100 S2000 T3 H4 L2 P0.5 Q-1");
  EXPECT_TRUE(b.n_present);
  EXPECT_EQ(b.g[kGroupMotion], 10);
  EXPECT_DOUBLE_EQ(b.get('y'), -2);
  EXPECT_DOUBLE_EQ(b.get('t'), 3);
  EXPECT_TRUE(b.has('q'));
  EXPECT_FALSE(b.has('z'));
  EXPECT_EQ(fails("G1 X1 X2"), ErrorCode::RepeatedWord);
  EXPECT_EQ(fails("G1 F-1"), ErrorCode::FeedNegative);
  EXPECT_EQ(fails("S-1"), ErrorCode::SpeedNegative);
  EXPECT_EQ(fails("T-1"), ErrorCode::ToolNegative);
  EXPECT_EQ(fails("G43 H-2"), ErrorCode::HWordNegative);
  EXPECT_EQ(fails("G81 L-1"), ErrorCode::LWordNegative);
  EXPECT_EQ(fails("T1.5"), ErrorCode::NotAnInteger);
  EXPECT_EQ(fails("G1 X1 N20"), ErrorCode::LineNumberNotFirst);
  EXPECT_EQ(fails("G1 X1 %"), ErrorCode::PercentMisplaced);
  EXPECT_EQ(fails("%"), ErrorCode::PercentMisplaced);
  EXPECT_EQ(fails("G1 X1 ?"), ErrorCode::BadCharacter);
  EXPECT_EQ(fails("G1 X1 ]"), ErrorCode::BadCharacter);
  // P may repeat when the first P is -1 or less (LinuxCNC's rule).
  EXPECT_DOUBLE_EQ(parse("G4 P-2 P3").get('p'), 3);
}

TEST_F(ParserTest, ChecksAxisLettersAgainstTheMachine) {
  env_.letters &= ~(1u << ('w' - 'a'));
  EXPECT_EQ(fails("G1 W1"), ErrorCode::AxisNotAvailable);
  env_.lathe_diameter = true;
  EXPECT_DOUBLE_EQ(parse("G1 X10").get('x'), 5.0);
}

TEST_F(ParserTest, ReadsGAndMCodesIntoTheirGroups) {
  const Block b = parse("G90 G21 G17 G40 G49 G54 G64 G94 G1 M3 M8");
  EXPECT_EQ(b.g[kGroupDistance], 900);
  EXPECT_EQ(b.g[kGroupUnits], 210);
  EXPECT_EQ(b.g[kGroupCoordSystem], 540);
  EXPECT_EQ(b.m[kGroupSpindle], 3);
  EXPECT_EQ(b.m[kGroupCoolant], 8);
  EXPECT_EQ(b.m_count, 2);
  EXPECT_EQ(parse("G59.3").g[kGroupCoordSystem], 593);
  EXPECT_EQ(parse("G80 G1").g[kGroupMotion], 10);   // G80 beside a motion code is ignored
  EXPECT_EQ(parse("G1 G80").g[kGroupMotion], 10);
  EXPECT_EQ(fails("G0 G1"), ErrorCode::ModalGroupConflict);
  EXPECT_EQ(fails("G1.5"), ErrorCode::UnknownGCode);
  EXPECT_EQ(fails("G1.25"), ErrorCode::GCodeOutOfRange);
  EXPECT_EQ(fails("G100"), ErrorCode::GCodeOutOfRange);
  EXPECT_EQ(fails("M3 M4"), ErrorCode::ModalGroupConflict);
  EXPECT_EQ(fails("M200"), ErrorCode::MCodeOutOfRange);
  EXPECT_EQ(fails("M10"), ErrorCode::UnknownMCode);
}

TEST_F(ParserTest, EvaluatesExpressionsWithLinuxCncPrecedence) {
  EXPECT_DOUBLE_EQ(eval("[1+2*3]"), 7);
  EXPECT_DOUBLE_EQ(eval("[2**3**2]"), 64);   // left to right within a level
  EXPECT_DOUBLE_EQ(eval("[2-3*4/5]"), -0.4);
  EXPECT_DOUBLE_EQ(eval("[10 MOD 3]"), 1);
  EXPECT_DOUBLE_EQ(eval("[-7 MOD 3]"), 2);
  EXPECT_DOUBLE_EQ(eval("[1 EQ 1.00005]"), 1);   // equal within 1e-4
  EXPECT_DOUBLE_EQ(eval("[1 NE 1.00005]"), 0);
  EXPECT_DOUBLE_EQ(eval("[2 GT 1 AND 0]"), 0);
  EXPECT_DOUBLE_EQ(eval("[1 + 1 EQ 2]"), 1);
  EXPECT_DOUBLE_EQ(eval("[0 OR 3 XOR 1]"), 0);
  EXPECT_DOUBLE_EQ(eval("[3 LE 3.00001]"), 1);
  EXPECT_DOUBLE_EQ(eval("[3.00001 LE 3]"), 0);   // LE and GE are exact in rs274 (threading.ngc's loop)
  EXPECT_DOUBLE_EQ(eval("[2.99999 GE 3]"), 0);
  EXPECT_DOUBLE_EQ(eval("[2 LT 2]"), 0);
}

TEST_F(ParserTest, EvaluatesFunctionsInDegrees) {
  EXPECT_NEAR(eval("sin[30]"), 0.5, 1e-15);
  EXPECT_NEAR(eval("cos[60]"), 0.5, 1e-15);
  EXPECT_NEAR(eval("tan[45]"), 1.0, 1e-15);
  EXPECT_NEAR(eval("atan[1]/[1]"), 45, 1e-12);
  EXPECT_NEAR(eval("atan[1]/[-1]"), 135, 1e-12);
  EXPECT_NEAR(eval("acos[0]"), 90, 1e-12);
  EXPECT_NEAR(eval("asin[1]"), 90, 1e-12);
  EXPECT_DOUBLE_EQ(eval("sqrt[16]"), 4);
  EXPECT_DOUBLE_EQ(eval("abs[-2]"), 2);
  EXPECT_DOUBLE_EQ(eval("fix[-1.5]"), -2);
  EXPECT_DOUBLE_EQ(eval("fup[-1.5]"), -1);
  EXPECT_DOUBLE_EQ(eval("round[2.5]"), 3);
  EXPECT_DOUBLE_EQ(eval("round[-2.5]"), -3);
  EXPECT_NEAR(eval("exp[1]"), std::exp(1.0), 1e-15);
  EXPECT_NEAR(eval("ln[10]"), std::log(10.0), 1e-15);
  EXPECT_DOUBLE_EQ(eval("exists[#<nothere>]"), 0);
  host_.named["there"] = 2;
  EXPECT_DOUBLE_EQ(eval("exists[#<there>]"), 1);
  EXPECT_DOUBLE_EQ(eval("exists[#5601]"), 1);
}

TEST_F(ParserTest, ReportsExpressionErrorsWithTheirCodes) {
  EXPECT_EQ(fails("x[1/0]"), ErrorCode::DivideByZero);
  EXPECT_EQ(fails("x[-2**0.5]"), ErrorCode::PowerDomain);
  EXPECT_EQ(fails("xsqrt[-1]"), ErrorCode::SqrtNegative);
  EXPECT_EQ(fails("xln[0]"), ErrorCode::LnNonPositive);
  EXPECT_EQ(fails("xacos[2]"), ErrorCode::TrigDomain);
  EXPECT_EQ(fails("xasin[-2]"), ErrorCode::TrigDomain);
  EXPECT_EQ(fails("x[1+2"), ErrorCode::UnclosedExpression);
  EXPECT_EQ(fails("x[1+2 f100"), ErrorCode::UnclosedExpression);  // the F word follows: the ']' is missing
  EXPECT_EQ(fails("x[1?2]"), ErrorCode::UnknownOperator);
  EXPECT_EQ(fails("x[1 an 2]"), ErrorCode::UnknownOperator);
  EXPECT_EQ(fails("xsin 30"), ErrorCode::FunctionBracketMissing);
  EXPECT_EQ(fails("xsine[30]"), ErrorCode::FunctionBracketMissing);
  EXPECT_EQ(fails("xfoo[1]"), ErrorCode::UnknownWord);
  EXPECT_EQ(fails("xatan[1]"), ErrorCode::AtanSyntax);
  EXPECT_EQ(fails("xatan[1]/2"), ErrorCode::AtanSyntax);
  EXPECT_EQ(fails("x[10**400]"), ErrorCode::ResultInfinite);
  EXPECT_EQ(fails("xexists[1]"), ErrorCode::ExistsSyntax);
  EXPECT_EQ(fails("xexists[#<a>"), ErrorCode::ExistsSyntax);
}

TEST_F(ParserTest, ReadsParametersAndBuffersAssignments) {
  params_[1] = 5;
  params_[2] = 1;
  params_[5] = 7;
  EXPECT_DOUBLE_EQ(eval("#1"), 5);
  EXPECT_DOUBLE_EQ(eval("##2"), 5);
  EXPECT_DOUBLE_EQ(eval("#[2+3]"), 7);
  EXPECT_EQ(fails("x#0"), ErrorCode::ParameterOutOfRange);
  EXPECT_EQ(fails("x#5602"), ErrorCode::ParameterOutOfRange);
  EXPECT_EQ(fails("x#<undefined>"), ErrorCode::NamedParameterUndefined);
  EXPECT_EQ(fails("x#<open"), ErrorCode::NameNotTerminated);
  // Assignments are collected, not applied: the line reads the old values.
  const Block b = parse("#1=2 #2=#1 #<v>=#1 G1 X#1");
  EXPECT_DOUBLE_EQ(b.get('x'), 5);
  ASSERT_EQ(parser_.numbered_assignments.size(), 2u);
  EXPECT_EQ(parser_.numbered_assignments[1], (std::pair<int, double>{2, 5.0}));
  ASSERT_EQ(parser_.named_assignments.size(), 1u);
  EXPECT_EQ(parser_.named_assignments[0].first, "v");
  EXPECT_TRUE(host_.named.count("v"));   // declared while reading, as in LinuxCNC
  EXPECT_EQ(fails("#5400=1"), ErrorCode::ParameterReadOnly);
  EXPECT_EQ(fails("#1 2"), ErrorCode::EqualSignMissing);
  env_.comp_on = true;
  EXPECT_EQ(fails("x#5420"), ErrorCode::CompPositionRead);
}

TEST_F(ParserTest, ReadsOWordsWithScopedLabels) {
  Block b = parse("o100 if [1 GT 0]");
  EXPECT_EQ(b.o_type, OWord::If);
  EXPECT_EQ(b.o_name, "#100");
  EXPECT_DOUBLE_EQ(b.o_value, 1);
  b = parse("O<Sub> call [1] (note) [2+3]");
  EXPECT_EQ(b.o_type, OWord::Call);
  EXPECT_EQ(b.o_name, "sub");
  ASSERT_EQ(b.arg_count, 2);
  EXPECT_DOUBLE_EQ(b.args[1], 5);
  env_.call_level = 1;
  env_.call_sub = "sub";
  EXPECT_EQ(parse("o7 while [1]").o_name, "sub#7");
  EXPECT_EQ(parse("o<sub> endsub [4]").o_value, 4);
  EXPECT_EQ(parse("O1234").o_type, OWord::Program);
  EXPECT_EQ(fails("o100 while 1"), ErrorCode::OwordConditionMissing);
  EXPECT_EQ(fails("o100 frobnicate"), ErrorCode::OwordUnknownKeyword);
  EXPECT_EQ(fails("o100 endif G1"), ErrorCode::OwordSyntax);
  std::string many = "o<s> call";
  for (int i = 0; i < 31; ++i) many += " [1]";
  EXPECT_EQ(fails(many), ErrorCode::OwordTooManyArgs);
}

TEST_F(ParserTest, SkippingLinesAreNotEvaluated) {
  env_.skipping_to = "#5";
  EXPECT_NO_THROW(parse("G1 X[1/0]"));
  // Another label's condition is not evaluated either.
  EXPECT_NO_THROW(parse("o6 if [1/0]"));
  EXPECT_EQ(fails("o5 if [1/0]"), ErrorCode::DivideByZero);
}

// --- property test: random expressions against a reference evaluator ----------------------

namespace {

// A small precedence-climbing evaluator (an independent formulation of the same grammar).
struct Ref {
  std::vector<std::string> toks;
  std::size_t i = 0;
  static int prec(const std::string& op) {
    if (op == "and" || op == "or" || op == "xor") return 2;
    if (op == "lt" || op == "gt" || op == "eq" || op == "ne" || op == "le" || op == "ge") return 3;
    if (op == "+" || op == "-") return 4;
    if (op == "*" || op == "/" || op == "mod") return 5;
    return 6;   // **
  }
  static double apply(double a, const std::string& op, double b) {
    if (op == "+") return a + b;
    if (op == "-") return a - b;
    if (op == "*") return a * b;
    if (op == "/") return a / b;
    if (op == "mod") {
      double r = std::fmod(a, b);
      return r < 0 ? r + std::fabs(b) : r;
    }
    if (op == "**") return std::pow(a, b);
    if (op == "and") return (a != 0 && b != 0) ? 1 : 0;
    if (op == "or") return (a != 0 || b != 0) ? 1 : 0;
    if (op == "xor") return ((a != 0) != (b != 0)) ? 1 : 0;
    if (op == "lt") return a < b;
    if (op == "gt") return a > b;
    if (op == "eq") return std::fabs(a - b) < 1e-4;
    if (op == "ne") return std::fabs(a - b) >= 1e-4;
    if (op == "le") return std::fabs(a - b) < 1e-4 || a <= b;
    return std::fabs(a - b) < 1e-4 || a >= b;
  }
  double primary() {
    if (toks[i] == "[") {
      ++i;
      const double v = expr(1);
      ++i;   // ]
      return v;
    }
    return std::stod(toks[i++]);
  }
  double expr(int min_prec) {
    double lhs = primary();
    while (toks[i] != "]" && prec(toks[i]) >= min_prec) {
      const std::string op = toks[i++];
      double rhs = primary();
      while (toks[i] != "]" && prec(toks[i]) > prec(op)) rhs = expr_from(rhs, prec(op) + 1);
      lhs = apply(lhs, op, rhs);
    }
    return lhs;
  }
  double expr_from(double lhs, int min_prec) {
    while (toks[i] != "]" && prec(toks[i]) >= min_prec) {
      const std::string op = toks[i++];
      double rhs = primary();
      while (toks[i] != "]" && prec(toks[i]) > prec(op)) rhs = expr_from(rhs, prec(op) + 1);
      lhs = apply(lhs, op, rhs);
    }
    return lhs;
  }
};

void random_expr(std::mt19937& rng, int depth, std::vector<std::string>& toks) {
  static const char* kOps[] = {"+", "-", "*", "/", "mod", "**", "and", "or", "xor", "lt", "gt", "eq", "ne", "le", "ge"};
  toks.push_back("[");
  const int terms = 1 + static_cast<int>(rng() % 5);
  for (int t = 0; t < terms; ++t) {
    if (t > 0) toks.push_back(kOps[rng() % 15]);
    if (depth < 3 && rng() % 4 == 0) {
      random_expr(rng, depth + 1, toks);
    } else {
      toks.push_back(std::to_string(1 + rng() % 9) + "." + std::to_string(rng() % 10));
    }
  }
  toks.push_back("]");
}

}  // namespace

TEST_F(ParserTest, RandomExpressionsAgreeWithAReferenceEvaluator) {
  std::mt19937 rng(20240611);
  int compared = 0;
  for (int n = 0; n < 20000; ++n) {
    std::vector<std::string> toks;
    random_expr(rng, 0, toks);
    std::string text = "x";
    for (const auto& t : toks) text += t + " ";
    Ref ref{toks};
    ref.i = 1;
    const double want = ref.expr(1);
    if (!std::isfinite(want) || std::fabs(want) > 1e12) continue;   // errors are tested elsewhere
    double got;
    try {
      got = eval(text.substr(1));
    } catch (const GcodeError&) {
      continue;   // overflow on the way (e.g. 9.9**9.9**9.9): rejected consistently, not compared
    }
    ASSERT_NEAR(got, want, 1e-9 * std::max(1.0, std::fabs(want))) << text;
    ++compared;
  }
  EXPECT_GT(compared, 15000);
}
