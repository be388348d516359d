// SPDX-License-Identifier: GPL-3.0-or-later
// FanucDialect — the Fanuc dialect's side of the interpreter: its programs, calls and loops
// (flow.cpp), its words rewritten into the core's (translate.cpp), its variables (vars.cpp), its
// header and foreign lines, its block ranges (dialect.cpp). The engine reaches it only through
// the dialect hooks (fanuc_hooks()), chosen when a program opens.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>

#include "../dialect_hooks.hpp"
#include "../engine.hpp"
#include "index.hpp"

namespace opencnc::gcode {

/// The Fanuc dialect's state and work for one engine. Interpreter thread.
class FanucDialect final : public DialectState {
 public:
  /// Sets `e` up for the dialect: #0, the locals and the commons vacant; on a lathe U and W are
  /// incremental X and Z.
  explicit FanucDialect(Engine& e);

  // flow.cpp: programs, calls and loops
  void start();
  bool percent_line();
  void end_of_file();
  void control_flow();
  void program_line();
  void block_done();
  bool stop_code(int m);
  bool leave_call(const CallFrame& f);

  // translate.cpp: Fanuc words and codes rewritten into the core's before the checks
  void translate();
  void after_block();

  // vars.cpp: system variables, vacancy, #3000 alarms and #3006 stops
  bool variable(int index, double& value);
  void assignments();

  // dialect.cpp: another controller's syntax, block ranges
  void foreign_syntax();
  void read_block_range(std::int64_t first, std::int64_t last, std::string_view what,
                        const std::function<void(const Block&)>& visit);

 private:
  void go_to(std::int64_t n);
  void while_do();
  void end_do();
  void call(std::uint32_t program, int count, bool macro);
  void range();
  void return_from_call();
  SourcePosition find_program(std::uint32_t program);
  bool program_file(std::uint32_t program, SourcePosition& at);
  const FanucIndex::Region& region(const SourcePosition& start);
  SourcePosition sequence(const SourcePosition& program_start, std::int64_t n, std::string_view what);
  std::string program_name(const FanucFrame& f) const;
  bool only_comments_between(const SourcePosition& from, const SourcePosition& to);
  void lathe_words();
  void lathe_tool();
  void lathe_codes();
  void dwell();
  void transform_conflicts();
  bool block_has_content() const noexcept;
  double computed(int index) const;
  double modal(int group) const;

  Engine& e_;
  FanucIndex index_;  ///< program lines, sequence numbers, loops of the files read
  std::map<std::uint32_t, SourcePosition> programs_;  ///< O number → program line found
  double p_ = -1;      ///< M98/M99 P of the block (taken out before the checks)
  double l_ = -1;      ///< M98 L of the block
  double clamp_ = -1;  ///< G50 S / G92 S of the block
};

/// The Fanuc dialect's hooks. Any thread.
const DialectHooks& fanuc_hooks() noexcept;

}  // namespace opencnc::gcode
