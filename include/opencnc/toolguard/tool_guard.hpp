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
#include "opencnc/controller/machine_setup.hpp"
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
class ToolGuard final : public controller::Feature {
 public:
  /// `pockets`: the magazine's pockets (0: not checked); a tool in a pocket beyond it refuses
  /// the start like a difference.
  ToolGuard(std::shared_ptr<store::ToolStore> store, const config::ToolGuardProfile& profile,
            int pockets = 0);

  std::string_view name() const override { return "tool-guard"; }
  bool allow_start(const controller::StartCheck& start, controller::FeatureHost& host,
                   std::string* why) override;
  bool allow_continue(const controller::SyncCheck& sync, controller::FeatureHost& host) override;
  controller::Outcome handle(const controller::requests::Feature& request,
                             controller::FeatureHost& host) override;

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

/// The tool guard's parts on `host` for a profile with [tool_guard]: the tool store as the
/// program source's tool table, the check M-code among its modules (a code module on top of the
/// others), the ToolGuard feature ("tool-guard", following the status) and, for a front end, its
/// state while it holds (`tool_guard`: the differences of the whole live table from the backup).
/// Nothing on another machine. False with the reasons in host.diagnostics() (a store that cannot
/// be opened). Set up before the features that take the source's tool table. Non-real-time; one
/// thread, before the controller runs.
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::toolguard
