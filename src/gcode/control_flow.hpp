// SPDX-License-Identifier: GPL-3.0-or-later
// FlowControl — the O-words of one engine: subprogram definitions, calls and returns,
// if/elseif/else, while, do-while, repeat, break and continue (control_flow.cpp).
#pragma once

#include <string>
#include <string_view>

#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

class Engine;

/// Runs a block's O-word and keeps the call frames. Reads and moves the engine's lines through
/// `e_` (a friend of the engine). Interpreter thread.
class FlowControl {
 public:
  explicit FlowControl(Engine& e) noexcept : e_(e) {}
  FlowControl(const FlowControl&) = delete;
  FlowControl& operator=(const FlowControl&) = delete;

  /// Runs the O-word of the engine's block (Block::o_type is not None).
  void control_flow();
  void o_call();
  /// An MDI line failed inside the subprogram it called: every call is left as if it returned.
  void abandon_calls();
  void leave_frame();
  /// A loop turned once more (the bound Limits::max_loop_iterations).
  void count_loop();
  LabelInfo* find_label(const std::string& name);

 private:
  void o_sub();
  void o_return();
  void o_do();
  void o_while();
  void o_repeat();
  void o_if();
  void o_elseif();
  void o_else();
  void o_endif();
  void o_break_continue(bool is_break);
  void o_end_loop();
  void o_program();
  void o_m98();
  void o_m99();
  void enter_sub(CallFrame frame, std::string name, std::string_view context_name);
  [[noreturn]] void mixed_styles(const char* what) const;
  [[noreturn]] void unmatched(const char* keyword, const char* opener,
                              const char* other_opener = nullptr) const;
  [[noreturn]] void mismatched(const char* keyword, const LabelInfo& label) const;
  void save_label(LabelKind kind);
  void jump_to_label(const std::string& name);
  bool open_sub_file(const std::string& name);

  Engine& e_;
};

}  // namespace opencnc::gcode
