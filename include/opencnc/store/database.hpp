// SPDX-License-Identifier: GPL-3.0-or-later
// store::Database — one SQLite connection with opencnc's durability settings, prepared
// statements and transactions that commit whole or not at all.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

struct sqlite3;
struct sqlite3_stmt;

namespace opencnc::store {

/// What went wrong in SQLite, in words ("database is locked", "disk I/O error"). Thrown inside
/// the store layer; its users turn it into a message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One prepared statement. Parameters are 1-based, columns 0-based. Not thread-safe; the
/// Database it came from must outlive it.
class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int index, double v);
  Statement& bind(int index, std::int64_t v);
  Statement& bind(int index, int v) { return bind(index, static_cast<std::int64_t>(v)); }
  Statement& bind(int index, std::string_view v);
  /// Steps once: true while a row is there to read, false when done. Throws Error.
  bool step();
  /// Steps to the end (statements without rows), then resets for the next use.
  void run();
  /// Clears the bindings' use: the statement can run again.
  void reset();

  double real(int column) const;
  std::int64_t integer(int column) const;
  std::string text(int column) const;

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

/// How a database file is opened.
struct OpenOptions {
  bool create = true;      ///< create the file when it is not there
  bool read_only = false;  ///< never write (inspection)
};

/// A SQLite database file, opened in WAL mode with synchronous=FULL: a commit is on the disk
/// when commit() returns, and a crash or power cut at any moment leaves the last committed
/// state (the write-ahead log is replayed or ignored on the next open). See docs/tool-guard.md,
/// "Power cuts", for why these settings. One thread at a time per Database; other processes may
/// open the same file (a busy database is waited for up to 5 s).
class Database {
 public:
  /// Opens `path`. Throws Error with the reason when it cannot be opened or is not a database.
  Database(const std::string& path, OpenOptions options = {});
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  /// Runs one or more statements without results. Throws Error.
  void exec(std::string_view sql);
  /// A statement to bind and step. Throws Error when it does not compile.
  Statement prepare(std::string_view sql) { return Statement(db_, sql); }
  /// The value of a one-value query ("PRAGMA user_version"). Throws Error.
  std::int64_t query_integer(std::string_view sql);
  /// Changes when another connection commits (PRAGMA data_version): a cache compares it.
  std::int64_t data_version();
  const std::string& path() const noexcept { return path_; }

  /// BEGIN IMMEDIATE on construction (the write lock is taken at once, so two writers never
  /// deadlock halfway); ROLLBACK on destruction unless commit() ran. Not thread-safe.
  class Transaction {
   public:
    explicit Transaction(Database& db);
    ~Transaction();
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
    /// COMMIT: durable when it returns. Throws Error (the transaction is then rolled back).
    void commit();

   private:
    Database& db_;
    bool done_ = false;
  };

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

}  // namespace opencnc::store
