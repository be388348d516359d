// SPDX-License-Identifier: GPL-3.0-or-later
// The lathe cycles' moves as the core's G0/G1/G2/G3, and the problem codes of the roughing
// engine's errors: shared by LinuxCNC's G70-G72 (lathe_cycles.cpp) and Fanuc's G71/G72
// (fanuc_roughing.cpp).
#pragma once

#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/lathe_roughing.hpp"

namespace opencnc::gcode {

/// Cutter compensation suspended for one move (restored also when the move fails).
struct CompensationOff {
  explicit CompensationOff(ModalState& m) : modal(m), saved(m.cutter_comp) { m.cutter_comp = CutterComp::Off; }
  ~CompensationOff() { modal.cutter_comp = saved; }
  CompensationOff(const CompensationOff&) = delete;
  CompensationOff& operator=(const CompensationOff&) = delete;
  ModalState& modal;
  CutterComp saved;
};

/// The cycle's moves as the core's G0/G1/G2/G3 with absolute XZ words (the caller runs the
/// cycle in G90 and G90.1). Interpreter thread, during the cycle's block only.
class CycleMoves final : public lathe::PathSink {
 public:
  /// `skip_still`: leave out straight moves that end where the tool already is (LinuxCNC's
  /// cycle prints them; Fanuc's have no use for them).
  explicit CycleMoves(ExecContext& ctx, bool skip_still = false) : ctx_(ctx), skip_still_(skip_still) {}
  void rapid(lathe::Point end) override { move(0, end); }
  void approach(lathe::Point end) override;
  void feed(lathe::Point end) override { move(10, end); }
  void arc(lathe::Point end, lathe::Point centre, bool ccw) override;

 private:
  void move(int motion, lathe::Point end);

  ExecContext& ctx_;
  bool skip_still_;
};

/// The problem code of a roughing engine error.
ErrorCode roughing_error_code(lathe::RoughingError::Kind kind) noexcept;

}  // namespace opencnc::gcode
