// SPDX-License-Identifier: GPL-3.0-or-later
// GcodeProgramSource — the ProgramSource of a real controller: gcode::Interpreter in scan mode for
// the preflight, in execute mode (streaming, sync points) for runs, into canon::ProgramBuilder.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/coupling_pass.hpp"
#include "opencnc/controller/hand_axis.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::gcode {
struct Extensions;
}

namespace opencnc::control {

/// The passes a program's moves go through as the builder appends them.
struct MovePasses {
  HandAxes hand;         ///< hand-fed axes (hand_axis.hpp)
  CoupledAxes coupling;  ///< the axis coupling (coupling_pass.hpp)
};

/// How the G-code source is set up.
struct GcodeSourceConfig {
  /// The base: axes, axis map, subroutine path, units (mm), machine kind, the default dialect
  /// (a program's own `(dialect: …)` comment wins over it).
  gcode::Options options;
  /// The code modules for a dialect; empty: gcode::standard_extensions. A feature that brings
  /// G or M codes of its own (a coupling law, machining conditions) gives a function that adds
  /// its modules to the standard ones.
  std::function<std::shared_ptr<const gcode::Extensions>(gcode::Dialect)> extensions;
  /// On an EDM (a profile with [edm]): the numbers of its machining conditions. M180 and M181
  /// are added to the modules above, and M180's P must be one of these (profile_changed() takes
  /// them again from an edited profile). Null on any other machine.
  std::shared_ptr<const std::vector<int>> edm_conditions;
  /// The machine's tool table (null: none): G43 and G41/G42 read it, G10 L1/L10/L11 write it
  /// (while a program runs, not in its preflight). At sync points the interpreter takes the
  /// operator's changes.
  std::shared_ptr<tools::ToolTableService> tools;
  /// Path tolerance (mm) while a program sets no G64 P (the profile's planner.default_tolerance).
  double default_tolerance_mm = 0;
  /// Hand-fed axes: their programmed moves become waits for the operator (hand_axis.hpp).
  HandAxes hand;
  /// The axis coupling of the broaching codes: while a law holds, the slave's coordinates come
  /// from it and its limits are checked through it (coupling_pass.hpp).
  CoupledAxes coupling;
};

/// Programs and MDI lines through the interpreter, in millimetres. Before a program, and before
/// an MDI line, the interpreter is placed where the machine is (Interpreter::set_machine_position),
/// so incremental moves and arcs start from there. While a program sets no G64 P the default
/// tolerance applies. On a machine with hand-fed axes the moves go through the hand-axis pass
/// (hand_axis.hpp). Non-real-time; one thread (the controller's).
class GcodeProgramSource final : public ProgramSource {
 public:
  /// The profile's dialect, machine kind, axes and axis map, subroutine path, default tolerance,
  /// and its tool table file as a tools::FileToolTable (G10 L1 writes it back); problems with it
  /// land in `diags` (errors: nullptr).
  static std::shared_ptr<GcodeProgramSource> create(const config::MachineProfile& profile, Diagnostics& diags);
  /// create()'s configuration, for a feature that changes a part of it (its own tool table or
  /// code modules) before building the source; nothing (and diagnostics) on errors.
  static std::optional<GcodeSourceConfig> config_for(const config::MachineProfile& profile,
                                                     Diagnostics& diags);
  explicit GcodeProgramSource(GcodeSourceConfig config);
  ~GcodeProgramSource() override;

  Preflight preflight(const std::string& path, const Pose& start, const LoadOptions& options,
                      MoveCheck& check) override;
  std::unique_ptr<ProgramStream> execute(const std::string& path, const Pose& start,
                                         const LoadOptions& options) override;
  std::unique_ptr<ProgramStream> resume(const std::string& path, const Pose& program_start, const Pose& start,
                                        canon::SegmentId segment, const LoadOptions& options) override;
  std::unique_ptr<ProgramStream> mdi(std::string_view line, const Pose& start) override;
  std::uint64_t version() const override {
    return (config_.tools ? config_.tools->version() : 0) + conditions_changed_;
  }
  /// An EDM's condition numbers taken again from `profile` (a condition added or deleted).
  void profile_changed(const config::MachineProfile& profile) override;

  /// The tool table G-code reads and writes (null: none). Any thread.
  const std::shared_ptr<tools::ToolTableService>& tools() const noexcept { return config_.tools; }
  /// The interpreter options a file runs with: its dialect (its own comment, else the default)
  /// and modules. Non-real-time.
  gcode::Options options_for(const std::string& path, const LoadOptions& options) const;

 private:
  MovePasses passes() const { return {config_.hand, config_.coupling}; }
  GcodeSourceConfig config_;
  std::unique_ptr<gcode::Interpreter> mdi_;  ///< the MDI session: modal state lives on
  std::uint64_t mdi_tools_version_ = 0;
  std::uint64_t conditions_changed_ = 0;  ///< counts changes of config_.edm_conditions
  std::shared_ptr<const std::vector<int>> mdi_conditions_;  ///< the numbers mdi_ was made with
};

}  // namespace opencnc::control
