// SPDX-License-Identifier: GPL-3.0-or-later
// O-word control flow: subprogram definitions, calls and returns (also from files on the
// search path), if/elseif/else, while, do-while, repeat, break and continue. LinuxCNC runs
// these by skipping forward to a label and seeking back to a remembered line; so does this.
#include <cmath>

#include "engine.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {

const char* kind_name(LabelKind k) noexcept {
  switch (k) {
    case LabelKind::Sub: return "sub";
    case LabelKind::Do: return "do";
    case LabelKind::While: return "while";
    case LabelKind::Repeat: return "repeat";
    case LabelKind::If: return "if";
  }
  return "?";
}

// The label as the program wrote it (without the "sub#" scope prefix).
std::string_view plain(std::string_view key) noexcept {
  const std::size_t hash = key.find('#');
  return hash == std::string_view::npos ? key : key.substr(hash + 1);
}
}  // namespace

LabelInfo* Engine::find_label(const std::string& name) {
  auto it = st_.control.labels.find(name);
  return it == st_.control.labels.end() ? nullptr : &it->second;
}

void Engine::save_label(LabelKind kind) {
  LabelInfo info;
  info.kind = kind;
  info.at = {line_file_, line_offset_, line_};
  st_.control.labels[block_.o_name] = info;
}

void Engine::count_loop() {
  if (opt_.limits.max_loop_iterations != 0 && ++st_.loop_iterations > opt_.limits.max_loop_iterations)
    fail(ErrorCode::LimitLoopIterations, "more than {} loop iterations (limit max_loop_iterations)",
         opt_.limits.max_loop_iterations);
}

void Engine::jump_to_label(const std::string& name) {
  const LabelInfo* l = find_label(name);
  if (l == nullptr) fail(ErrorCode::LabelUndefined, "o{} is not defined", plain(name));
  jump_to(l->at);
}

void Engine::control_flow() {
  const Block& b = block_;
  ControlState& c = st_.control;
  if (!c.skipping_to.empty() && c.skipping_to != b.o_name) return;
  if (!c.seeking_sub.empty() && b.o_type != OWord::Sub) return;
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
      // A program number line: nothing to do in the main program (Fanuc subprograms, which
      // it would start, are not supported yet).
      if (st_.frames.size() > 1) fail(ErrorCode::Unsupported, "O{} program numbers inside a subprogram (Fanuc style) are not supported yet", block_.o_name);
      return;
    case OWord::None: return;
  }
}

void Engine::o_sub() {
  ControlState& c = st_.control;
  auto define = [&] {
    if (const LabelInfo* old = find_label(block_.o_name)) {
      if (old->at.line == line_ && old->at.file == line_file_)
        fail(ErrorCode::SubRedefined, "o<{}> sub is read a second time (a definition inside a loop or an if?)",
             block_.o_name);
      fail(ErrorCode::SubRedefined, "o<{}> is already defined ({}:{})", block_.o_name, sources_->file(old->at.file),
           old->at.line);
    }
    save_label(LabelKind::Sub);
  };
  if (!c.skipping_to.empty()) {
    // The sub a call was looking for.
    define();
    c.skipping_to.clear();
  }
  c.seeking_sub.clear();
  if (st_.frames.size() > 1) return;   // entering the body of a call
  if (c.defining_sub) fail(ErrorCode::NestedSub, "o<{}> sub inside the definition of o<{}>", block_.o_name, c.defining_name);
  define();
  // A definition in the flow of the program: pass over its body.
  c.skipping_to = block_.o_name;
  c.skip_start_line = line_;
  c.defining_sub = true;
  c.defining_name = block_.o_name;
}

void Engine::o_return() {
  ControlState& c = st_.control;
  c.return_value = block_.o_has_value ? block_.o_value : 0.0;
  c.value_returned = block_.o_has_value;
  if (st_.frames.size() == 1 && !c.defining_sub)
    fail(ErrorCode::NotInSub, "o<{}> {} outside a subprogram", block_.o_name,
         block_.o_type == OWord::EndSub ? "endsub" : "return");
  if (!c.skipping_to.empty() && block_.o_type == OWord::EndSub) c.skipping_to.clear();
  if (st_.frames.size() > 1) {
    CallFrame& f = st_.frames.back();
    for (int i = 0; i < kSubArgumentCount; ++i) st_.parameters[static_cast<std::size_t>(1 + i)] = f.saved_args[static_cast<std::size_t>(i)];
    jump_to(f.return_to);
    leave_frame();
    return;
  }
  if (block_.o_type == OWord::EndSub) {
    c.skipping_to.clear();
    c.defining_sub = false;
    c.defining_name.clear();
  }
}

