// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart store: schema, the chart, audited changes.
#include "opencnc/store/cut_chart_store.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "opencnc/store/database.hpp"

#include "guarded.hpp"

namespace opencnc::store {

using detail::guarded;

namespace {

// 1: the first chart; 2: preheat_s (an oxy-fuel row's preheat time), added to a schema-1 chart by
// migrate() with 0 in every row it holds.
constexpr int kSchemaVersion = 2;
constexpr std::int64_t kApplicationId = 0x4f434343;  // "OCCC": an opencnc cut chart

// Columns after number, in material_fields() order: name TEXT, thickness_mm REAL, process TEXT, …
std::vector<std::string> value_columns() {
  std::vector<std::string> out;
  for (const MaterialField& f : material_fields())
    if (std::string_view(f.name) != "number") out.emplace_back(f.name);
  return out;
}

void create_schema(Database& db) {
  std::string cols;
  for (const std::string& c : value_columns())
    cols += fmt::format(", {} {} NOT NULL", c, c == "name" || c == "process" ? "TEXT" : "REAL");
  db.exec(fmt::format(R"(
CREATE TABLE materials(number INTEGER PRIMARY KEY{});
CREATE TABLE selection(id INTEGER PRIMARY KEY CHECK (id = 1), material INTEGER NOT NULL);
INSERT INTO selection(id, material) VALUES(1, 0);
CREATE TABLE audit(id INTEGER PRIMARY KEY, at_utc TEXT NOT NULL, interface TEXT NOT NULL,
  reason TEXT NOT NULL, what TEXT NOT NULL, old_value TEXT NOT NULL, new_value TEXT NOT NULL);
)",
                      cols));
}

void open_schema(Database& db, bool read_only) {
  const std::int64_t id = db.query_integer("PRAGMA application_id");
  const std::int64_t v = db.query_integer("PRAGMA user_version");
  const bool empty = db.query_integer("SELECT count(*) FROM sqlite_schema") == 0;
  if (id == kApplicationId) {
    if (v > kSchemaVersion)
      throw Error(
          fmt::format("the cut chart has schema {}, newer than this opencnc's {}", v, kSchemaVersion));
    if (v == kSchemaVersion) return;
    if (v == 1 && !read_only) {  // a chart of schema 1 opened writable: updated in place, rows kept
      Database::Transaction t(db);
      db.exec("ALTER TABLE materials ADD COLUMN preheat_s REAL NOT NULL DEFAULT 0");
      db.exec(fmt::format("PRAGMA user_version={}", kSchemaVersion));
      t.commit();
      return;
    }
    if (v == 1) return;  // read-only: read as it is (its rows without a preheat, read_chart)
  }
  if (!empty || id != 0) throw Error("this database is not an opencnc cut chart");
  if (read_only)
    throw Error("this database is not an opencnc cut chart (or one that must be opened writable)");
  Database::Transaction t(db);
  create_schema(db);
  db.exec(fmt::format("PRAGMA application_id={}; PRAGMA user_version={}", kApplicationId, kSchemaVersion));
  t.commit();
}

int read_selected(Database& db) {
  return static_cast<int>(db.query_integer("SELECT material FROM selection"));
}

// The value columns the chart's table has (a schema-1 chart opened read-only lacks preheat_s).
std::vector<std::string> table_columns(Database& db) {
  std::vector<std::string> cols;
  for (const std::string& c : value_columns())
    if (db.query_integer(
            fmt::format("SELECT count(*) FROM pragma_table_info('materials') WHERE name = '{}'", c)) > 0)
      cols.push_back(c);
  return cols;
}

std::vector<Material> read_chart(Database& db) {
  const std::vector<std::string> cols = table_columns(db);
  std::string sql = "SELECT number";
  for (const std::string& c : cols) sql += ", " + c;
  Statement s = db.prepare(sql + " FROM materials ORDER BY number");
  std::vector<Material> out;
  while (s.step()) {
    Material m;
    m.number = static_cast<int>(s.integer(0));
    for (std::size_t i = 0; i < cols.size(); ++i) {
      const int col = static_cast<int>(i) + 1;
      if (cols[i] == "name" || cols[i] == "process") {
        if (const auto why = set_field(m, cols[i], s.text(col)))
          throw Error(fmt::format("material {}: {}", m.number, *why));
      } else {
        set_number(m, cols[i], s.real(col));
      }
    }
    out.push_back(std::move(m));
  }
  return out;
}

void insert(Database& db, const Material& m) {
  const std::vector<std::string> cols = value_columns();
  std::string names = "number", marks = "?1";
  for (std::size_t i = 0; i < cols.size(); ++i) {
    names += ", " + cols[i];
    marks += fmt::format(", ?{}", i + 2);
  }
  Statement s = db.prepare(fmt::format("INSERT INTO materials({}) VALUES({})", names, marks));
  s.bind(1, m.number);
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const int at = static_cast<int>(i) + 2;
    if (cols[i] == "name")
      s.bind(at, std::string_view(m.name));
    else if (cols[i] == "process")
      s.bind(at, std::string_view(to_string(m.process)));
    else
      s.bind(at, field_number(m, cols[i]));
  }
  s.run();
}

