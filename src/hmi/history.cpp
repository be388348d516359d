// SPDX-License-Identifier: GPL-3.0-or-later
// The machining history and audit trail in SQLite, written on a thread of their own.
#include "opencnc/hmi/history.hpp"

#include <sqlite3.h>

#include <chrono>
#include <ctime>

#include <fmt/format.h>

namespace opencnc::hmi {

namespace {

constexpr const char* kSchema = R"sql(
PRAGMA journal_mode = WAL;
PRAGMA synchronous = NORMAL;
CREATE TABLE IF NOT EXISTS jobs (
  id INTEGER PRIMARY KEY, job_id INTEGER, kind TEXT, program TEXT, started_utc TEXT, ended_utc TEXT,
  outcome TEXT, machining_s REAL, end_line INTEGER, alarms TEXT);
CREATE TABLE IF NOT EXISTS audit (
  id INTEGER PRIMARY KEY, time_utc TEXT, role TEXT, remote TEXT, action TEXT, body TEXT, status INTEGER,
  result TEXT);
)sql";

/// A prepared statement that finalizes itself.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) {
    ok_ = sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) == SQLITE_OK;
  }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  bool ok() const { return ok_; }
  void bind(int i, const std::string& v) {
    sqlite3_bind_text(s_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  void bind(int i, std::int64_t v) { sqlite3_bind_int64(s_, i, v); }
  void bind(int i, double v) { sqlite3_bind_double(s_, i, v); }
  int step() { return sqlite3_step(s_); }
  std::string text(int i) const {
    const auto* t = sqlite3_column_text(s_, i);
    return t ? reinterpret_cast<const char*>(t) : "";
  }
  std::int64_t integer(int i) const { return sqlite3_column_int64(s_, i); }
  double real(int i) const { return sqlite3_column_double(s_, i); }

 private:
  sqlite3_stmt* s_ = nullptr;
  bool ok_ = false;
};

/// Alarms are stored one per line (they are sentences without line breaks).
std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& a : v) s += (s.empty() ? "" : "\n") + a;
  return s;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> v;
  std::size_t from = 0;
  while (from < s.size()) {
    const std::size_t nl = s.find('\n', from);
    v.push_back(s.substr(from, nl == std::string::npos ? std::string::npos : nl - from));
    if (nl == std::string::npos) break;
    from = nl + 1;
  }
  return v;
}

}  // namespace

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::unique_ptr<History> History::open(const std::filesystem::path& path, std::string* error) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK ||
      sqlite3_exec(db, kSchema, nullptr, nullptr, nullptr) != SQLITE_OK) {
    if (error) *error = fmt::format("{}: {}", path.string(), db ? sqlite3_errmsg(db) : "cannot open");
    sqlite3_close(db);
    return nullptr;
  }
  sqlite3_busy_timeout(db, 2000);
  return std::unique_ptr<History>(new History(db));
}

History::History(sqlite3* db) : db_(db), thread_([this] { writer(); }) {}

History::~History() {
  {
    std::lock_guard lock(queue_mutex_);
    stop_ = true;
  }
  queue_cv_.notify_all();
  thread_.join();
  sqlite3_close(db_);
}

void History::add(JobRecord r) {
  {
    std::lock_guard lock(queue_mutex_);
    queue_.emplace_back(std::move(r));
  }
  queue_cv_.notify_one();
}

void History::add(AuditRecord r) {
  if (r.body.size() > 4096) r.body.resize(4096);
  {
    std::lock_guard lock(queue_mutex_);
    queue_.emplace_back(std::move(r));
  }
  queue_cv_.notify_one();
}

void History::flush() {
  std::unique_lock lock(queue_mutex_);
  idle_cv_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

void History::writer() {
  std::unique_lock lock(queue_mutex_);
  for (;;) {
    queue_cv_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty() && stop_) return;
    auto r = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    const bool ok = write(r);
    lock.lock();
    busy_ = false;
    if (!ok) ++failures_;
    idle_cv_.notify_all();
  }
}

