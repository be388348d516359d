// SPDX-License-Identifier: GPL-3.0-or-later
// O-word control flow: subprogram definitions, calls and returns (also from files on the
// search path), if/elseif/else, while, do-while, repeat, break and continue. LinuxCNC runs
// these by skipping forward to a label and seeking back to a remembered line; so does this.
#include <cmath>

#include "engine.hpp"
#include "lexer.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

const char* label_kind_name(LabelKind k) noexcept {
  switch (k) {
    case LabelKind::Sub: return "sub";
    case LabelKind::Do: return "do";
    case LabelKind::While: return "while";
    case LabelKind::Repeat: return "repeat";
    case LabelKind::If: return "if";
  }
  return "?";
}

const char* label_end_keyword(LabelKind k) noexcept {
  switch (k) {
    case LabelKind::Sub:
      return "endsub";
    case LabelKind::Do:
      return "while [...]";
    case LabelKind::While:
      return "endwhile";
    case LabelKind::Repeat:
      return "endrepeat";
    case LabelKind::If:
      return "endif";
  }
  return "?";
}

std::string label_text(std::string_view key) {
  const std::size_t hash = key.find('#');
  const std::string_view name = hash == std::string_view::npos ? key : key.substr(hash + 1);
  const bool number = !name.empty() && name.find_first_not_of("0123456789") == std::string_view::npos;
  return number ? fmt::format("o{}", name) : fmt::format("o<{}>", name);
}

LabelInfo* FlowControl::find_label(const std::string& name) {
  auto it = e_.st_.control.labels.find(name);
  return it == e_.st_.control.labels.end() ? nullptr : &it->second;
}

void FlowControl::save_label(LabelKind kind) {
  LabelInfo info;
  info.kind = kind;
  info.at = {e_.line_.file, e_.line_.offset, e_.line_.number};
  e_.st_.control.labels[e_.block_.o_name] = info;
}

void FlowControl::count_loop() {
  if (e_.opt_.limits.max_loop_iterations != 0 &&
      ++e_.st_.loop_iterations > e_.opt_.limits.max_loop_iterations)
    fail(ErrorCode::LimitLoopIterations, "more than {} loop iterations (limit max_loop_iterations)",
         e_.opt_.limits.max_loop_iterations);
}

void FlowControl::jump_to_label(const std::string& name) {
  const LabelInfo* l = find_label(name);
  if (l == nullptr) fail(ErrorCode::OwordUnmatched, "{} is not defined", label_text(name));
  e_.jump_to(l->at);
}

void FlowControl::control_flow() {
  const Block& b = e_.block_;
  ControlState& c = e_.st_.control;
  if (!c.skipping_to.empty() && c.skipping_to != b.o_name) return;
  if (!c.seeking_sub.empty() && b.o_type != OWord::Sub && b.o_type != OWord::Program) return;
  switch (b.o_type) {
    case OWord::Sub: return o_sub();
    case OWord::EndSub:
    case OWord::Return: return o_return();
    case OWord::Call: return o_call();
    case OWord::Do: return o_do();
    case OWord::While: return o_while();
    case OWord::Repeat: return o_repeat();
    case OWord::If: return o_if();
    case OWord::ElseIf: return o_elseif();
    case OWord::Else: return o_else();
    case OWord::EndIf: return o_endif();
    case OWord::Break: return o_break_continue(true);
    case OWord::Continue: return o_break_continue(false);
    case OWord::EndWhile:
    case OWord::EndRepeat: return o_end_loop();
    case OWord::Program:
      if (e_.dialect_.control_flow) return e_.dialect_.control_flow(e_);  // its numbered programs
      return o_program();
    case OWord::M98:
      return o_m98();
    case OWord::M99:
      return o_m99();
    case OWord::Goto:
    case OWord::FanucWhile:
    case OWord::FanucEnd:
    case OWord::MacroCall:
    case OWord::BlockRange:  // the dialect's own statements (only its parser makes them)
      if (e_.dialect_.control_flow) e_.dialect_.control_flow(e_);
      return;
    case OWord::None: return;
  }
}

void FlowControl::mixed_styles(const char* what) const {
  fail(ErrorCode::OwordMixedStyles,
       "{}: numbered subprograms (O{} ... M99, called by M98) and O-word ones "
       "(o{} sub ... endsub, called by 'call') do not mix",
       what, e_.block_.o_name, e_.block_.o_name);
}