std::string all_values(const Material& m) {
  std::string s;
  for (const MaterialField& f : material_fields()) {
    if (std::string_view(f.name) == "number") continue;
    s += fmt::format(
        "{}{}={}", s.empty() ? "" : " ", f.name,
        std::string_view(f.name) == "name" ? fmt::format("\"{}\"", m.name) : field_text(m, f.name));
  }
  return s;
}

struct Change {
  std::string what, old_value, new_value;
};

std::vector<Change> diff(const std::vector<Material>& before, const std::vector<Material>& after) {
  std::vector<Change> out;
  for (const Material& m : after) {
    const Material* b = find(before, m.number);
    if (b == nullptr) {
      out.push_back({fmt::format("material {}", m.number), "", all_values(m)});
      continue;
    }
    for (const MaterialField& f : material_fields()) {
      const std::string o = field_text(*b, f.name), n = field_text(m, f.name);
      if (o != n) out.push_back({fmt::format("material {} {}", m.number, f.name), o, n});
    }
  }
  for (const Material& b : before)
    if (find(after, b.number) == nullptr)
      out.push_back({fmt::format("material {}", b.number), all_values(b), ""});
  return out;
}

}  // namespace

CutChartStore::CutChartStore(std::unique_ptr<Database> db, std::string path)
    : db_(std::move(db)), path_(std::move(path)), clock_(utc_now) {}

CutChartStore::~CutChartStore() = default;

std::shared_ptr<CutChartStore> CutChartStore::open(const std::string& path, std::string* error, bool create,
                                                   bool read_only) {
  try {
    auto db = std::make_unique<Database>(path, OpenOptions{create && !read_only, read_only});
    open_schema(*db, read_only);
    return std::shared_ptr<CutChartStore>(new CutChartStore(std::move(db), path));
  } catch (const std::exception& ex) {
    if (error != nullptr) *error = ex.what();
    return nullptr;
  }
}

std::optional<std::vector<Material>> CutChartStore::chart(std::string* error) {
  std::lock_guard lock(mutex_);
  return guarded(error, [&] { return std::optional<std::vector<Material>>(read_chart(*db_)); });
}

std::optional<Material> CutChartStore::material(int number, std::string* error) {
  const auto all = chart(error);
  if (!all) return std::nullopt;
  const Material* m = find(*all, number);
  return m != nullptr ? std::optional<Material>(*m) : std::nullopt;
}

bool CutChartStore::modify_locked(const Edit& edit, std::string_view interface, std::string_view reason,
                                  std::string* error) {
  std::string why;
  const bool ok = guarded(error, [&] {
    Database::Transaction t(*db_);  // the chart is read and written under one write lock
    const std::vector<Material> before = read_chart(*db_);
    std::vector<Material> after = before;
    if (auto refused = edit(after)) {
      why = std::move(*refused);
      return false;
    }
    if (const auto bad = invalid(after)) {
      why = bad->message;
      return false;
    }
    std::vector<Change> changes = diff(before, after);
    if (changes.empty()) return true;
    db_->exec("DELETE FROM materials");
    for (const Material& m : after) insert(*db_, m);
    if (const int sel = read_selected(*db_); sel != 0 && find(after, sel) == nullptr) {
      db_->exec("UPDATE selection SET material = 0");
      changes.push_back({"selected material", std::to_string(sel), "0"});
    }
    Statement a = db_->prepare(
        "INSERT INTO audit(at_utc, interface, reason, what, old_value, new_value) VALUES(?1, ?2, ?3, ?4, ?5, "
        "?6)");
    const std::string at = clock_();
    for (const Change& c : changes) {
      a.bind(1, std::string_view(at)).bind(2, interface).bind(3, reason).bind(4, std::string_view(c.what));
      a.bind(5, std::string_view(c.old_value)).bind(6, std::string_view(c.new_value));
      a.run();
    }
    t.commit();
    ++changes_;
    return true;
  });
  if (!why.empty() && error != nullptr) *error = why;
  return ok;
}