bool History::write(const std::variant<JobRecord, AuditRecord>& r) {
  std::lock_guard lock(db_mutex_);
  int rc = SQLITE_ERROR;
  if (const auto* j = std::get_if<JobRecord>(&r)) {
    Statement s(db_,
                "INSERT INTO jobs (job_id, kind, program, started_utc, ended_utc, outcome, machining_s, "
                "end_line, alarms) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
    if (s.ok()) {
      s.bind(1, std::int64_t{j->job_id});
      s.bind(2, j->kind);
      s.bind(3, j->program);
      s.bind(4, j->started_utc);
      s.bind(5, j->ended_utc);
      s.bind(6, j->outcome);
      s.bind(7, j->machining_s);
      s.bind(8, std::int64_t{j->end_line});
      s.bind(9, join(j->alarms));
      rc = s.step();
    }
  } else {
    const auto& a = std::get<AuditRecord>(r);
    Statement s(db_,
                "INSERT INTO audit (time_utc, role, remote, action, body, status, result) VALUES (?, ?, ?, "
                "?, ?, ?, ?)");
    if (s.ok()) {
      s.bind(1, a.time_utc);
      s.bind(2, a.role);
      s.bind(3, a.remote);
      s.bind(4, a.action);
      s.bind(5, a.body);
      s.bind(6, std::int64_t{a.status});
      s.bind(7, a.result);
      rc = s.step();
    }
  }
  if (rc == SQLITE_DONE) return true;
  std::lock_guard q(queue_mutex_);
  last_error_ = sqlite3_errmsg(db_);
  return false;
}

std::vector<JobRecord> History::jobs(int limit) const {
  std::lock_guard lock(db_mutex_);
  Statement s(
      db_,
      "SELECT id, job_id, kind, program, started_utc, ended_utc, outcome, machining_s, end_line, alarms "
      "FROM jobs ORDER BY id DESC LIMIT ?");
  std::vector<JobRecord> out;
  if (!s.ok()) return out;
  s.bind(1, std::int64_t{limit});
  while (s.step() == SQLITE_ROW) {
    out.push_back({s.integer(0), static_cast<std::uint32_t>(s.integer(1)), s.text(2), s.text(3), s.text(4),
                   s.text(5), s.text(6), s.real(7), static_cast<std::uint32_t>(s.integer(8)),
                   split(s.text(9))});
  }
  return out;
}

std::vector<AuditRecord> History::audit(int limit) const {
  std::lock_guard lock(db_mutex_);
  Statement s(
      db_,
      "SELECT id, time_utc, role, remote, action, body, status, result FROM audit ORDER BY id DESC LIMIT ?");
  std::vector<AuditRecord> out;
  if (!s.ok()) return out;
  s.bind(1, std::int64_t{limit});
  while (s.step() == SQLITE_ROW) {
    out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5),
                   static_cast<int>(s.integer(6)), s.text(7)});
  }
  return out;
}

std::uint64_t History::failures() const {
  std::lock_guard lock(queue_mutex_);
  return failures_;
}

std::string History::last_error() const {
  std::lock_guard lock(queue_mutex_);
  return last_error_;
}

void HistoryRecorder::on_event(const controller::ControllerEvent& e) {
  using controller::ControllerEventKind;
  if (e.kind == ControllerEventKind::JobStarted &&
      (e.job == controller::JobKind::Program || e.job == controller::JobKind::Auxiliary)) {
    JobRecord r;
    r.job_id = e.job_id;
    r.kind = controller::to_string(e.job);
    r.program = e.text;
    r.started_utc = utc_now();
    running_ = std::move(r);
    started_tick_ = e.tick;
  } else if (running_ && (e.kind == ControllerEventKind::Note || e.kind == ControllerEventKind::Answer) &&
             e.severity != Severity::Note && running_->alarms.size() < 100) {
    running_->alarms.push_back(e.code.empty() ? e.text : fmt::format("{} [{}]", e.text, e.code));
  } else if (running_ && e.kind == ControllerEventKind::JobEnded && e.job_id == running_->job_id) {
    running_->ended_utc = utc_now();
    running_->outcome = controller::to_string(e.end);
    running_->machining_s = static_cast<double>(e.tick - started_tick_) * period_s_;
    running_->end_line = e.location.line;
    history_->add(std::move(*running_));
    running_.reset();
  }
}

}  // namespace opencnc::hmi