void FlowControl::o_sub() {
  ControlState& c = e_.st_.control;
  if (e_.st_.frames.back().kind == CallKind::Numbered)
    mixed_styles(fmt::format("o{} sub reached by M98", e_.block_.o_name).c_str());
  auto define = [&] {
    if (const LabelInfo* old = find_label(e_.block_.o_name)) {
      if (old->at.line == e_.line_.number && old->at.file == e_.line_.file)
        fail(ErrorCode::OwordSubRedefined,
             "{} sub is read a second time: a subprogram cannot be defined inside a loop or an if",
             label_text(e_.block_.o_name));
      fail(ErrorCode::OwordSubRedefined, "{} is defined twice (first at {}:{}): rename one of them",
           label_text(e_.block_.o_name), e_.sources_->file(old->at.file), old->at.line);
    }
    save_label(LabelKind::Sub);
  };
  if (!c.skipping_to.empty()) {
    // The sub a call was looking for.
    define();
    c.skipping_to.clear();
  }
  c.seeking_sub.clear();
  if (e_.st_.frames.size() > 1) return;  // entering the body of a call
  if (c.defining_sub)
    fail(ErrorCode::OwordSubNested, "{} sub inside the definition of {}: end that one with endsub first",
         label_text(e_.block_.o_name), label_text(c.defining_name));
  define();
  // A definition in the flow of the program: pass over its body.
  c.skipping_to = e_.block_.o_name;
  c.skip_start_line = e_.line_.number;
  c.defining_sub = true;
  c.defining_name = e_.block_.o_name;
}

void FlowControl::o_return() {
  ControlState& c = e_.st_.control;
  if (e_.st_.frames.back().kind == CallKind::Numbered)
    mixed_styles(fmt::format("{} in a subprogram called by M98 (it returns with M99)",
                             e_.block_.o_type == OWord::EndSub ? "endsub" : "return")
                     .c_str());
  c.return_value = e_.block_.o_has_value ? e_.block_.o_value : 0.0;
  c.value_returned = e_.block_.o_has_value;
  if (e_.st_.frames.size() == 1 && !c.defining_sub)
    fail(ErrorCode::OwordNotInSub, "{} {} outside a subprogram: it belongs between 'sub' and 'endsub'",
         label_text(e_.block_.o_name), e_.block_.o_type == OWord::EndSub ? "endsub" : "return");
  if (!c.skipping_to.empty() && e_.block_.o_type == OWord::EndSub) c.skipping_to.clear();
  if (e_.st_.frames.size() > 1) {
    CallFrame& f = e_.st_.frames.back();
    for (int i = 0; i < kSubArgumentCount; ++i)
      e_.st_.parameters[static_cast<std::size_t>(1 + i)] = f.saved_args[static_cast<std::size_t>(i)];
    e_.jump_to(f.return_to);
    leave_frame();
    return;
  }
  if (e_.block_.o_type == OWord::EndSub) {
    c.skipping_to.clear();
    c.defining_sub = false;
    c.defining_name.clear();
  }
}

void FlowControl::leave_frame() {
  const CallFrame leaving = std::move(e_.st_.frames.back());
  e_.st_.frames.pop_back();
  if (leaving.saved.valid && leaving.saved.restore_on_return) e_.mcodes_.restore_context(leaving.saved);
}

// An MDI line failed inside the subprogram it called: every call is left as if it had returned
// (arguments or macro locals back as they were), so the next line runs in the session's frame.
void FlowControl::abandon_calls() {
  while (e_.st_.frames.size() > 1) {
    const CallFrame& f = e_.st_.frames.back();
    if (!(e_.dialect_.leave_call && e_.dialect_.leave_call(e_, f))) {
      for (int i = 0; i < kSubArgumentCount; ++i)
        e_.st_.parameters[static_cast<std::size_t>(1 + i)] = f.saved_args[static_cast<std::size_t>(i)];
    }
    leave_frame();
  }
  e_.st_.control.skipping_to.clear();
  e_.st_.control.seeking_sub.clear();
}

void FlowControl::o_call() {
  CallFrame frame;
  frame.kind = CallKind::OWord;
  frame.return_to = e_.st_.next;
  for (int i = 0; i < kSubArgumentCount; ++i) {
    frame.saved_args[static_cast<std::size_t>(i)] = e_.st_.parameters[static_cast<std::size_t>(1 + i)];
  }
  enter_sub(std::move(frame), e_.block_.o_name, fmt::format("o<{}>", e_.block_.o_name));
  // The arguments, once the call is sure to happen.
  for (int i = 0; i < kSubArgumentCount; ++i) {
    e_.st_.parameters[static_cast<std::size_t>(1 + i)] =
        i < e_.block_.arg_count ? e_.block_.args[static_cast<std::size_t>(i)] : 0.0;
  }
}

