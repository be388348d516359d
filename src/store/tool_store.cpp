// SPDX-License-Identifier: GPL-3.0-or-later
// The tool store: schema, live table, backups, audit; the live table as the interpreter's.
#include "opencnc/store/tool_store.hpp"

#include <chrono>
#include <ctime>

#include <fmt/format.h>

#include "opencnc/store/database.hpp"
#include "opencnc/tools/edge_mapping.hpp"
#include "opencnc/tools/tool_check.hpp"

#include "guarded.hpp"

namespace opencnc::store {

using tools::Edge;
using tools::Param;
using tools::Tool;
using tools::ToolSet;

using detail::guarded;

namespace {

constexpr int kSchemaVersion = 1;

// The parameter columns in $TC_DP order: "type REAL NOT NULL, cutting_direction REAL NOT NULL, …"
std::string param_columns(bool with_types) {
  std::string s;
  for (const tools::ParamInfo& p : tools::param_table()) {
    s += fmt::format("{}{}{}", s.empty() ? "" : ", ", p.name, with_types ? " REAL NOT NULL DEFAULT 0" : "");
  }
  return s;
}

std::string placeholders(std::size_t from, std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{}?{}", s.empty() ? "" : ", ", from + i);
  return s;
}

void create_schema(Database& db) {
  const std::string cols = param_columns(true);
  db.exec(fmt::format(R"(
CREATE TABLE IF NOT EXISTS tools(tool INTEGER PRIMARY KEY, pocket INTEGER NOT NULL, comment TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS edges(tool INTEGER NOT NULL REFERENCES tools(tool) ON DELETE CASCADE,
  edge INTEGER NOT NULL, {0}, PRIMARY KEY(tool, edge));
CREATE TABLE IF NOT EXISTS backups(id INTEGER PRIMARY KEY, taken_utc TEXT NOT NULL, interface TEXT NOT NULL,
  reason TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS backup_tools(backup INTEGER NOT NULL REFERENCES backups(id), tool INTEGER NOT NULL,
  pocket INTEGER NOT NULL, comment TEXT NOT NULL, PRIMARY KEY(backup, tool));
CREATE TABLE IF NOT EXISTS backup_edges(backup INTEGER NOT NULL REFERENCES backups(id), tool INTEGER NOT NULL,
  edge INTEGER NOT NULL, {0}, PRIMARY KEY(backup, tool, edge));
CREATE TABLE IF NOT EXISTS audit(id INTEGER PRIMARY KEY, at_utc TEXT NOT NULL, interface TEXT NOT NULL,
  reason TEXT NOT NULL, what TEXT NOT NULL, old_value TEXT NOT NULL, new_value TEXT NOT NULL);
)",
                      cols));
}

void open_schema(Database& db, bool read_only) {
  const std::int64_t v = db.query_integer("PRAGMA user_version");
  if (v > kSchemaVersion)
    throw Error(fmt::format("the tool store has schema {}, newer than this opencnc's {}", v, kSchemaVersion));
  if (v == kSchemaVersion) return;
  if (read_only)
    throw Error(
        "this database is not an opencnc tool store (or one that must be opened writable to be set up)");
  const bool empty = db.query_integer("SELECT count(*) FROM sqlite_schema") == 0;
  if (!empty) throw Error("this database is not an opencnc tool store");
  Database::Transaction t(db);
  create_schema(db);
  db.exec(fmt::format("PRAGMA user_version={}", kSchemaVersion));
  t.commit();
}

// Reads (tool, pocket, comment) and (tool, edge, params…) rows into a set, in T then D order.
ToolSet read_set(Database& db, std::string_view tools_sql, std::string_view edges_sql,
                 std::optional<std::int64_t> backup) {
  ToolSet set;
  Statement ts = db.prepare(tools_sql);
  if (backup) ts.bind(1, *backup);
  while (ts.step()) {
    Tool& t = set.tool_or_add(static_cast<int>(ts.integer(0)));
    t.pocket = static_cast<int>(ts.integer(1));
    t.comment = ts.text(2);
  }
  Statement es = db.prepare(edges_sql);
  if (backup) es.bind(1, *backup);
  while (es.step()) {
    Edge& e = set.edge_or_add(static_cast<int>(es.integer(0)), static_cast<int>(es.integer(1)));
    for (std::size_t i = 0; i < tools::kParamCount; ++i) e.values[i] = es.real(static_cast<int>(i) + 2);
  }
  return set;
}

std::string edge_values(const Edge& e) {
  std::string s;
  for (const tools::ParamInfo& p : tools::param_table()) {
    s += fmt::format("{}{}={}", s.empty() ? "" : " ", p.name, tools::format_value(e.get(p.param)));
  }
  return s;
}

std::string tool_values(const Tool& t) {
  return fmt::format("pocket={} comment=\"{}\"", t.pocket, t.comment);
}

struct Change {
  std::string what, old_value, new_value;
};

void diff_edges(const Tool& t, const Tool* before, std::vector<Change>& out) {
  for (const Edge& e : t.edges) {
    const Edge* b = before != nullptr ? before->edge(e.edge) : nullptr;
    if (b == nullptr) {
      out.push_back({fmt::format("T{} D{}", t.tool, e.edge), "", edge_values(e)});
      continue;
    }
    for (const tools::ParamInfo& p : tools::param_table()) {
      if (b->get(p.param) != e.get(p.param))
        out.push_back({fmt::format("T{} D{} {}", t.tool, e.edge, p.name),
                       tools::format_value(b->get(p.param)), tools::format_value(e.get(p.param))});
    }
  }
  if (before == nullptr) return;
  for (const Edge& b : before->edges) {
    if (t.edge(b.edge) == nullptr)
      out.push_back({fmt::format("T{} D{}", t.tool, b.edge), edge_values(b), ""});
  }
}

// What changes from `before` to `after`, value by value, in T and D order.
std::vector<Change> diff(const ToolSet& before, const ToolSet& after) {
  std::vector<Change> out;
  for (const Tool& t : after.tools) {
    const Tool* b = before.tool(t.tool);
    if (b == nullptr) {
      out.push_back({fmt::format("T{}", t.tool), "", tool_values(t)});
    } else {
      if (b->pocket != t.pocket)
        out.push_back(
            {fmt::format("T{} pocket", t.tool), std::to_string(b->pocket), std::to_string(t.pocket)});
      if (b->comment != t.comment) out.push_back({fmt::format("T{} comment", t.tool), b->comment, t.comment});
    }
    diff_edges(t, b, out);
  }
  for (const Tool& b : before.tools) {
    if (after.tool(b.tool) != nullptr) continue;
    Tool gone = b;
    gone.edges.clear();
    diff_edges(gone, &b, out);
    out.push_back({fmt::format("T{}", b.tool), tool_values(b), ""});
  }
  return out;
}

void insert_audit(Database& db, const std::string& at, std::string_view interface, std::string_view reason,
                  const std::vector<Change>& changes) {
  Statement s = db.prepare(
      "INSERT INTO audit(at_utc, interface, reason, what, old_value, new_value) VALUES(?1, ?2, ?3, ?4, ?5, "
      "?6)");
  for (const Change& c : changes) {
    s.bind(1, std::string_view(at)).bind(2, interface).bind(3, reason);
    s.bind(4, std::string_view(c.what))
        .bind(5, std::string_view(c.old_value))
        .bind(6, std::string_view(c.new_value));
    s.run();
  }
}

void replace_live(Database& db, const ToolSet& set) {
  db.exec("DELETE FROM edges; DELETE FROM tools;");
  Statement ts = db.prepare("INSERT INTO tools(tool, pocket, comment) VALUES(?1, ?2, ?3)");
  Statement es = db.prepare(fmt::format("INSERT INTO edges(tool, edge, {}) VALUES(?1, ?2, {})",
                                        param_columns(false), placeholders(3, tools::kParamCount)));
  for (const Tool& t : set.tools) {
    ts.bind(1, t.tool).bind(2, t.pocket).bind(3, std::string_view(t.comment));
    ts.run();
    for (const Edge& e : t.edges) {
      es.bind(1, t.tool).bind(2, e.edge);
      for (std::size_t i = 0; i < tools::kParamCount; ++i) es.bind(static_cast<int>(i) + 3, e.values[i]);
      es.run();
    }
  }
}

}  // namespace

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

ToolStore::ToolStore(std::unique_ptr<Database> db, std::string path)
    : db_(std::move(db)), path_(std::move(path)), clock_(utc_now) {}

ToolStore::~ToolStore() = default;

std::shared_ptr<ToolStore> ToolStore::open(const std::string& path, std::string* error, bool create,
                                           bool read_only) {
  return guarded(error, [&]() -> std::shared_ptr<ToolStore> {
    OpenOptions o;
    o.create = create && !read_only;
    o.read_only = read_only;
    auto db = std::make_unique<Database>(path, o);
    try {
      open_schema(*db, read_only);
    } catch (const Error& e) {
      throw Error(fmt::format("{}: {}", path, e.what()));
    }
    std::shared_ptr<ToolStore> s(new ToolStore(std::move(db), path));
    std::lock_guard lock(s->mutex_);
    s->refresh_locked();
    return s;
  });
}

void ToolStore::set_clock(std::function<std::string()> clock) {
  std::lock_guard lock(mutex_);
  clock_ = std::move(clock);
}

ToolSet ToolStore::read_live_locked() const {
  return read_set(*db_, "SELECT tool, pocket, comment FROM tools ORDER BY tool",
                  fmt::format("SELECT tool, edge, {} FROM edges ORDER BY tool, edge", param_columns(false)),
                  std::nullopt);
}

void ToolStore::refresh_locked() const {
  const std::int64_t v = db_->data_version();
  if (v == data_version_ && table_) return;
  ++changes_;
  ToolSet fresh = read_live_locked();
  if (!table_ || fresh != live_) {
    live_ = std::move(fresh);
    table_ = std::make_shared<const tools::ToolTable>(tools::linuxcnc_table(live_));
    if (data_version_ >= 0) ++version_;
  }
  data_version_ = v;
}

std::optional<ToolSet> ToolStore::live(std::string* error) {
  return guarded(error, [&]() -> std::optional<ToolSet> {
    std::lock_guard lock(mutex_);
    refresh_locked();
    return live_;
  });
}

bool ToolStore::write_locked(const ToolSet& changed, std::string_view interface, std::string_view reason,
                             std::string* error) {
  return modify_locked(
      [&changed](ToolSet& live) -> std::optional<std::string> {
        live = changed;
        return std::nullopt;
      },
      interface, reason, error);
}

// The read, the change and the write in one BEGIN IMMEDIATE transaction: two writers each change
// what the other committed, never a copy read before it (the audit names only what this one changed).
bool ToolStore::modify_locked(const Edit& change, std::string_view interface, std::string_view reason,
                              std::string* error) {
  std::optional<std::string> refused;
  const bool ok = guarded(error, [&]() -> bool {
    Database::Transaction t(*db_);
    const ToolSet before = read_live_locked();
    ToolSet changed = before;
    refused = change(changed);
    if (!refused) refused = tools::invalid(changed);
    if (refused) return false;
    const std::vector<Change> changes = diff(before, changed);
    if (!changes.empty()) {
      replace_live(*db_, changed);
      insert_audit(*db_, clock_(), interface, reason, changes);
      t.commit();
    }
    live_ = std::move(changed);
    table_ = std::make_shared<const tools::ToolTable>(tools::linuxcnc_table(live_));
    data_version_ = db_->data_version();
    ++version_;
    ++changes_;
    return true;
  });
  if (refused && error != nullptr) *error = *refused;
  return ok;
}

bool ToolStore::write(const ToolSet& changed, std::string_view interface, std::string_view reason,
                      std::string* error) {
  std::lock_guard lock(mutex_);
  return write_locked(changed, interface, reason, error);
}

bool ToolStore::modify(const Edit& change, std::string_view interface, std::string_view reason,
                       std::string* error) {
  std::lock_guard lock(mutex_);
  return modify_locked(change, interface, reason, error);
}

bool ToolStore::set(int t, int d, Param p, double value, std::string_view interface, std::string* error) {
  if (t < 1 || t > tools::kMaxToolNumber || d < 1 || d > tools::kMaxEdge) {
    if (error != nullptr)
      *error = fmt::format("T{} D{}: tools go from T1 to T{}, edges from D1 to D{}", t, d,
                           tools::kMaxToolNumber, tools::kMaxEdge);
    return false;
  }
  return modify(
      [&](ToolSet& live) -> std::optional<std::string> {
        live.edge_or_add(t, d).set(p, value);
        return std::nullopt;
      },
      interface, "set", error);
}

bool ToolStore::set_tool(int t, int pocket, std::string_view comment, std::string_view interface,
                         std::string* error) {
  if (t < 1 || t > tools::kMaxToolNumber) {
    if (error != nullptr) *error = fmt::format("T{}: tools go from T1 to T{}", t, tools::kMaxToolNumber);
    return false;
  }
  return modify(
      [&](ToolSet& live) -> std::optional<std::string> {
        Tool& tool = live.tool_or_add(t);
        tool.pocket = pocket;
        tool.comment = std::string(comment);
        return std::nullopt;
      },
      interface, "set", error);
}

std::optional<std::int64_t> ToolStore::backup(std::string_view interface, std::string_view reason,
                                              std::string* error) {
  std::lock_guard lock(mutex_);
  return guarded(error, [&]() -> std::optional<std::int64_t> {
    Database::Transaction t(*db_);
    const std::string at = clock_();
    Statement b =
        db_->prepare("INSERT INTO backups(taken_utc, interface, reason) VALUES(?1, ?2, ?3) RETURNING id");
    b.bind(1, std::string_view(at)).bind(2, interface).bind(3, reason);
    if (!b.step()) throw Error("a backup got no number");
    const std::int64_t id = b.integer(0);
    b.reset();
    Statement ts = db_->prepare("INSERT INTO backup_tools SELECT ?1, tool, pocket, comment FROM tools");
    ts.bind(1, id);
    ts.run();
    const std::string cols = param_columns(false);
    Statement es =
        db_->prepare(fmt::format("INSERT INTO backup_edges SELECT ?1, tool, edge, {} FROM edges", cols));
    es.bind(1, id);
    es.run();
    const std::int64_t n =
        db_->query_integer(fmt::format("SELECT count(*) FROM backup_edges WHERE backup={}", id));
    insert_audit(*db_, at, interface, reason,
                 {{fmt::format("backup {}", id), "", fmt::format("{} edges", n)}});
    t.commit();
    data_version_ = db_->data_version();
    ++changes_;
    return id;
  });
}

std::vector<BackupInfo> ToolStore::backups(std::string* error) {
  std::lock_guard lock(mutex_);
  return guarded(error, [&] {
    std::vector<BackupInfo> out;
    Statement s = db_->prepare(
        "SELECT id, taken_utc, interface, reason, (SELECT count(*) FROM backup_tools WHERE backup=id),"
        " (SELECT count(*) FROM backup_edges WHERE backup=id) FROM backups ORDER BY id");
    while (s.step())
      out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3), s.integer(4), s.integer(5)});
    return out;
  });
}