void Engine::leave_frame() {
  const CallFrame leaving = std::move(st_.frames.back());
  st_.frames.pop_back();
  if (leaving.saved.valid && leaving.saved.restore_on_return) restore_context(leaving.saved);
}

void Engine::o_call() {
  const std::uint32_t depth = static_cast<std::uint32_t>(st_.frames.size());
  const std::uint32_t max_depth = opt_.limits.max_call_depth == 0 ? 10 : opt_.limits.max_call_depth;
  if (depth >= max_depth)
    fail(ErrorCode::CallDepth, "o<{}> call nests subprograms deeper than {} levels (limit max_call_depth)", block_.o_name,
         max_depth - 1);
  ControlState& c = st_.control;
  c.skipping_to.clear();
  CallFrame frame;
  frame.sub = block_.o_name;
  frame.return_to = st_.next;
  for (int i = 0; i < kSubArgumentCount; ++i) {
    frame.saved_args[static_cast<std::size_t>(i)] = st_.parameters[static_cast<std::size_t>(1 + i)];
    st_.parameters[static_cast<std::size_t>(1 + i)] = i < block_.arg_count ? block_.args[static_cast<std::size_t>(i)] : 0.0;
  }
  const std::uint32_t parent_context = st_.frames.back().context;
  const canon::SourceRef call_site{line_file_, line_, 1};
  st_.frames.push_back(std::move(frame));
  // Find the body: a sub met before, a file <name>.ngc on the search path, or later in this file.
  std::string name = block_.o_name;
  if (const std::size_t slash = name.rfind('/'); slash != std::string::npos) name = name.substr(slash + 1);
  if (const LabelInfo* l = find_label(name); l != nullptr && l->kind == LabelKind::Sub) {
    jump_to(l->at);
  } else {
    if (!open_sub_file(name) && in_mdi_)
      fail(ErrorCode::SubNotFound, "o<{}> is not defined and no {}.ngc is on the subroutine path", name, name);
    c.skipping_to = name;
    c.seeking_sub = name;
    c.skip_start_line = line_;
  }
  st_.frames.back().context =
      sources_->context(parent_context, call_site, st_.next.file, fmt::format("o<{}>", block_.o_name));
}

bool Engine::open_sub_file(const std::string& name) {
  for (const std::string& dir : opt_.subroutine_path) {
    const std::string path = dir.empty() ? name + ".ngc" : dir + "/" + name + ".ngc";
    auto file = SourceFile::open(path);
    if (!file) continue;
    const std::uint32_t index = sources_->add_file(path);
    if (files_.size() <= index) files_.resize(index + 1);
    files_[index] = std::move(file);
    jump_to({index, 0, 1});
    return true;
  }
  return false;
}

void Engine::o_do() {
  st_.control.skipping_to.clear();
  if (find_label(block_.o_name) == nullptr) save_label(LabelKind::Do);
}

void Engine::o_while() {
  ControlState& c = st_.control;
  LabelInfo* l = find_label(block_.o_name);
  if (l != nullptr) {
    if (l->kind != LabelKind::Do && l->at.line != line_)
      fail(ErrorCode::LabelDuplicate, "o{} is already used on line {}", plain(block_.o_name), l->at.line);
  } else {
    save_label(LabelKind::While);
    l = find_label(block_.o_name);
  }
  c.skipping_to.clear();
  if (l->kind == LabelKind::While) {
    if (block_.o_value == 0.0) {
      c.skipping_to = block_.o_name;
      c.skip_start_line = line_;
    }
    return;
  }
  // The `while` that closes a do-loop.
  if (block_.o_value != 0.0 && !c.doing_break) {
    count_loop();
    jump_to_label(block_.o_name);
  } else {
    c.doing_break = false;
  }
}

void Engine::o_repeat() {
  ControlState& c = st_.control;
  LabelInfo* l = find_label(block_.o_name);
  if (l != nullptr) {
    if (l->at.line != line_) fail(ErrorCode::LabelDuplicate, "o{} is already used on line {}", plain(block_.o_name), l->at.line);
  } else {
    save_label(LabelKind::Repeat);
    l = find_label(block_.o_name);
  }
  c.skipping_to.clear();
  if (l->kind != LabelKind::Repeat) return;
  if (l->repeat_left == -1) {
    const int count = round_to_int(block_.o_value);
    if (opt_.limits.max_repeat_count != 0 && count > 0 && static_cast<std::uint64_t>(count) > opt_.limits.max_repeat_count)
      fail(ErrorCode::LimitRepeatCount, "repeat [{}] is more than {} (limit max_repeat_count)", count,
           opt_.limits.max_repeat_count);
    l->repeat_left = count;
  }
  if (l->repeat_left > 0) {
    --l->repeat_left;
  } else {
    c.skipping_to = block_.o_name;
    c.skip_start_line = line_;
    l->repeat_left = -1;
  }
}

