// SPDX-License-Identifier: GPL-3.0-or-later
// MCodes — the M codes of one engine: I/O, tools (T, M6, M61), spindle, modal state save and
// restore, coolant, overrides, stops and program end (mcodes.cpp).
#pragma once

#include <string_view>

#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

class Engine;

/// Runs a block's M codes and T word. Reaches the engine's state through `e_` (a friend of the
/// engine). Interpreter thread.
class MCodes {
 public:
  explicit MCodes(Engine& e) noexcept : e_(e) {}
  MCodes(const MCodes&) = delete;
  MCodes& operator=(const MCodes&) = delete;

  void convert_m();  ///< the block's M codes but the stops; the block has some (m_count > 0)
  void select_tool(int tool);
  /// M0, M1, M2, M30, M60, M99 of the block.
  void convert_stop();
  void end_program(int code);
  /// The tool table index of `tool`; `at`: where the word naming the tool starts.
  int tool_index(int tool, int at) const;
  int pocket_of(int index) const noexcept;
  /// #5400-#5413 from the tool in the spindle.
  void set_tool_parameters();
  void restore_context(const SavedContext& saved);

 private:
  void convert_io();
  void convert_tool_change_group();
  void convert_spindle_group();
  void convert_coolant();
  void convert_overrides();
  void change_tool();
  void move_to_tool_change(int at);  ///< `at`: where the M6 starts (its errors point there)
  void set_tool_number(int tool);
  void load_spindle(int index);
  SavedContext active_context() const;
  void save_context(bool restore_on_return);
  void execute_text(std::string_view text);
  void repeat_main();

  Engine& e_;
  bool warned_repeat_ = false;  ///< M99 ended the main program (the repeat warning)
};

}  // namespace opencnc::gcode
