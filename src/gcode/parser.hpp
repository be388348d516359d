// SPDX-License-Identifier: GPL-3.0-or-later
// Parser — reads one normalised block into a Block: words, G/M codes, comments, parameter
// assignments, O-words and expressions, with LinuxCNC's syntax and error rules.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "opencnc/gcode/block.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::gcode {

struct Extensions;

/// What the parser needs from the interpreter to read parameters. Implemented by the engine.
class ParamHost {
 public:
  virtual ~ParamHost() = default;
  /// Value of #<name> (name lowercase, without <>); false if it is not defined.
  virtual bool named_value(std::string_view name, double& value) = 0;
  /// #<name>=... declares the name while the line is read (LinuxCNC does the same).
  virtual void declare_named(std::string_view name) = 0;
  /// Macro variables (SyntaxRules::macro_variables): the value of system variable #index when
  /// the dialect computes it rather than stores it (modal information, positions); false for
  /// stored variables. Throws GcodeError for variables the dialect does not provide.
  virtual bool computed_variable(int /*index*/, double& /*value*/) { return false; }
};

/// How a dialect's lines read where they differ from LinuxCNC's, each rule a flag: the dialect's
/// hooks (dialect_hooks.hpp) give them once when a program opens. LinuxCNC's are all false.
struct SyntaxRules {
  /// Programs numbered O1000 (":1000"; "%O1000" on a first line) and the dialect's statements
  /// (GOTO, IF, WHILE … DO, END, G65: read_fanuc_statement); o<name> and O-word statements are
  /// another dialect's then.
  bool numbered_programs = false;
  bool nested_comments = false;  ///< (a (b) c) is one comment
  /// Macro variables: #0 and unassigned locals and commons are vacant (0 in arithmetic, a word
  /// whose value is one left out, equal only to another vacant one), assignments check their own
  /// ranges, system variables may be computed by the host (ParamHost::computed_variable).
  bool macro_variables = false;
  bool decimal_points = false;    ///< a word notes whether it was written with a decimal point
  bool open_assignments = false;  ///< #1 = #1 + 1: the right-hand side runs to the line's end
  bool m98_calls = false;         ///< M98 is a subprogram call, in the stop group
  bool own_functions = false;     ///< FIX, ROUND … and ATAN[y,x] as the dialect defines them
};


/// Interpreter facts that change how a line reads.
struct ParseEnv {
  const double* parameters = nullptr;   ///< kParameterCount numbered parameters
  ParamHost* host = nullptr;
  std::uint32_t letters = 0;            ///< bit (letter - 'a') per letter word allowed
  std::uint32_t mapped_away = 0;        ///< axis letters the axis map sends to an axis the machine lacks
  bool lathe_diameter = false;          ///< G7: X words are diameters
  bool comp_on = false;                 ///< cutter compensation active (#5420-5428 unreadable)
  int call_level = 0;
  std::string_view call_sub;            ///< subprogram running at this call level
  bool defining_sub = false;            ///< passing over `o<name> sub` .. `endsub`
  std::string_view defining_name;
  std::string_view skipping_to;         ///< label being skipped to ("" = not skipping)
  SyntaxRules syntax;  ///< the dialect's (a copy: the parser tests a flag per word)
  const Extensions* ext = nullptr;      ///< modal groups of codes the core does not know
  /// Macro variables: #0..#999 without a value.
  const std::bitset<kFanucVariableCount>* vacant = nullptr;
};

/// Reads blocks. Reuses its buffers; after warm-up a block allocates nothing unless it has
/// named parameters or O-words. Not thread-safe.
class Parser {
 public:
  /// Parses `text` (normalised, non-empty) into `block` (cleared first) and the assignment
  /// buffers. Throws GcodeError with the position in `text`.
  void parse(std::string_view text, const ParseEnv& env, Block& block);

  /// Evaluates a bracketed expression starting at `text[pos]` == '['; advances `pos`.
  double expression(std::string_view text, std::size_t& pos, const ParseEnv& env);

  std::vector<std::pair<int, double>> numbered_assignments;
  std::vector<std::pair<std::string, double>> named_assignments;
  /// Macro variables: numbered assignments whose value is vacant (`#2 = #0`, `#2 = #1` with #1 vacant).
  std::vector<int> vacant_assignments;

 private:
  // One parse in progress.
  struct Cursor {
    std::string_view text;
    std::size_t pos;
    const ParseEnv& env;
    char at() const noexcept { return pos < text.size() ? text[pos] : '\0'; }
    char at(std::size_t ahead) const noexcept { return pos + ahead < text.size() ? text[pos + ahead] : '\0'; }
  };

  static bool macro_variables(const Cursor& c) noexcept {
    return c.env.syntax.macro_variables;
  }
  void read_line_number(Cursor& c, Block& b);
  void read_item(Cursor& c, Block& b);
  [[noreturn, gnu::cold]] static void letter_without_word(const Cursor& c, char letter);
  static void misspelt_keyword(const Cursor& c, std::size_t keyword_at);
  void read_o_word(Cursor& c, Block& b);
  bool read_numbered_statement(Cursor& c, Block& b);
  void read_word(Cursor& c, Block& b, char letter);
  [[gnu::cold]] static void repeated_word(const Block& b, char letter, int pos);
  double integer_word(Cursor& c, char letter, int pos);
  [[noreturn, gnu::cold]] static void negative_rate(char letter, double v, int pos);
  static void note_decimal_point(const Cursor& c, Block& b, char letter, std::size_t start);
  void read_g(Cursor& c, Block& b);
  void read_m(Cursor& c, Block& b);
  void read_comment(Cursor& c, Block& b);
  void read_assignment(Cursor& c);
  std::string read_name(Cursor& c);

  double real_value(Cursor& c);
  int integer_value(Cursor& c, const char* what);  ///< `what`: "L", "a parameter number" (for messages)
  static int plain_code(Cursor& c) noexcept;
  [[gnu::always_inline]] inline double real_number(Cursor& c);
  [[noreturn, gnu::cold]] static void bad_number(const char* start, const char* limit, const char* text, bool unreadable);
  /// A bracketed expression; `open`: an open assignment's right-hand side (SyntaxRules::
  /// open_assignments), which runs to the end of the line or a comment without brackets.
  double expression(Cursor& c, bool open = false);
  double parameter(Cursor& c, bool exists_only);
  double unary(Cursor& c);
  int binary_operator(Cursor& c, bool open);
  int code_group(int code, bool m_code, const ParseEnv& env) const noexcept;

  // fanuc/parse.cpp: the Fanuc dialect's statements
  bool read_fanuc_statement(Cursor& c, Block& b);
  void read_goto(Cursor& c, Block& b);
  void read_if(Cursor& c, Block& b);
  void read_while(Cursor& c, Block& b, bool with_condition);
  void read_macro_call(Cursor& c, Block& b);
  void read_statement_tail(Cursor& c, Block& b);
  int loop_number(Cursor& c);
  void check_fanuc_assignment(int index, int pos) const;
  double fanuc_unary(int op, double x, int pos) const;

  bool value_vacant_ = false;  ///< macro variables: the last real_value was a bare vacant variable
};

/// G code (×10) → modal group, -1 if unknown. M code → group, -1 if unknown.
int g_group(int code) noexcept;
int m_group(int code) noexcept;
/// "G1", "G17.1": a G code (×10) as a program writes it, for messages.
std::string g_name(int code);

}  // namespace opencnc::gcode