bool CutChartStore::write(const std::vector<Material>& chart, std::string_view interface,
                          std::string_view reason, std::string* error) {
  std::lock_guard lock(mutex_);
  return modify_locked(
      [&](std::vector<Material>& c) {
        c = chart;
        return std::optional<std::string>();
      },
      interface, reason, error);
}

bool CutChartStore::put(const Material& m, std::string_view interface, std::string* error) {
  std::lock_guard lock(mutex_);
  if (const auto bad = invalid(m)) {
    if (error != nullptr) *error = fmt::format("{}: {}", bad->field, bad->message);
    return false;
  }
  return modify_locked(
      [&](std::vector<Material>& c) {
        for (Material& x : c) {
          if (x.number == m.number) {
            x = m;
            return std::optional<std::string>();
          }
        }
        c.push_back(m);
        std::sort(c.begin(), c.end(),
                  [](const Material& a, const Material& b) { return a.number < b.number; });
        return std::optional<std::string>();
      },
      interface, "set", error);
}

bool CutChartStore::remove(int number, std::string_view interface, std::string* error) {
  std::lock_guard lock(mutex_);
  return modify_locked(
      [&](std::vector<Material>& c) {
        if (std::erase_if(c, [&](const Material& m) { return m.number == number; }) == 0)
          return std::optional<std::string>(fmt::format("material {} is not in the cut chart", number));
        return std::optional<std::string>();
      },
      interface, "remove", error);
}

std::optional<int> CutChartStore::selected(std::string* error) {
  std::lock_guard lock(mutex_);
  return guarded(error, [&] { return std::optional<int>(read_selected(*db_)); });
}

bool CutChartStore::select(int number, std::string_view interface, std::string* error) {
  std::lock_guard lock(mutex_);
  std::string why;
  const bool ok = guarded(error, [&] {
    Database::Transaction t(*db_);
    if (number != 0 && find(read_chart(*db_), number) == nullptr) {
      why = fmt::format("material {} is not in the cut chart", number);
      return false;
    }
    const int before = read_selected(*db_);
    if (before == number) return true;
    Statement u = db_->prepare("UPDATE selection SET material = ?1");
    u.bind(1, number);
    u.run();
    Statement a = db_->prepare(
        "INSERT INTO audit(at_utc, interface, reason, what, old_value, new_value) VALUES(?1, ?2, ?3, ?4, ?5, "
        "?6)");
    const std::string at = clock_(), o = std::to_string(before), n = std::to_string(number);
    a.bind(1, std::string_view(at)).bind(2, interface).bind(3, "select").bind(4, "selected material");
    a.bind(5, std::string_view(o)).bind(6, std::string_view(n));
    a.run();
    t.commit();
    ++changes_;
    return true;
  });
  if (!why.empty() && error != nullptr) *error = why;
  return ok;
}

std::vector<AuditEntry> CutChartStore::audit(std::size_t limit, std::string* error) {
  std::lock_guard lock(mutex_);
  return guarded(error, [&] {
    std::vector<AuditEntry> out;
    Statement s = db_->prepare(
        limit == 0
            ? "SELECT id, at_utc, interface, reason, what, old_value, new_value FROM audit ORDER BY id"
            : "SELECT * FROM (SELECT id, at_utc, interface, reason, what, old_value, new_value FROM audit "
              "ORDER BY id DESC LIMIT ?1) ORDER BY id");
    if (limit != 0) s.bind(1, static_cast<std::int64_t>(limit));
    while (s.step())
      out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5), s.text(6)});
    return out;
  });
}

std::uint64_t CutChartStore::changes() {
  std::lock_guard lock(mutex_);
  try {
    const std::int64_t v = db_->data_version();
    if (v != data_version_) {
      data_version_ = v;
      ++changes_;
    }
  } catch (const std::exception&) {
  }
  return changes_;
}

void CutChartStore::set_clock(std::function<std::string()> clock) {
  std::lock_guard lock(mutex_);
  clock_ = std::move(clock);
}

}  // namespace opencnc::store
