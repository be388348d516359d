// SPDX-License-Identifier: GPL-3.0-or-later
// SQLite behind store::Database: durability pragmas, statements, transactions.
#include "opencnc/store/database.hpp"

#include <sqlite3.h>

#include <fmt/format.h>

namespace opencnc::store {

namespace {

[[noreturn]] void fail(sqlite3* db, std::string_view what) {
  throw Error(fmt::format("{}: {}", what, db != nullptr ? sqlite3_errmsg(db) : "out of memory"));
}

}  // namespace

Statement::Statement(sqlite3* db, std::string_view sql) : db_(db) {
  if (sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr) != SQLITE_OK)
    fail(db, "cannot prepare a statement");
}

Statement::~Statement() {
  sqlite3_finalize(stmt_);
}

Statement& Statement::bind(int index, double v) {
  if (sqlite3_bind_double(stmt_, index, v) != SQLITE_OK) fail(db_, "cannot bind a value");
  return *this;
}

Statement& Statement::bind(int index, std::int64_t v) {
  if (sqlite3_bind_int64(stmt_, index, v) != SQLITE_OK) fail(db_, "cannot bind a value");
  return *this;
}

Statement& Statement::bind(int index, std::string_view v) {
  if (sqlite3_bind_text(stmt_, index, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT) != SQLITE_OK)
    fail(db_, "cannot bind a value");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  sqlite3_reset(stmt_);
  fail(db_, "the database refused");
}

void Statement::run() {
  while (step()) {
  }
  reset();
}

void Statement::reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

double Statement::real(int column) const {
  return sqlite3_column_double(stmt_, column);
}
std::int64_t Statement::integer(int column) const {
  return sqlite3_column_int64(stmt_, column);
}
std::string Statement::text(int column) const {
  const auto* p = sqlite3_column_text(stmt_, column);
  return p != nullptr ? std::string(reinterpret_cast<const char*>(p),
                                    static_cast<std::size_t>(sqlite3_column_bytes(stmt_, column)))
                      : std::string();
}

namespace {

/// `path` as an SQLite URI filename (file:…, with %, ? and # escaped) with `query`.
std::string uri(const std::string& path, std::string_view query) {
  std::string out = "file:";
  for (const char c : path) {
    if (c == '%' || c == '?' || c == '#')
      out += fmt::format("%{:02X}", static_cast<unsigned char>(c));
    else
      out += c;
  }
  return out + "?" + std::string(query);
}

}  // namespace

Database::Database(const std::string& path, OpenOptions options) : path_(path) {
  const int flags = options.read_only ? SQLITE_OPEN_READONLY
                                      : (SQLITE_OPEN_READWRITE | (options.create ? SQLITE_OPEN_CREATE : 0));
  if (sqlite3_open_v2(path.c_str(), &db_, flags | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK) {
    const std::string why = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw Error(fmt::format("cannot open {}: {}", path, why));
  }
  sqlite3_busy_timeout(db_, 5000);
  if (options.read_only &&
      sqlite3_exec(db_, "SELECT count(*) FROM sqlite_schema", nullptr, nullptr, nullptr) != SQLITE_OK) {
    // A WAL database in a folder this user may not write (read-only media, another user's store):
    // its shared-memory index cannot be made there. Read it as an unchanging file instead; a
    // writer elsewhere at the same time is the one case this cannot see.
    sqlite3_close(db_);
    db_ = nullptr;
    if (sqlite3_open_v2(uri(path, "immutable=1").c_str(), &db_,
                        SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK) {
      const std::string why = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw Error(fmt::format("cannot open {}: {}", path, why));
    }
  }
  try {
    // Reading the schema proves it is a database before anything is written to it.
    query_integer("SELECT count(*) FROM sqlite_schema");
    if (!options.read_only) {
      // WAL: readers (the HMI, `opencnc tools`) never block the writer; a commit appends to the
      // log, so a cut mid-write leaves the database file as it was. synchronous=FULL: the log is
      // fsync'ed at every commit, so a change reported as stored survives a power cut (NORMAL
      // would only keep the database consistent, and may lose the last commits).
      exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON;");
    }
  } catch (const Error& e) {
    sqlite3_close(db_);
    throw Error(fmt::format("{}: {}", path, e.what()));
  }
}

Database::~Database() {
  sqlite3_close(db_);
}

void Database::exec(std::string_view sql) {
  char* message = nullptr;
  const std::string s(sql);
  if (sqlite3_exec(db_, s.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string why = message != nullptr ? message : sqlite3_errmsg(db_);
    sqlite3_free(message);
    throw Error(why);
  }
}

std::int64_t Database::query_integer(std::string_view sql) {
  Statement s(db_, sql);
  return s.step() ? s.integer(0) : 0;
}

std::int64_t Database::data_version() {
  return query_integer("PRAGMA data_version");
}

Database::Transaction::Transaction(Database& db) : db_(db) {
  db_.exec("BEGIN IMMEDIATE");
}

Database::Transaction::~Transaction() {
  if (!done_) sqlite3_exec(db_.db_, "ROLLBACK", nullptr, nullptr, nullptr);
}

void Database::Transaction::commit() {
  db_.exec("COMMIT");
  done_ = true;
}

}  // namespace opencnc::store
