// SPDX-License-Identifier: GPL-3.0-or-later
// GcodeProgramSource — the ProgramSource of a real controller: gcode::Interpreter in scan mode for
// the preflight, in execute mode (streaming, sync points) for runs, into canon::ProgramBuilder.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::gcode {
struct Extensions;
}

namespace opencnc::controller {

/// How the G-code source is set up.
struct GcodeSourceConfig {
  /// The base: axes, axis map, subroutine path, units (mm), machine kind, the default dialect
  /// (a program's own `(dialect: …)` comment wins over it).
  gcode::Options options;
  /// The machine's tool table (null: none): G43 and G41/G42 read it, G10 L1/L10/L11 write it
  /// (while a program runs, not in its preflight). At sync points the interpreter takes the
  /// operator's changes.
  std::shared_ptr<tools::ToolTableService> tools;
  /// Path tolerance (mm) while a program sets no G64 P (the profile's planner.default_tolerance).
  double default_tolerance_mm = 0;
  /// What the machine's features add, in order: code modules on top of the dialect's standard
  /// ones, and passes every move goes through as the builder appends it (extensions.hpp).
  std::vector<std::shared_ptr<const SourcePart>> parts;
};

/// What a scan shows its reader: every move as the features' passes leave it, and the actions
/// before it, in order.
class ScanReader {
 public:
  virtual ~ScanReader() = default;
  /// Action `index` of `program` (before the next move). False: the scan stops here.
  virtual bool action(const canon::Program& /*program*/, std::size_t /*index*/) { return true; }
  /// Move `move` of `program`. False: the scan stops here.
  virtual bool move(const canon::Program& program, canon::SegmentId move) = 0;
};

/// Programs and MDI lines through the interpreter, in millimetres. Before a program, and before
/// an MDI line, the interpreter is placed where the machine is (Interpreter::set_machine_position),
/// so incremental moves and arcs start from there. While a program sets no G64 P the default
/// tolerance applies. The moves go through the features' passes (GcodeSourceConfig::parts) as
/// they are appended. Non-real-time; one thread (the controller's).
class GcodeProgramSource final : public ProgramSource {
 public:
  /// The profile's dialect, machine kind, axes and axis map, subroutine path, default tolerance,
  /// and its tool table file as a tools::FileToolTable (G10 L1 writes it back), without any
  /// feature's parts (controller::MachineSetup adds them); problems with it land in `diags` (errors:
  /// nullptr).
  static std::shared_ptr<GcodeProgramSource> create(const config::MachineProfile& profile, Diagnostics& diags);
  /// create()'s configuration, for a set-up that adds to it before building the source; nothing
  /// (and diagnostics) on errors.
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
  /// `path` read once in scan mode (the machine's answers at sync points assumed, as the
  /// preflight's first pass) from `start`, through the features' passes: every move and action to
  /// `reader`, in order, in bounded memory (what it has seen is released). Returns the
  /// interpreter's and the passes' problems. Non-real-time; any thread (the preview's), beside
  /// the controller's use of the source.
  Diagnostics scan(const std::string& path, const Pose& start, const LoadOptions& options,
                   ScanReader& reader) const;
  std::uint64_t version() const override {
    return (config_.tools ? config_.tools->version() : 0) + parts_changed_;
  }
  /// Each feature's part for `profile` (SourcePart::for_profile): an EDM's condition numbers after
  /// a condition was added or deleted.
  void profile_changed(const config::MachineProfile& profile) override;

  /// The tool table G-code reads and writes (null: none). Any thread.
  const std::shared_ptr<tools::ToolTableService>& tools() const noexcept { return config_.tools; }
  /// The interpreter options a file runs with: its dialect (its own comment, else the default)
  /// and modules. Non-real-time.
  gcode::Options options_for(const std::string& path, const LoadOptions& options) const;

 private:
  /// The features' parts as they are now (profile_changed() may replace them on the controller's
  /// thread while scan() reads them on another).
  std::vector<std::shared_ptr<const SourcePart>> parts() const;

  GcodeSourceConfig config_;
  mutable std::mutex parts_mutex_;           ///< config_.parts
  std::unique_ptr<gcode::Interpreter> mdi_;  ///< the MDI session: modal state lives on
  std::uint64_t mdi_tools_version_ = 0;
  std::uint64_t parts_changed_ = 0;  ///< counts the profile changes a part took
  std::uint64_t mdi_parts_ = 0;      ///< parts_changed_ when mdi_ was made (its modules)
};

}  // namespace opencnc::controller