void Engine::o_if() {
  ControlState& c = st_.control;
  if (const LabelInfo* l = find_label(block_.o_name)) {
    if (l->at.line != line_) fail(ErrorCode::LabelDuplicate, "o{} is already used on line {}", plain(block_.o_name), l->at.line);
  } else {
    save_label(LabelKind::If);
  }
  if (block_.o_value != 0.0) {
    c.skipping_to.clear();
    c.executed_if = true;
  } else {
    c.skipping_to = block_.o_name;
    c.skip_start_line = line_;
    c.executed_if = false;
  }
}

void Engine::o_elseif() {
  ControlState& c = st_.control;
  const LabelInfo* l = find_label(block_.o_name);
  if (l == nullptr) fail(ErrorCode::LabelUndefined, "elseif with no 'o{} if' before it", plain(block_.o_name));
  if (l->kind != LabelKind::If)
    fail(ErrorCode::LabelMismatch, "elseif for o{} does not match its '{}' on line {}", plain(block_.o_name), kind_name(l->kind), l->at.line);
  if (c.executed_if) {
    c.skipping_to = block_.o_name;
    c.skip_start_line = line_;
    return;
  }
  if (block_.o_value != 0.0) {
    c.skipping_to.clear();
    c.executed_if = true;
  }
}

void Engine::o_else() {
  ControlState& c = st_.control;
  const LabelInfo* l = find_label(block_.o_name);
  if (l == nullptr) fail(ErrorCode::LabelUndefined, "else with no 'o{} if' before it", plain(block_.o_name));
  if (l->kind != LabelKind::If)
    fail(ErrorCode::LabelMismatch, "else for o{} does not match its '{}' on line {}", plain(block_.o_name), kind_name(l->kind), l->at.line);
  if (c.executed_if) {
    c.skipping_to = block_.o_name;
    c.skip_start_line = line_;
    return;
  }
  if (c.skipping_to == block_.o_name) {
    c.executed_if = true;
    c.skipping_to.clear();
  }
}

void Engine::o_endif() {
  ControlState& c = st_.control;
  const LabelInfo* l = find_label(block_.o_name);
  if (l == nullptr) fail(ErrorCode::LabelUndefined, "endif with no 'o{} if' before it", plain(block_.o_name));
  if (l->kind != LabelKind::If)
    fail(ErrorCode::LabelMismatch, "endif for o{} does not match its '{}' on line {}", plain(block_.o_name), kind_name(l->kind), l->at.line);
  c.skipping_to.clear();
  c.executed_if = true;
}

void Engine::o_break_continue(bool is_break) {
  ControlState& c = st_.control;
  const char* what = is_break ? "break" : "continue";
  const LabelInfo* l = find_label(block_.o_name);
  if (l == nullptr) fail(ErrorCode::LabelUndefined, "{} with no loop o{} around it", what, plain(block_.o_name));
  if (l->kind != LabelKind::While && l->kind != LabelKind::Do)
    fail(ErrorCode::LabelMismatch, "{} for o{} does not match its '{}' on line {}", what, plain(block_.o_name), kind_name(l->kind),
         l->at.line);
  if (!is_break && c.skipping_to == block_.o_name) return;
  c.skipping_to = block_.o_name;
  c.skip_start_line = line_;
  if (is_break) c.doing_break = true;
  else c.doing_continue = true;
}

void Engine::o_end_loop() {
  ControlState& c = st_.control;
  const bool repeat = block_.o_type == OWord::EndRepeat;
  const LabelInfo* l = find_label(block_.o_name);
  if (l == nullptr) fail(ErrorCode::LabelUndefined, "{} with no loop o{} before it", repeat ? "endrepeat" : "endwhile", plain(block_.o_name));
  if ((repeat && l->kind != LabelKind::Repeat) || (!repeat && l->kind != LabelKind::While))
    fail(ErrorCode::LabelMismatch, "{} for o{} does not match its '{}' on line {}", repeat ? "endrepeat" : "endwhile",
         plain(block_.o_name), kind_name(l->kind), l->at.line);
  if (c.skipping_to == block_.o_name) {
    c.skipping_to.clear();
    if (!c.doing_continue) return;   // the loop is over
    c.doing_continue = false;
  }
  count_loop();
  jump_to_label(block_.o_name);
}

}  // namespace opencnc::gcode
