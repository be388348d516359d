// SPDX-License-Identifier: GPL-3.0-or-later
// The live tool table: snapshots for readers, whole changes under a lock, the .tbl file kept.
#include "opencnc/tools/tool_table_service.hpp"

#include <fmt/format.h>

#include "opencnc/core/output_file.hpp"
#include "opencnc/tools/tool_data.hpp"

namespace opencnc::tools {

const char* to_string(ChangeSource s) noexcept {
  switch (s) {
    case ChangeSource::Program:
      return "program";
    case ChangeSource::Operator:
      return "operator";
    case ChangeSource::Import:
      return "import";
  }
  return "";
}

MemoryToolTable::MemoryToolTable(ToolTable table) : table_(std::make_shared<const ToolTable>(std::move(table))) {}

std::shared_ptr<const ToolTable> MemoryToolTable::snapshot() const {
  std::lock_guard lock(mutex_);
  return table_;
}

std::uint64_t MemoryToolTable::version() const {
  std::lock_guard lock(mutex_);
  return version_;
}

bool MemoryToolTable::update(std::size_t index, const ToolEntry& entry, ChangeSource /*source*/,
                             Diagnostics& diags) {
  std::lock_guard lock(mutex_);
  if (index < 1 || index > table_->size()) {
    diags.error("", 0, 0, fmt::format("there is no tool table entry {} (the table has {})", index, table_->size()),
                "tools.no-entry");
    return false;
  }
  if (const auto why = invalid_comment(entry.comment)) {
    diags.error("", 0, 0, fmt::format("T{}: {}", entry.tool, *why), "tools.bad-comment");
    return false;
  }
  if (const auto other = table_->find(entry.tool); other && *other != index) {
    diags.error("", 0, 0, fmt::format("tool {} is already entry {} of the table", entry.tool, *other),
                "tools.duplicate-tool");
    return false;
  }
  if (table_->at_index(index) == entry) return true;  // nothing changes: nothing to store
  ToolTable changed = *table_;
  changed.replace(index, entry);
  if (!store(changed, diags)) return false;
  table_ = std::make_shared<const ToolTable>(std::move(changed));
  ++version_;
  return true;
}

std::shared_ptr<FileToolTable> FileToolTable::open(const std::string& path, Diagnostics& diags) {
  const std::size_t before = diags.error_count();
  auto table = ToolTable::load(path, diags);
  if (!table || diags.error_count() > before) return nullptr;
  return std::shared_ptr<FileToolTable>(new FileToolTable(path, std::move(*table)));
}

// The user's file, by OutputFile's rules: a symlink is followed, the permission bits stay, a
// read-only table is refused, and a power cut leaves the old table or the new one.
bool FileToolTable::store(const ToolTable& changed, Diagnostics& diags) {
  std::string error;
  const std::unique_ptr<OutputFile> out = OutputFile::open({"the tool table", path_}, &error);
  if (out && out->write(changed.format()) && out->commit(&error)) return true;
  diags.error(path_, 0, 0, fmt::format("the tool table was not changed: {}", error), "tools.cannot-write");
  return false;
}

}  // namespace opencnc::tools
