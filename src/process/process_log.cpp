// SPDX-License-Identifier: GPL-3.0-or-later
// ProcessLog: trace samples at the log's rate, queued, and written by a thread of its own to CSV
// or to a SQLite database that becomes the output file at the end.
#include "opencnc/process/process_log.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "opencnc/core/number_format.hpp"
#include "opencnc/store/database.hpp"

namespace opencnc::process {

namespace {

constexpr double kPi = 3.141592653589793;
/// Rows the writer takes at once (one SQLite transaction): a second at 100 Hz.
constexpr std::size_t kBatchRows = 100;

std::string lower_extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& ch : e) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return e;
}

/// The columns of a row, in order (CSV header and SQLite table alike).
std::vector<std::string> columns(const ProcessLogSetup& s) {
  std::vector<std::string> c = {"t_s", "line", "load_kn", "feed_mm_min"};
  for (int i = 0; i < kAxisCount; ++i) {
    if (!s.axes.has(static_cast<Axis>(i))) continue;
    const char l = static_cast<char>(std::tolower(kAxisLetters[static_cast<std::size_t>(i)]));
    c.push_back(fmt::format("{}_cmd", l));
    c.push_back(fmt::format("{}_act", l));
  }
  c.insert(c.end(), {"coupled", "coupling_error_deg"});
  if (s.radius_mm > 0) c.push_back("helix_error_um");
  return c;
}

/// The row's values in column order (the integers as doubles; SQLite keeps them REAL but 'line'
/// and 'coupled').
std::vector<double> values(const ProcessLogSetup& s, const ProcessRow& r) {
  std::vector<double> v = {r.t_s, static_cast<double>(r.line), r.load_kn, r.feed_mm_min};
  for (int i = 0; i < kAxisCount; ++i) {
    if (!s.axes.has(static_cast<Axis>(i))) continue;
    v.push_back(r.commanded[static_cast<Axis>(i)]);
    v.push_back(r.actual[static_cast<Axis>(i)]);
  }
  v.push_back(r.coupled ? 1.0 : 0.0);
  v.push_back(r.coupling_error_deg);
  if (s.radius_mm > 0) v.push_back(r.coupling_error_deg * kPi / 180 * s.radius_mm * 1000);
  return v;
}

}  // namespace

std::optional<LogFormat> log_format(const std::string& path) {
  const std::string e = lower_extension(path);
  if (e == ".csv") return LogFormat::Csv;
  if (e == ".sqlite" || e == ".sqlite3" || e == ".db") return LogFormat::Sqlite;
  return std::nullopt;
}

