// SPDX-License-Identifier: GPL-3.0-or-later
// Machining history and the audit trail in SQLite: each job (program, start, end, outcome,
// alarms, machining time) and each change a client asked for (who, when, what, the answer).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "opencnc/controller/observer.hpp"

struct sqlite3;

namespace opencnc::hmi {

/// One job of the machining history.
struct JobRecord {
  std::int64_t id = 0;  ///< row number (0 before it is stored)
  std::uint32_t job_id = 0;
  std::string kind;                    ///< "program", "auxiliary"
  std::string program;                 ///< its name
  std::string started_utc, ended_utc;  ///< ISO 8601, seconds
  std::string outcome;                 ///< "finished", "aborted", "error", "fault"
  double machining_s = 0;              ///< machine time from start to end
  std::uint32_t end_line = 0;          ///< the source line where it ended
  std::vector<std::string> alarms;     ///< warnings and errors while it ran, in words
};

/// One audited request: who asked what, when, and what came of it.
struct AuditRecord {
  std::int64_t id = 0;
  std::string time_utc;
  std::string role;    ///< "operator", "admin", "" for a refused token
  std::string remote;  ///< the client's address
  std::string action;  ///< "POST /api/v1/commands"
  std::string body;    ///< the request body (at most 4 KiB of it)
  int status = 0;      ///< the HTTP status answered
  std::string result;  ///< accepted, the refusal, or why the API refused it
};

/// The history database. Writes are queued and done on a thread of its own (never on the
/// controller's); reads from any thread.
class History {
 public:
  /// Opens (creating) the database at `path`; nothing (and `*error`) when it cannot.
  static std::unique_ptr<History> open(const std::filesystem::path& path, std::string* error);
  ~History();
  History(const History&) = delete;
  History& operator=(const History&) = delete;

  /// Queues a record for the writer thread. Any thread; does not wait for the disk.
  void add(JobRecord r);
  void add(AuditRecord r);
  /// Waits until everything queued so far is written. Any thread.
  void flush();
  /// The newest `limit` jobs / audit records, newest first. Any thread.
  std::vector<JobRecord> jobs(int limit) const;
  std::vector<AuditRecord> audit(int limit) const;
  /// Writes that failed (the disk full, the file gone); the last error in words. Any thread.
  std::uint64_t failures() const;
  std::string last_error() const;

 private:
  explicit History(sqlite3* db);
  void writer();
  bool write(const std::variant<JobRecord, AuditRecord>& r);

  sqlite3* db_;
  mutable std::mutex db_mutex_;  ///< the connection
  mutable std::mutex queue_mutex_;
  std::condition_variable queue_cv_, idle_cv_;
  std::deque<std::variant<JobRecord, AuditRecord>> queue_;
  bool stop_ = false, busy_ = false;
  std::uint64_t failures_ = 0;
  std::string last_error_;
  std::thread thread_;
};

/// The current UTC time as ISO 8601 ("2026-11-26T03:10:00Z"). Any thread.
std::string utc_now();

/// Turns the event log into job records: a ControllerObserver (controller thread) that hands
/// each finished program or auxiliary job to the History (which writes on its own thread).
class HistoryRecorder final : public controller::ControllerObserver {
 public:
  HistoryRecorder(History& history, double servo_period_s) : history_(&history), period_s_(servo_period_s) {}
  void on_event(const controller::ControllerEvent& e) override;

 private:
  History* history_;
  double period_s_;
  std::optional<JobRecord> running_;
  std::uint64_t started_tick_ = 0;
};

}  // namespace opencnc::hmi