// Pushes the frame of a call to sub `name` (its kind and return position set) and goes to its
// body: a sub met before, a file <name>.ngc on the search path, or later in this file.
void FlowControl::enter_sub(CallFrame frame, std::string name, std::string_view context_name) {
  const std::uint32_t depth = static_cast<std::uint32_t>(e_.st_.frames.size());
  const std::uint32_t max_depth = e_.opt_.limits.max_call_depth == 0 ? 10 : e_.opt_.limits.max_call_depth;
  const bool m98 = frame.kind == CallKind::Numbered;
  if (depth >= max_depth)
    fail(ErrorCode::LimitCallDepth, "{} nests subprograms deeper than {} levels (limit max_call_depth)",
         m98 ? fmt::format("M98 P{}", name) : fmt::format("{} call", label_text(name)), max_depth - 1);
  ControlState& c = e_.st_.control;
  c.skipping_to.clear();
  frame.sub = name;
  const std::uint32_t parent_context = e_.st_.frames.back().context;
  const canon::SourceRef call_site{e_.line_.file, e_.line_.number, raw_column(e_.line_.raw, e_.block_.o_at)};
  e_.st_.frames.push_back(std::move(frame));
  if (const std::size_t slash = name.rfind('/'); slash != std::string::npos) name = name.substr(slash + 1);
  if (const LabelInfo* l = find_label(name); l != nullptr && l->kind == LabelKind::Sub) {
    e_.jump_to(l->at);
  } else {
    if (!open_sub_file(name) && e_.mdi_.active)
      fail(ErrorCode::OwordSubNotFound, "{} is not defined, and no file {}.ngc is on the subroutine path",
           m98 ? fmt::format("O{}", name) : fmt::format("o<{}>", name), name);
    c.skipping_to = name;
    c.seeking_sub = name;
    c.skip_start_line = e_.line_.number;
  }
  e_.st_.frames.back().context =
      e_.sources_->context(parent_context, call_site, e_.st_.next.file, std::string(context_name));
}

// A bare O number. Where an M98 looked for it, the numbered subprogram starts here; in the
// flow of the program (a main program's number, or the next subprogram after one without
// M99) reading goes on into it, as LinuxCNC does. A sub called with 'call' cannot be one.
void FlowControl::o_program() {
  ControlState& c = e_.st_.control;
  if (e_.st_.frames.back().kind == CallKind::OWord)
    mixed_styles(fmt::format("O{} reached by 'o{} call' (a numbered subprogram is called with M98)",
                             e_.block_.o_name, e_.block_.o_name)
                     .c_str());
  if (c.seeking_sub.empty()) return;
  if (const LabelInfo* old = find_label(e_.block_.o_name); old != nullptr)
    fail(ErrorCode::OwordSubRedefined, "O{} is defined twice (first at {}:{}): renumber one of them",
         e_.block_.o_name, e_.sources_->file(old->at.file), old->at.line);
  save_label(LabelKind::Sub);
  c.skipping_to.clear();
  c.seeking_sub.clear();
}

// M98 P L: a call of the numbered subprogram O<P>, L times (none for L0). #1..#30 are not
// saved: they are global for numbered subprograms. While repeats remain, the call returns to
// its own line, which is read again.
void FlowControl::o_m98() {
  if (!e_.parser_.numbered_assignments.empty() || !e_.parser_.named_assignments.empty())
    fail_at(
        e_.block_.o_at, ErrorCode::OwordSyntax,
        "a parameter assignment on an M98 line: LinuxCNC would not make it, so put it on a line of its own");
  const std::string name = std::to_string(round_to_int(e_.block_.get('p')));
  e_.block_.o_name = name;
  if (e_.block_.has('l') && e_.opt_.limits.max_repeat_count != 0 &&
      e_.block_.get('l') > static_cast<double>(e_.opt_.limits.max_repeat_count))
    fail_at(e_.block_.word_position('l'), ErrorCode::LimitRepeatCount,
            "M98 L{} is more than {} (limit max_repeat_count)", e_.block_.get('l'),
            e_.opt_.limits.max_repeat_count);
  CallFrame& caller = e_.st_.frames.back();
  CallFrame frame;
  frame.kind = CallKind::Numbered;
  frame.return_to = e_.st_.next;
  if (e_.block_.has('l') && e_.mdi_.active) {
    // An MDI line is not read again: the body runs again from its M99 (L0: not at all).
    if (round_to_int(e_.block_.get('l')) == 0) return;
    frame.m98_runs_left = round_to_int(e_.block_.get('l')) - 1;
  } else if (e_.block_.has('l')) {
    if (caller.m98_left == -1) caller.m98_left = round_to_int(e_.block_.get('l'));
    --caller.m98_left;
    if (caller.m98_left > 0) {
      count_loop();
      frame.return_to = {e_.line_.file, e_.line_.offset, e_.line_.number};
    } else {
      caller.m98_left = -1;
    }
    if (round_to_int(e_.block_.get('l')) == 0) return;
  }
  enter_sub(std::move(frame), name, fmt::format("O{}", name));
}

