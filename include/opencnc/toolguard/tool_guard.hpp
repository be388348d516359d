// SPDX-License-Identifier: GPL-3.0-or-later
// The tool-offset guard: the live tool table checked against its backup before a program starts
// and at each tool change (a controller Feature that refuses or holds), on demand from G-code
// (a user M-code) and from the command line; the operator accepts or restores.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/store/tool_store.hpp"
#include "opencnc/tools/tool_check.hpp"

namespace opencnc::toolguard {

/// The tolerances of the profile's [tool_guard]. Any thread.
tools::CheckTolerances tolerances(const config::ToolGuardProfile& p) noexcept;

/// What one check found.
struct CheckResult {
  std::optional<store::BackupInfo> backup;     ///< the backup compared with (none: no backup yet)
  std::vector<tools::Difference> differences;  ///< beyond the tolerances, in T, D order
  std::string error;                           ///< the store could not be read

  bool ok() const noexcept { return error.empty() && backup && differences.empty(); }
  /// The first line ("the live tool table differs from backup 3 of 2026-…Z in 1 value:") then
  /// one line per difference ("T53 D1 length1: backup 193.225, live 139.225 (…)"). Any thread.
  std::string report() const;
};

/// Compares the live table with the current backup; only the edges of tool `tool` when given.
/// Any thread (the store locks).
CheckResult check(store::ToolStore& store, const tools::CheckTolerances& tolerances,
                  std::optional<int> tool = std::nullopt);

/// The Feature "tool-guard" of the controller hub. Refuses cycle start when the check fails
/// (profile: check at start), holds the program at a tool change whose tool differs (check at
/// tool change) until the live table passes: the operator accepts (the live values become a new
/// backup) or restores (the backup's values become live) with requests::Feature{"tool-guard",
/// "accept"|"restore"|"check"} (restore's args: a backup id as std::int64_t, else the
/// current one). Every result is a note with the difference lines. Accept and restore write the
/// store, which may wait for another writer's lock: they are the controller's long work
/// (FeatureHost::answer_after), so its loop never waits for the database. Controller thread.
class ToolGuard final : public control::Feature {
 public:
  /// `pockets`: the magazine's pockets (0: not checked); a tool in a pocket beyond it refuses
  /// the start like a difference.
  ToolGuard(std::shared_ptr<store::ToolStore> store, const config::ToolGuardProfile& profile,
            int pockets = 0);

  std::string_view name() const override { return "tool-guard"; }
  bool allow_start(const control::StartCheck& start, control::FeatureHost& host, std::string* why) override;
  bool allow_continue(const control::SyncCheck& sync, control::FeatureHost& host) override;
  control::Outcome handle(const control::requests::Feature& request, control::FeatureHost& host) override;

 private:
  std::shared_ptr<store::ToolStore> store_;
  config::ToolGuardProfile profile_;
  tools::CheckTolerances tolerances_;
  int pockets_ = 0;
  /// While holding at a sync point: the store's changes() last checked and the report noted, so
  /// the check runs and the note appears again only when the table changed.
  std::uint64_t held_version_ = ~std::uint64_t{0};
  bool held_ = false;
  int held_tool_ = 0;  ///< the tool T of the tool change being checked
};

/// The G-code source and the feature for a profile: with [tool_guard], the tool store as the
/// interpreter's tool table, the check M-code among the standard modules, and the ToolGuard
/// feature; without it, the profile's standard source and no feature.
struct Setup {
  std::shared_ptr<control::GcodeProgramSource> source;
  std::shared_ptr<store::ToolStore> store;  ///< null without [tool_guard]
  std::shared_ptr<ToolGuard> feature;       ///< null without [tool_guard]
};

/// Builds the Setup; problems (a store that cannot be opened) land in `diags` and give nothing.
/// `tool_table_in_memory`: without a tool store, the profile's tool table file is read into a
/// table in memory that G10 L1 and electrode setting change instead of the file (a simulation's
/// own measurements). Non-real-time; one thread.
std::optional<Setup> setup(const config::MachineProfile& profile, Diagnostics& diags,
                           bool tool_table_in_memory = false);

}  // namespace opencnc::toolguard
