// SPDX-License-Identifier: GPL-3.0-or-later
// store::CutChartStore — the cut chart in a SQLite file, kept like the tool store: every change
// one transaction with an audit row per value (old → new, who, when) (docs/cutting.md).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/store/cut_chart.hpp"
#include "opencnc/store/tool_store.hpp"

namespace opencnc::store {

class Database;

/// The cut chart store. Changes are whole or not at all, also across a crash (store::Database);
/// other processes may change the same file and reads see their commits. All members may be
/// called from any thread (one lock); none is real-time safe. Errors are values: false /
/// nothing, with `*error` set; a refused change changes nothing.
class CutChartStore {
 public:
  /// Opens (creates, when allowed) the store at `path`; null with `*error` when it cannot (also
  /// when the file is another SQLite database, such as a tool store).
  static std::shared_ptr<CutChartStore> open(const std::string& path, std::string* error, bool create = true,
                                             bool read_only = false);
  ~CutChartStore();

  /// Every material, by number.
  std::optional<std::vector<Material>> chart(std::string* error = nullptr);
  /// One material, or nothing (`*error` empty when it is just not there).
  std::optional<Material> material(int number, std::string* error = nullptr);
  /// Replaces the whole chart (an import): refused when invalid(chart) says why.
  bool write(const std::vector<Material>& chart, std::string_view interface, std::string_view reason,
             std::string* error);
  /// Adds material `m.number` or changes it.
  bool put(const Material& m, std::string_view interface, std::string* error);
  /// Removes material `number` (false when it is not there).
  bool remove(int number, std::string_view interface, std::string* error);
  /// The material selected for the machine (the HMI's choice): programs that select none use it;
  /// 0: none. Kept in the store, so every process sees it.
  std::optional<int> selected(std::string* error = nullptr);
  /// Selects material `number` of the chart, or none (0). Audited ("selected"). A change that
  /// removes the selected material from the chart selects none (audited with it).
  bool select(int number, std::string_view interface, std::string* error);
  /// The newest `limit` audit entries (0: all), oldest first.
  std::vector<AuditEntry> audit(std::size_t limit = 0, std::string* error = nullptr);
  /// Grows with every commit by any connection: a cache compares it.
  std::uint64_t changes();
  /// Where timestamps come from (default utc_now). Tests fix it.
  void set_clock(std::function<std::string()> clock);
  const std::string& path() const noexcept { return path_; }

 private:
  CutChartStore(std::unique_ptr<Database> db, std::string path);
  using Edit = std::function<std::optional<std::string>(std::vector<Material>&)>;
  bool modify_locked(const Edit& edit, std::string_view interface, std::string_view reason,
                     std::string* error);

  std::mutex mutex_;
  std::unique_ptr<Database> db_;
  std::string path_;
  std::function<std::string()> clock_;
  std::int64_t data_version_ = -1;
  std::uint64_t changes_ = 0;
};

}  // namespace opencnc::store
