// SPDX-License-Identifier: GPL-3.0-or-later
// store::ToolStore — the tool guard's database: the live tools with their edges (T/D), every
// backup taken, and the audit of every change; to the interpreter it is the live tool table.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/tools/tool_data.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::store {

class Database;

/// One snapshot of the whole table (newest = current: the one the check compares with).
struct BackupInfo {
  std::int64_t id = 0;
  std::string taken_utc;  ///< "2026-11-26T03:10:56Z"
  std::string interface;  ///< who took it: "command line", "hmi", "tool guard" …
  std::string reason;     ///< "backup", "accept"
  std::int64_t tools = 0, edges = 0;
};

/// One audited change of one value.
struct AuditEntry {
  std::int64_t id = 0;
  std::string at_utc;
  std::string interface;  ///< "command line", "program" (G10 L1), "hmi", …
  std::string reason;     ///< "set", "import tools.tbl", "restore of backup 3", "G10" …
  std::string what;       ///< "T3 D1 length1", "T3 pocket", "T3 D2" (edge added/removed), "backup 4"
  std::string old_value, new_value;
};

/// The tool store in a SQLite file. Every change is one transaction with its audit rows: it
/// is stored whole or not at all, also across a crash or power cut (store::Database's WAL and
/// synchronous=FULL). Other processes may change the same file (the command line while a
/// program runs): reads notice their commits. All members may be called from any thread (one
/// lock); none is real-time safe. Errors are values: false / nothing, with `*error` set.
class ToolStore final : public tools::ToolTableService {
 public:
  /// Opens (creates, when allowed) the store at `path`; null with `*error` when it cannot.
  /// `read_only`: for looking only (a store the user may not write, a backup on read-only media):
  /// nothing is created or upgraded, and every change is refused.
  static std::shared_ptr<ToolStore> open(const std::string& path, std::string* error, bool create = true,
                                         bool read_only = false);
  ~ToolStore() override;

  /// The live table as now committed.
  std::optional<tools::ToolSet> live(std::string* error = nullptr);
  /// Makes `changed` the live table in one transaction, with an audit row per value that
  /// changed (`interface` and `reason` on each). Invalid sets (tools::invalid) are refused.
  bool write(const tools::ToolSet& changed, std::string_view interface, std::string_view reason,
             std::string* error);
  /// A change of the live table as it is committed when the change is made: `change` edits the
  /// table read inside the write transaction (another writer's commit is never overwritten with
  /// a stale copy) and returns why it cannot, or nothing. Audited as write() is.
  using Edit = std::function<std::optional<std::string>(tools::ToolSet&)>;
  bool modify(const Edit& change, std::string_view interface, std::string_view reason, std::string* error);
  /// One parameter of edge D`d` of tool T`t` (the edge and tool are added when new).
  bool set(int t, int d, tools::Param p, double value, std::string_view interface, std::string* error);
  /// Pocket and comment of tool T`t` (added when new).
  bool set_tool(int t, int pocket, std::string_view comment, std::string_view interface, std::string* error);

  /// Takes a snapshot of the live table, which becomes the current backup; older ones are all
  /// kept. `reason` is "backup" or "accept". Returns its id.
  std::optional<std::int64_t> backup(std::string_view interface, std::string_view reason, std::string* error);
  /// Every backup, oldest first.
  std::vector<BackupInfo> backups(std::string* error = nullptr);
  /// The newest backup, if any.
  std::optional<BackupInfo> current_backup(std::string* error = nullptr);
  /// The tools of backup `id`.
  std::optional<tools::ToolSet> backup_set(std::int64_t id, std::string* error = nullptr);
  /// Writes backup `id` over the live table (audited as "restore of backup <id>").
  bool restore(std::int64_t id, std::string_view interface, std::string* error);
  /// The newest `limit` audit entries (0: all), oldest first.
  std::vector<AuditEntry> audit(std::size_t limit = 0, std::string* error = nullptr);

  /// Grows with every commit to the store by any connection (changes and backups): a cache
  /// of a check compares it.
  std::uint64_t changes() const;
  /// Where timestamps come from ("YYYY-MM-DDTHH:MM:SSZ"; default: the system clock in UTC).
  /// Tests fix it.
  void set_clock(std::function<std::string()> clock);
  const std::string& path() const noexcept { return path_; }

  // tools::ToolTableService: edge D of tool T is LinuxCNC tool T (D1) or D·10000+T
  // (tools/edge_mapping.hpp); G10 L1/L10/L11 writes geometry, keeping wear and base.
  std::shared_ptr<const tools::ToolTable> snapshot() const override;
  std::uint64_t version() const override;
  bool update(std::size_t index, const tools::ToolEntry& entry, tools::ChangeSource source,
              Diagnostics& diags) override;

 private:
  ToolStore(std::unique_ptr<Database> db, std::string path);
  void refresh_locked() const;  // re-reads after another process's commit
  void refresh_keeping_last_locked() const;  // the same; a failed read keeps the last table
  tools::ToolSet read_live_locked() const;
  bool write_locked(const tools::ToolSet& changed, std::string_view interface, std::string_view reason,
                    std::string* error);
  bool modify_locked(const Edit& change, std::string_view interface, std::string_view reason,
                     std::string* error);

  mutable std::mutex mutex_;
  std::unique_ptr<Database> db_;
  std::string path_;
  std::function<std::string()> clock_;
  mutable tools::ToolSet live_;
  mutable std::shared_ptr<const tools::ToolTable> table_;
  mutable std::int64_t data_version_ = -1;
  mutable std::uint64_t version_ = 0;
  mutable std::uint64_t changes_ = 0;
};

/// The current UTC time as "YYYY-MM-DDTHH:MM:SSZ". Any thread.
std::string utc_now();

}  // namespace opencnc::store