/// The database the rows go into, in a folder of its own under the temporary directory: SQLite
/// needs a file it may write in place, the user's output is replaced whole at commit.
struct ProcessLog::Sqlite {
  std::filesystem::path dir;
  std::unique_ptr<store::Database> db;
  std::string insert;  ///< the row's INSERT (prepared once per batch: a Statement does not move)
  ~Sqlite() {
    db.reset();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
};

ProcessLog::ProcessLog(ProcessLogSetup setup, LogFormat format, OutputFile& out)
    : setup_(std::move(setup)), format_(format), out_(out) {
  every_ticks_ = static_cast<std::uint64_t>(
      std::max(1.0, std::floor(1.0 / (setup_.rate_hz * setup_.servo_period_s) + 1e-9)));
  const std::vector<std::string> cols = columns(setup_);
  if (format_ == LogFormat::Csv) {
    std::string header;
    for (const std::string& c : cols) header += (header.empty() ? "" : ",") + c;
    out_.write(header + "\n");
  } else {
    db_ = std::make_unique<Sqlite>();
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    db_->dir =
        std::filesystem::temp_directory_path() / fmt::format("opencnc-process-log-{}-{}", ::getpid(), stamp);
    std::filesystem::create_directories(db_->dir);
    db_->db = std::make_unique<store::Database>((db_->dir / "log.sqlite").string());
    std::string defs, marks;
    for (const std::string& c : cols) {
      defs += fmt::format("{}{} {}", defs.empty() ? "" : ", ", c,
                          c == "line" || c == "coupled" ? "INTEGER" : "REAL");
      marks += marks.empty() ? "?" : ", ?";
    }
    db_->db->exec(
        "CREATE TABLE run (program TEXT, machine TEXT, rate_hz REAL, servo_period_s REAL);"
        "CREATE TABLE process_data (" +
        defs + ");");
    db_->db->prepare("INSERT INTO run VALUES (?, ?, ?, ?)")
        .bind(1, setup_.program)
        .bind(2, setup_.machine)
        .bind(3, setup_.rate_hz)
        .bind(4, setup_.servo_period_s)
        .run();
    db_->insert = "INSERT INTO process_data VALUES (" + marks + ")";
  }
  writer_ = std::thread([this] { write_loop(); });
}

ProcessLog::~ProcessLog() {
  if (writer_.joinable()) {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    writer_.join();
  }
}

void ProcessLog::on_trace(const control::TraceSample& s, const controller::TraceContext&) {
  // The feed of the linear axes from this sample and the one before (the path velocity would mix
  // in the degrees of a coupled C).
  double feed_mm_s = 0;
  if (started_ && s.tick > previous_tick_) {
    double d2 = 0;
    for (const Axis a : {Axis::X, Axis::Y, Axis::Z, Axis::U, Axis::V, Axis::W}) {
      const double d = s.commanded[a] - previous_[a];
      d2 += d * d;
    }
    feed_mm_s = std::sqrt(d2) / (static_cast<double>(s.tick - previous_tick_) * setup_.servo_period_s);
  }
  previous_ = s.commanded;
  previous_tick_ = s.tick;
  if (!started_) {
    started_ = true;
    next_tick_ = s.tick;
  }
  if (s.tick < next_tick_) return;
  next_tick_ = s.tick + every_ticks_;
  ProcessRow r;
  r.t_s = static_cast<double>(s.tick) * setup_.servo_period_s;
  r.line = s.line;
  r.load_kn = s.load_kn;
  r.feed_mm_min = feed_mm_s * 60;
  r.commanded = s.commanded;
  r.actual = s.actual;
  r.coupled = s.coupled;
  r.coupling_error_deg = s.coupling_error_deg;
  bool wake = false;
  {
    const std::lock_guard lock(mutex_);
    queue_.push_back(r);
    ++rows_;
    wake = queue_.size() >= kBatchRows;
  }
  if (wake) wake_.notify_one();
}

std::uint64_t ProcessLog::rows() const {
  const std::lock_guard lock(mutex_);
  return rows_;
}

void ProcessLog::write_loop() {
  std::vector<ProcessRow> batch;
  for (;;) {
    bool done = false;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || queue_.size() >= kBatchRows; });
      batch.swap(queue_);
      done = stop_;
    }
    if (!batch.empty() && error_.empty()) write_rows(batch);
    batch.clear();
    if (done) return;
  }
}

void ProcessLog::write_rows(const std::vector<ProcessRow>& rows) {
  if (format_ == LogFormat::Csv) {
    std::string text;
    char number[kFixedBufferSize];
    const std::size_t coupled = 4 + 2 * static_cast<std::size_t>(setup_.axes.count());  // after the axes
    for (const ProcessRow& r : rows) {
      text.clear();
      const std::vector<double> v = values(setup_, r);
      for (std::size_t i = 0; i < v.size(); ++i) {
        const int decimals = i == 1 || i == coupled ? 0 : (i == 0 ? 4 : 6);  // line and coupled are whole
        const std::size_t n = format_fixed(number, v[i], decimals);
        text.append(i ? "," : "").append(number, n);
      }
      if (!out_.write(text + "\n")) return;  // commit says why
    }
    return;
  }
  try {
    db_->db->exec("BEGIN");
    store::Statement insert = db_->db->prepare(db_->insert);
    for (const ProcessRow& r : rows) {
      const std::vector<double> v = values(setup_, r);
      for (std::size_t i = 0; i < v.size(); ++i) insert.bind(static_cast<int>(i + 1), v[i]);
      insert.run();
    }
    db_->db->exec("COMMIT");
  } catch (const store::Error& e) {
    error_ = fmt::format("the process log's database: {}", e.what());
  }
}

bool ProcessLog::finish(std::string* error) {
  if (writer_.joinable()) {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    writer_.join();
  }
  if (error_.empty() && db_) {
    const std::filesystem::path file = db_->dir / "log.sqlite";
    db_->db.reset();  // the last connection: SQLite checkpoints the write-ahead log into the file
    std::ifstream in(file, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (!in || !out_.write(bytes.str()))
      error_ = "the process log's database could not be copied to its file";
  }
  if (!error_.empty() && error != nullptr) *error = error_;
  return error_.empty();
}

}  // namespace opencnc::process
