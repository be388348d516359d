// SPDX-License-Identifier: GPL-3.0-or-later
// MachineFeatures — the controller features a profile calls for, set up as every front end sets
// them up (features::set_up on a controller::MachineSetup), and a board that snapshots their state on
// the controller's thread for the HMI's status (docs/hmi.md, "Features").
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/machine_setup.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::hmi {

struct FeatureOptions {
  /// The breakpoint journal's folder (created if missing). Used when the profile has a power
  /// monitor (`[power] monitor`); "" then means no journal.
  std::string journal_dir;
};

/// The features of one machine. create() on the thread that sets the server up; install() once,
/// before the controller runs; status() from any thread.
class MachineFeatures {
 public:
  /// The profile's program source and the features it calls for (features::set_up): with
  /// `[tool_guard]` the tool store as its table and "tool-guard", "journal" with a power monitor
  /// and a journal folder, "electrode" with `[probe.reference_sphere]` and a tool table,
  /// "retrace" with `[process.cutting]`, "run-from-line" always. Nullptr with the reasons in
  /// `diags` (a journal folder or tool store that cannot be opened).
  static std::unique_ptr<MachineFeatures> create(const config::MachineProfile& profile,
                                                 const FeatureOptions& options, Diagnostics& diags);
  ~MachineFeatures();
  MachineFeatures(const MachineFeatures&) = delete;
  MachineFeatures& operator=(const MachineFeatures&) = delete;

  /// The program source the controller and the server use. Any thread.
  const std::shared_ptr<controller::GcodeProgramSource>& source() const noexcept { return source_; }
  /// Adds the features and the board that follows them to `controller` (before it runs).
  void install(controller::Controller& controller);
  /// The names of the installed features, in installation order. Any thread.
  const std::vector<std::string>& names() const noexcept { return names_; }
  /// Whether feature `name` is installed. Any thread.
  bool has(std::string_view name) const;
  /// The features' state as of the controller's last status period (docs/api.md, "features"):
  /// `{"installed": […], "journal": {…}, "retrace": {…}, "electrode": {…}, "tool_guard": {…},
  /// "edm": {…}}`, each present when its feature is. Any thread.
  nlohmann::json status() const;

 private:
  class Board;
  MachineFeatures() = default;
  nlohmann::json snapshot(const controller::ControllerStatus& s);  // controller thread

  std::unique_ptr<controller::MachineSetup> setup_;
  std::shared_ptr<controller::GcodeProgramSource> source_;
  std::vector<std::string> names_;

  mutable std::mutex mutex_;
  nlohmann::json state_;  ///< the board's last snapshot
};

}  // namespace opencnc::hmi
