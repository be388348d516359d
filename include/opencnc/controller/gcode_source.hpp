// SPDX-License-Identifier: GPL-3.0-or-later
// GcodeProgramSource — the ProgramSource of a real controller: gcode::Interpreter (scan mode)
// into canon::ProgramBuilder, set up from the machine profile.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/hand_axis.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::control {

/// Programs and MDI lines through the interpreter, with the profile's dialect, subroutine
/// path, tool table and axes, in millimetres. While a program sets no G64 P the profile's
/// planner.default_tolerance applies. Before a program, and before an MDI line when the machine
/// has moved since the last one, the interpreter is told where the machine is (a G53 G0 to it,
/// run without output), so that incremental moves and arcs start from there; in MDI an arc or
/// canned-cycle motion mode is then cancelled (G80) rather than left for a line without G code.
/// On a machine with hand-fed axes the programs go through the hand-axis pass (hand_axis.hpp).
/// Non-real-time; one thread.
class GcodeProgramSource final : public ProgramSource {
 public:
  /// Reads the profile's tool table; its problems land in `diags` (errors: nullptr).
  static std::shared_ptr<GcodeProgramSource> create(const config::MachineProfile& profile,
                                                    Diagnostics& diags);

  LoadedProgram load(const std::string& path, const Pose& start, const LoadOptions& options) override;
  LoadedProgram mdi(std::string_view line, const Pose& start) override;

 private:
  GcodeProgramSource(gcode::Options options, double default_tolerance, HandAxes hand);
  bool place(gcode::Interpreter& interp, const Pose& machine, Diagnostics& diags) const;
  void replay_state(const gcode::InterpState& s, canon::ProgramBuilder& b) const;

  gcode::Options options_;
  double default_tolerance_;
  HandAxes hand_;
  std::unique_ptr<gcode::Interpreter> mdi_;  ///< the MDI session: modal state lives on
  Pose mdi_end_{};                           ///< where the last MDI line left the machine
  bool mdi_placed_ = false;
};

}  // namespace opencnc::control
