// SPDX-License-Identifier: GPL-3.0-or-later
// ToolTableService — the machine's live tool table, shared by the interpreter (G43 and G41/G42
// read it, G10 L1/L10/L11 write it) and the front ends, in memory or kept in a LinuxCNC .tbl file.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "opencnc/core/diagnostic.hpp"
#include "opencnc/tools/tool_table.hpp"

namespace opencnc::tools {

/// Who changed a tool entry (kept with the change for audits and shown to the operator).
enum class ChangeSource : std::uint8_t {
  Program,   ///< G10 L1 / L10 / L11 in a program or an MDI line
  Operator,  ///< an edit from a front end
  Import,    ///< a table read from a file
};

/// "program", "operator", "import". Any thread.
const char* to_string(ChangeSource s) noexcept;

/// The live tool table. Readers take a snapshot, which stays valid and unchanged however the
/// table changes later; every change is whole or not at all. All members may be called from
/// any thread; none is real-time safe.
class ToolTableService {
 public:
  virtual ~ToolTableService() = default;
  /// The table now.
  virtual std::shared_ptr<const ToolTable> snapshot() const = 0;
  /// Grows with every change (0 before the first): a reader compares it with the one it saw.
  virtual std::uint64_t version() const = 0;
  /// Replaces the entry at 1-based `index` by `entry` (its tool number must stay that of the
  /// entry, or be free). Returns false with a diagnostic, the table unchanged, when the index is
  /// out of range, the number is taken, or the change cannot be stored.
  virtual bool update(std::size_t index, const ToolEntry& entry, ChangeSource source, Diagnostics& diags) = 0;
};

/// A table held in memory only (machines without a table file, tests).
class MemoryToolTable : public ToolTableService {
 public:
  explicit MemoryToolTable(ToolTable table = {});
  std::shared_ptr<const ToolTable> snapshot() const override;
  std::uint64_t version() const override;
  bool update(std::size_t index, const ToolEntry& entry, ChangeSource source, Diagnostics& diags) override;

 protected:
  /// Called with the changed table before it replaces the current one; false keeps the old.
  virtual bool store(const ToolTable& /*changed*/, Diagnostics& /*diags*/) { return true; }

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const ToolTable> table_;
  std::uint64_t version_ = 0;
};

/// A LinuxCNC `.tbl` file: read when opened, and written back after every change before the
/// change counts, by core::OutputFile's rules (temporary file, fdatasync, rename: a power cut leaves
/// the old table or the new one; a symlink is written through, the permission bits stay, a
/// read-only table refuses the change).
class FileToolTable final : public MemoryToolTable {
 public:
  /// Reads `path`; null (and diagnostics) when it cannot be read or has errors.
  static std::shared_ptr<FileToolTable> open(const std::string& path, Diagnostics& diags);
  const std::string& path() const noexcept { return path_; }

 private:
  FileToolTable(std::string path, ToolTable table) : MemoryToolTable(std::move(table)), path_(std::move(path)) {}
  bool store(const ToolTable& changed, Diagnostics& diags) override;
  std::string path_;
};

}  // namespace opencnc::tools
