// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect's hooks: its state made with the engine, another controller's lines named,
// the program's own block ranges read for G71/G72, M98 and M99, and the table the engine takes.
#include "dialect.hpp"

#include <fmt/format.h>

#include <utility>

#include "../numeric.hpp"
#include "codes.hpp"

namespace opencnc::gcode {

FanucDialect::FanucDialect(Engine& e) : e_(e) {
  // #0, the locals and the commons start vacant; on a lathe U and W are incremental X and Z.
  e.st_.fanuc.vacant.set();
  for (int i = 34; i < 100; ++i) e.st_.fanuc.vacant.reset(static_cast<std::size_t>(i));
  if (e.opt_.machine == MachineKind::Lathe) e.letters_ |= (1u << ('u' - 'a')) | (1u << ('w' - 'a'));
}

// Lines that start like another controller's program header or command ("%PM",
// "%_N_PART_MPF", "$H", "$BR0137.MIN%") are named as such instead of failing on a character.
void FanucDialect::foreign_syntax() {
  const std::string& raw = e_.line_.raw;
  const std::size_t first = raw.find_first_not_of(" \t");
  if (first == std::string::npos) return;
  const char c = raw[first];
  const char next = first + 1 < raw.size() ? raw[first + 1] : '\0';
  const bool dollar = c == '$' && ((next >= 'A' && next <= 'Z') || (next >= 'a' && next <= 'z'));
  const bool percent =
      c == '%' && next != '\0' && next != ' ' && next != '\t' && !fanuc_program_number(raw).has_value();
  if (!dollar && !percent) return;
  const std::size_t end = raw.find_first_of(" \t(", first);
  const std::string construct = raw.substr(first, end == std::string::npos ? std::string::npos : end - first);
  fail(ErrorCode::DialectUnsupported, "'{}' is another controller's syntax ({}), not Fanuc G-code", construct,
       dollar ? "a command or program header starting with '$'" : "a program header starting with '%'");
}

// G71/G72 P Q: the shape's blocks read, not run (ExecContext::read_block_range).
void FanucDialect::read_block_range(std::int64_t first, std::int64_t last, std::string_view what,
                                    const std::function<void(const Block&)>& visit) {
  if (e_.mdi_.active)
    fail(ErrorCode::OwordInMdi,
         "{} P Q reads the program's own blocks: it cannot run from MDI (as G70 P Q cannot)", what);
  const SourcePosition body = e_.st_.frames.back().fanuc.body;
  const SourcePosition from = sequence(body, first, fmt::format("{} P", what));
  const SourcePosition to = sequence(body, last, fmt::format("{} Q", what));
  if (to.file != from.file || to.offset < from.offset)
    fail(ErrorCode::FanucGotoTargetMissing, "{} P{} Q{}: block N{} comes before N{}", what, first, last, last,
         first);
  // Errors of the shape's blocks point at them, not at the cycle's code.
  struct Site {
    int& slot;
    int saved;
    ~Site() { slot = saved; }
  } site{e_.extension_at_, std::exchange(e_.extension_at_, -1)};
  const SourcePosition resume = e_.st_.next;
  Engine::SavedLine saved = e_.save_line();
  const double p = p_, l = l_, clamp = clamp_;  // the block's own, reset per line read
  e_.jump_to(from);
  for (;;) {
    const Engine::LineKind kind = e_.next_block();
    if (kind == Engine::LineKind::ProgramEnd)
      fail(ErrorCode::MissingProgramEnd, "the program ends inside the shape of {} P{} Q{}", what, first,
           last);
    if (kind == Engine::LineKind::Block) {
      if (e_.block_.o_type != OWord::None || !e_.parser_.numbered_assignments.empty() ||
          !e_.parser_.named_assignments.empty())
        fail(ErrorCode::FanucProfileBlock,
             "the shape of {} P{} Q{} cannot hold macro statements, assignments, calls or G70 (only its "
             "moves are "
             "read)",
             what, first, last);
      visit(e_.block_);
    }
    if (e_.line_.file == to.file && e_.line_.offset == to.offset) break;
  }
  const SourcePosition after = e_.st_.next;
  e_.restore_line(saved, saved.origin);
  p_ = p, l_ = l, clamp_ = clamp;
  e_.jump_to(only_comments_between(resume, from) ? after : resume);
}

// M98 and M99 after the block's motion, as Fanuc calls and returns.
bool FanucDialect::stop_code(int m) {
  if (m == 98) {
    const int p = round_to_int(p_);
    if (p < 1) fail(ErrorCode::FanucCallProgramMissing, "M98 needs P (the program number)");
    // More than four digits: the Fanuc 0 form P<count><program>, e.g. P0031002.
    if (p > 9999 && l_ >= 0)
      fail(ErrorCode::FanucCallCountConflict, "M98 P{} already holds a repeat count: no L with it", p);
    const int count = p > 9999 ? p / 10000 : (l_ >= 0 ? round_to_int(l_) : 1);
    call(static_cast<std::uint32_t>(p > 9999 ? p % 10000 : p), count, false);
    return true;
  }
  if (m == 99) {
    return_from_call();
    return true;
  }
  return false;
}

// A macro call (G65) restores the caller's locals; an M98 call has none of its own.
bool FanucDialect::leave_call(const CallFrame& f) {
  if (f.fanuc.macro) {
    for (std::size_t i = 1; i <= kFanucLocalCount; ++i) {
      e_.st_.parameters[i] = f.fanuc.saved_locals[i - 1];
      e_.st_.fanuc.vacant[i] = f.fanuc.saved_vacant[i];
    }
  }
  return true;
}

namespace {

FanucDialect& state(Engine& e) {
  return static_cast<FanucDialect&>(*e.dialect_state());
}

DialectHooks make_hooks() {
  DialectHooks h;
  h.name = "Fanuc";
  h.syntax.numbered_programs = true;
  h.syntax.nested_comments = true;
  h.syntax.macro_variables = true;
  h.syntax.decimal_points = true;
  h.syntax.open_assignments = true;
  h.syntax.m98_calls = true;
  h.syntax.own_functions = true;
  h.add_codes = add_fanuc_codes;
  h.make_state = [](Engine& e) -> std::unique_ptr<DialectState> { return std::make_unique<FanucDialect>(e); };
  h.start = [](Engine& e) { state(e).start(); };
  h.program_header = [](std::string_view line) {
    return line.front() == '%' && fanuc_program_number(line).has_value();
  };
  h.percent_line = [](Engine& e) { return state(e).percent_line(); };
  h.foreign_syntax = [](Engine& e) { state(e).foreign_syntax(); };
  h.translate = [](Engine& e) { state(e).translate(); };
  h.assignments = [](Engine& e) { state(e).assignments(); };
  h.control_flow = [](Engine& e) { state(e).control_flow(); };
  h.block_done = [](Engine& e, bool flow) {
    FanucDialect& f = state(e);
    if (!flow) f.after_block();
    f.block_done();
  };
  h.end_of_file = [](Engine& e) { state(e).end_of_file(); };
  h.stop_code = [](Engine& e, int m) { return state(e).stop_code(m); };
  h.computed_variable = [](Engine& e, int index, double& value) { return state(e).variable(index, value); };
  h.leave_call = [](Engine& e, const CallFrame& f) { return state(e).leave_call(f); };
  h.read_block_range = [](Engine& e, std::int64_t first, std::int64_t last, std::string_view what,
                          const std::function<void(const Block&)>& visit) {
    state(e).read_block_range(first, last, what, visit);
  };
  h.turret_keeps_spindle = true;
  return h;
}

}  // namespace

const DialectHooks& fanuc_hooks() noexcept {
  static const DialectHooks hooks = make_hooks();
  return hooks;
}

}  // namespace opencnc::gcode
