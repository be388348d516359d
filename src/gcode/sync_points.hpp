// SPDX-License-Identifier: GPL-3.0-or-later
// SyncPoints — where a block needs the machine's feedback (probe, M66, tool change, program
// stop): what execute mode waits for, what scan mode assumes, and the answer's effect on the
// parameters and the position (sync_points.cpp).
#pragma once

#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

/// One engine's sync points. Holds no reference to the engine: the state an answer changes is
/// passed in. Interpreter thread.
class SyncPoints {
 public:
  /// What the machine must answer before the next block (None: nothing).
  SyncKind pending() const noexcept { return pending_; }
  /// What the pending sync point asked for (its kind, the probe's expectations).
  const SyncValues& request() const noexcept { return request_; }

  /// A block needs feedback. Execute mode waits for it (pending()); scan mode assumes
  /// `assumed` and applies it when the block is done (end_of_block()).
  void ask(const SyncValues& assumed, Mode mode);
  /// After each block: scan mode's assumed feedback takes effect now, so that the codes of the
  /// block that asked did not see it (LinuxCNC reads it before the next block). Inline: a test
  /// of one flag on every line.
  void end_of_block(InterpState& st) {
    if (block_pending_) apply_assumed(st);
  }

  /// How the machine's answer ended the probe move it answers.
  enum class Answer : std::uint8_t { Done, NoContact, ContactKept };
  /// Execute mode: the machine's answer to the pending request, applied to `st`. A program
  /// stop that followed the request becomes pending. Done also when nothing was pending.
  Answer answer(const SyncValues& values, InterpState& st);

 private:
  static void apply(const SyncValues& values, InterpState& st);
  void apply_assumed(InterpState& st);

  SyncKind pending_ = SyncKind::None;
  SyncValues request_;          ///< execute mode: what the pending sync point asked for
  bool stop_after_ = false;     ///< execute mode: a program stop follows the pending sync
  SyncValues assumed_;          ///< scan mode: feedback assumed at the end of this block
  bool block_pending_ = false;  ///< scan mode: `assumed_` is still to be applied
};

}  // namespace opencnc::gcode