// M99 in a subprogram: back to the caller (to the M98 line itself while its L repeats remain).
void FlowControl::o_m99() {
  ControlState& c = e_.st_.control;
  const CallFrame& f = e_.st_.frames.back();
  if (f.kind != CallKind::Numbered)
    mixed_styles(
        fmt::format("M99 in o<{}> (called by 'call': it ends with endsub or return)", f.sub).c_str());
  c.return_value = 0;
  c.value_returned = false;
  if (f.m98_runs_left > 0) {
    if (const LabelInfo* body = find_label(f.sub); body != nullptr) {
      --e_.st_.frames.back().m98_runs_left;
      count_loop();
      e_.jump_to(body->at);
      return;
    }
  }
  e_.jump_to(f.return_to);
  leave_frame();
}

bool FlowControl::open_sub_file(const std::string& name) {
  for (const std::string& dir : e_.opt_.subroutine_path) {
    const std::string path = dir.empty() ? name + ".ngc" : dir + "/" + name + ".ngc";
    auto file = SourceFile::open(path);
    if (!file) continue;
    const std::uint32_t index = e_.sources_->add_file(path);
    if (e_.files_.size() <= index) e_.files_.resize(index + 1);
    e_.files_[index] = std::move(file);
    e_.jump_to({index, 0, 1});
    return true;
  }
  return false;
}

void FlowControl::o_do() {
  e_.st_.control.skipping_to.clear();
  if (find_label(e_.block_.o_name) == nullptr) save_label(LabelKind::Do);
}

void FlowControl::o_while() {
  ControlState& c = e_.st_.control;
  LabelInfo* l = find_label(e_.block_.o_name);
  if (l != nullptr) {
    if (l->kind != LabelKind::Do && l->at.line != e_.line_.number)
      fail(ErrorCode::OwordLabelDuplicate, "{} is already used on line {}: give this {} its own label",
           label_text(e_.block_.o_name), l->at.line, "while");
  } else {
    save_label(LabelKind::While);
    l = find_label(e_.block_.o_name);
  }
  c.skipping_to.clear();
  if (l->kind == LabelKind::While) {
    if (e_.block_.o_value == 0.0) {
      c.skipping_to = e_.block_.o_name;
      c.skip_start_line = e_.line_.number;
    }
    return;
  }
  // The `while` that closes a do-loop.
  if (e_.block_.o_value != 0.0 && !c.doing_break) {
    count_loop();
    jump_to_label(e_.block_.o_name);
  } else {
    c.doing_break = false;
  }
}

void FlowControl::o_repeat() {
  ControlState& c = e_.st_.control;
  LabelInfo* l = find_label(e_.block_.o_name);
  if (l != nullptr) {
    if (l->at.line != e_.line_.number)
      fail(ErrorCode::OwordLabelDuplicate, "{} is already used on line {}: give this {} its own label",
           label_text(e_.block_.o_name), l->at.line, "repeat");
  } else {
    save_label(LabelKind::Repeat);
    l = find_label(e_.block_.o_name);
  }
  c.skipping_to.clear();
  if (l->kind != LabelKind::Repeat) return;
  if (l->repeat_left == -1) {
    const int count = round_to_int(e_.block_.o_value);
    if (e_.opt_.limits.max_repeat_count != 0 && count > 0 &&
        static_cast<std::uint64_t>(count) > e_.opt_.limits.max_repeat_count)
      fail(ErrorCode::LimitRepeatCount, "repeat [{}] is more than {} (limit max_repeat_count)", count,
           e_.opt_.limits.max_repeat_count);
    l->repeat_left = count;
  }
  if (l->repeat_left > 0) {
    --l->repeat_left;
  } else {
    c.skipping_to = e_.block_.o_name;
    c.skip_start_line = e_.line_.number;
    l->repeat_left = -1;
  }
}