std::optional<BackupInfo> ToolStore::current_backup(std::string* error) {
  std::vector<BackupInfo> all = backups(error);
  if (all.empty()) return std::nullopt;
  return all.back();
}

std::optional<ToolSet> ToolStore::backup_set(std::int64_t id, std::string* error) {
  std::lock_guard lock(mutex_);
  return guarded(error, [&]() -> std::optional<ToolSet> {
    if (db_->query_integer(fmt::format("SELECT count(*) FROM backups WHERE id={}", id)) == 0)
      throw Error(fmt::format("there is no backup {}", id));
    return read_set(*db_, "SELECT tool, pocket, comment FROM backup_tools WHERE backup=?1 ORDER BY tool",
                    fmt::format("SELECT tool, edge, {} FROM backup_edges WHERE backup=?1 ORDER BY tool, edge",
                                param_columns(false)),
                    id);
  });
}

bool ToolStore::restore(std::int64_t id, std::string_view interface, std::string* error) {
  const std::optional<ToolSet> set = backup_set(id, error);
  if (!set) return false;
  std::lock_guard lock(mutex_);
  return write_locked(*set, interface, fmt::format("restore of backup {}", id), error);
}

std::vector<AuditEntry> ToolStore::audit(std::size_t limit, std::string* error) {
  std::lock_guard lock(mutex_);
  return guarded(error, [&] {
    std::vector<AuditEntry> out;
    Statement s = db_->prepare(
        "SELECT * FROM (SELECT id, at_utc, interface, reason, what, old_value, new_value FROM audit ORDER BY "
        "id DESC"
        " LIMIT ?1) ORDER BY id");
    s.bind(1, limit == 0 ? std::int64_t{-1} : static_cast<std::int64_t>(limit));
    while (s.step())
      out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5), s.text(6)});
    return out;
  });
}

