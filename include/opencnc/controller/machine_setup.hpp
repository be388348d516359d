// SPDX-License-Identifier: GPL-3.0-or-later
// MachineSetup — a machine as its features set it up: the profile's G-code source with what each
// feature adds to it, and the features, observers, texts and move reaches for its controller. The
// command line and the HMI build it the same way: every feature's setup(profile, host) is called
// on it (features::set_up), then the front end takes the source, builds the controller and
// installs the rest (docs/code-overview.md, "How to add a machine feature").
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::controller {

/// The host a feature's setup adds its parts to, and what a front end takes from it. Built and set
/// up on one thread before the controller runs; the sources it makes are the controller's and the
/// features' own.
class MachineSetup {
 public:
  /// What the front end asks of the features.
  struct Options {
    /// The front end writes a report of each run (the command line): features add the observers
    /// that write its sections (ReportSection).
    bool reports = false;
    /// Settings the front end hands the features by name: "journal" (the breakpoint journal's
    /// folder), "tool-table" ("memory": the program source's table is a copy in memory).
    std::map<std::string, std::string, std::less<>> settings;
    /// The program source's tool table when the front end brings its own (null: the profile's).
    std::shared_ptr<tools::ToolTableService> tools;

    /// Options with one setting.
    static Options with(std::string name, std::string value) {
      Options o;
      o.settings.emplace(std::move(name), std::move(value));
      return o;
    }
    /// Options with the front end's own tool table.
    static Options with_tools(std::shared_ptr<tools::ToolTableService> table) {
      Options o;
      o.tools = std::move(table);
      return o;
    }
  };

  /// The profile's G-code source configuration (GcodeProgramSource::config_for) to start from;
  /// null with the reasons in `diags` when it cannot be made (a tool table that cannot be read).
  static std::unique_ptr<MachineSetup> create(const config::MachineProfile& profile, Options options,
                                              Diagnostics& diags);
  ~MachineSetup();
  MachineSetup(const MachineSetup&) = delete;
  MachineSetup& operator=(const MachineSetup&) = delete;

  const config::MachineProfile& profile() const noexcept { return profile_; }
  /// Where a feature's setup puts the problems that stop it (setup then returns false).
  Diagnostics& diagnostics() noexcept { return diags_; }
  bool reports() const noexcept { return options_.reports; }
  /// A setting of the front end's by name, or null.
  const std::string* setting(std::string_view name) const;

  // --- what a feature's setup adds ----------------------------------------------------------
  /// The G-code source's configuration so far: a feature may give it another tool table (the tool
  /// guard's store). Before source() is first called.
  GcodeSourceConfig& source_config() noexcept { return config_; }
  /// Code modules and a pass over the moves, for every source made from here on.
  void add_source_part(std::shared_ptr<const SourcePart> part);
  /// What the feature's process adds around a move, for the soft-limit check.
  void add_move_reach(MoveReachFactory reach);
  /// The words of the feature's events, faults and waits.
  void add_texts(std::shared_ptr<const EventTexts> texts);
  /// A feature for the controller (requests, starts, sync points), following the status (and the
  /// trace) as `options` say.
  void add_feature(std::shared_ptr<Feature> feature, ObserverOptions options);
  /// An observer for the controller (a recorder writing a report section).
  void add_observer(std::shared_ptr<ControllerObserver> observer, ObserverOptions options);
  /// A part of the features' state a front end shows (the HMI's status), in this order.
  void add_state(std::shared_ptr<FeatureState> state);
  /// A new G-code source like the controller's, for a feature that scans or replays on its own;
  /// from the configuration as it is now (so features that add parts are set up before those
  /// that make sources). Its own tool table when `tools` is given.
  std::shared_ptr<GcodeProgramSource> make_source(
      std::shared_ptr<tools::ToolTableService> tools = nullptr) const;

  // --- what the front end takes -------------------------------------------------------------
  /// The controller's G-code source (made at the first call).
  const std::shared_ptr<GcodeProgramSource>& source();
  /// Adds the features, observers, texts and move reaches to `controller`, before it runs (once).
  void install(Controller& controller);
  /// The features and observers added, in order, with their options (a front end looks among them
  /// for the ones that write report sections or carry state).
  const std::vector<std::pair<std::shared_ptr<Feature>, ObserverOptions>>& features() const noexcept {
    return features_;
  }
  const std::vector<std::pair<std::shared_ptr<ControllerObserver>, ObserverOptions>>& observers()
      const noexcept {
    return observers_;
  }
  /// The feature named `name`, or null.
  std::shared_ptr<Feature> feature(std::string_view name) const;
  /// The features' states for a front end's status (add_state), in order.
  const std::vector<std::shared_ptr<FeatureState>>& states() const noexcept { return states_; }

 private:
  MachineSetup(const config::MachineProfile& profile, Options options, GcodeSourceConfig config);

  config::MachineProfile profile_;
  Options options_;
  GcodeSourceConfig config_;
  Diagnostics diags_;
  std::shared_ptr<GcodeProgramSource> source_;
  std::vector<MoveReachFactory> reaches_;
  std::vector<std::shared_ptr<const EventTexts>> texts_;
  std::vector<std::pair<std::shared_ptr<Feature>, ObserverOptions>> features_;
  std::vector<std::pair<std::shared_ptr<ControllerObserver>, ObserverOptions>> observers_;
  std::vector<std::shared_ptr<FeatureState>> states_;
};

}  // namespace opencnc::controller