void FlowControl::o_if() {
  ControlState& c = e_.st_.control;
  if (const LabelInfo* l = find_label(e_.block_.o_name)) {
    if (l->at.line != e_.line_.number)
      fail(ErrorCode::OwordLabelDuplicate, "{} is already used on line {}: give this {} its own label",
           label_text(e_.block_.o_name), l->at.line, "if");
  } else {
    save_label(LabelKind::If);
  }
  if (e_.block_.o_value != 0.0) {
    c.skipping_to.clear();
    c.executed_if = true;
  } else {
    c.skipping_to = e_.block_.o_name;
    c.skip_start_line = e_.line_.number;
    c.executed_if = false;
  }
}

void FlowControl::unmatched(const char* keyword, const char* opener, const char* other_opener) const {
  const std::string l = label_text(e_.block_.o_name);
  const std::string openers = other_opener == nullptr
                                  ? fmt::format("'{} {}'", l, opener)
                                  : fmt::format("'{} {}' or '{} {}'", l, opener, l, other_opener);
  fail(ErrorCode::OwordUnmatched, "'{} {}' has no {} before it: correct the label, or open the block first",
       l, keyword, openers);
}

void FlowControl::mismatched(const char* keyword, const LabelInfo& label) const {
  const std::string l = label_text(e_.block_.o_name);
  fail(ErrorCode::OwordMismatched, "'{} {}' does not fit '{} {}' (line {}): that block ends with '{} {}'", l,
       keyword, l, label_kind_name(label.kind), label.at.line, l, label_end_keyword(label.kind));
}

void FlowControl::o_elseif() {
  ControlState& c = e_.st_.control;
  const LabelInfo* l = find_label(e_.block_.o_name);
  if (l == nullptr) unmatched("elseif", "if");
  if (l->kind != LabelKind::If) mismatched("elseif", *l);
  if (c.executed_if) {
    c.skipping_to = e_.block_.o_name;
    c.skip_start_line = e_.line_.number;
    return;
  }
  if (e_.block_.o_value != 0.0) {
    c.skipping_to.clear();
    c.executed_if = true;
  }
}

void FlowControl::o_else() {
  ControlState& c = e_.st_.control;
  const LabelInfo* l = find_label(e_.block_.o_name);
  if (l == nullptr) unmatched("else", "if");
  if (l->kind != LabelKind::If) mismatched("else", *l);
  if (c.executed_if) {
    c.skipping_to = e_.block_.o_name;
    c.skip_start_line = e_.line_.number;
    return;
  }
  if (c.skipping_to == e_.block_.o_name) {
    c.executed_if = true;
    c.skipping_to.clear();
  }
}

void FlowControl::o_endif() {
  ControlState& c = e_.st_.control;
  const LabelInfo* l = find_label(e_.block_.o_name);
  if (l == nullptr) unmatched("endif", "if");
  if (l->kind != LabelKind::If) mismatched("endif", *l);
  c.skipping_to.clear();
  c.executed_if = true;
}

void FlowControl::o_break_continue(bool is_break) {
  ControlState& c = e_.st_.control;
  const char* what = is_break ? "break" : "continue";
  const LabelInfo* l = find_label(e_.block_.o_name);
  if (l == nullptr) unmatched(what, "while", "do");
  if (l->kind != LabelKind::While && l->kind != LabelKind::Do) mismatched(what, *l);
  if (!is_break && c.skipping_to == e_.block_.o_name) return;
  c.skipping_to = e_.block_.o_name;
  c.skip_start_line = e_.line_.number;
  if (is_break) c.doing_break = true;
  else c.doing_continue = true;
}

void FlowControl::o_end_loop() {
  ControlState& c = e_.st_.control;
  const bool repeat = e_.block_.o_type == OWord::EndRepeat;
  const LabelInfo* l = find_label(e_.block_.o_name);
  const char* what = repeat ? "endrepeat" : "endwhile";
  if (l == nullptr) unmatched(what, repeat ? "repeat" : "while");
  if ((repeat && l->kind != LabelKind::Repeat) || (!repeat && l->kind != LabelKind::While))
    mismatched(what, *l);
  if (c.skipping_to == e_.block_.o_name) {
    c.skipping_to.clear();
    if (!c.doing_continue) return;   // the loop is over
    c.doing_continue = false;
  }
  count_loop();
  jump_to_label(e_.block_.o_name);
}

}  // namespace opencnc::gcode