// --- the interpreter's view ------------------------------------------------------------------

void ToolStore::refresh_keeping_last_locked() const {
  try {
    refresh_locked();
  } catch (const std::exception&) {
    // A read that fails (the disk is gone) keeps the table last read: the interpreter never
    // sees a half table. The next write reports the problem.
  }
}

std::shared_ptr<const tools::ToolTable> ToolStore::snapshot() const {
  std::lock_guard lock(mutex_);
  refresh_keeping_last_locked();
  return table_;
}

std::uint64_t ToolStore::changes() const {
  std::lock_guard lock(mutex_);
  refresh_keeping_last_locked();
  return changes_;
}

std::uint64_t ToolStore::version() const {
  std::lock_guard lock(mutex_);
  refresh_keeping_last_locked();
  return version_;
}

bool ToolStore::update(std::size_t index, const tools::ToolEntry& entry, tools::ChangeSource source,
                       Diagnostics& diags) {
  std::lock_guard lock(mutex_);
  std::string error;
  const bool read = guarded(&error, [&] {
    refresh_locked();
    return true;
  });
  auto refuse = [&](const std::string& why) {
    diags.error(path_, 0, 0, fmt::format("the tool store was not changed: {}", why), "tools.cannot-write");
    return false;
  };
  if (!read) return refuse(error);
  if (index < 1 || index > table_->size()) {
    diags.error("", 0, 0,
                fmt::format("there is no tool table entry {} (the table has {})", index, table_->size()),
                "tools.no-entry");
    return false;
  }
  const tools::ToolEntry& old = table_->at_index(index);
  if (entry.tool != old.tool)
    return refuse(
        fmt::format("tool {} cannot be renumbered to {} (T/D numbers are fixed)", old.tool, entry.tool));
  const auto td = tools::tool_and_edge(entry.tool);
  if (!td) return refuse(fmt::format("tool {} names no edge", entry.tool));
  // The entry applied to the table as committed when it is written (the rest of it as another
  // writer may have left it).
  const bool written = modify_locked(
      [&](ToolSet& live) -> std::optional<std::string> {
        Tool* tool = live.tool(td->first);
        Edge* e = tool != nullptr ? tool->edge(td->second) : nullptr;
        if (e == nullptr) return fmt::format("T{} D{} was removed meanwhile", td->first, td->second);
        if (const auto why = tools::apply_entry(entry, *e))
          return fmt::format("T{} D{}: {}", td->first, td->second, *why);
        if (td->second == 1) tool->pocket = entry.pocket;
        return std::nullopt;
      },
      tools::to_string(source), "G10", &error);
  return written || refuse(error);
}

}  // namespace opencnc::store
