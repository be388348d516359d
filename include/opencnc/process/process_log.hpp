// SPDX-License-Identifier: GPL-3.0-or-later
// process::ProcessLog — the process data of a run (load, positions, feed, helix error) at a set
// rate, to CSV or SQLite, written off the controller's thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "opencnc/controller/observer.hpp"
#include "opencnc/core/output_file.hpp"

namespace opencnc::process {

/// The file's format, from its name: `.csv`, or `.sqlite`/`.sqlite3`/`.db`.
enum class LogFormat : std::uint8_t { Csv, Sqlite };

/// The format a path names, or nullopt for another extension. Any thread.
std::optional<LogFormat> log_format(const std::string& path);

/// One row: a trace sample as logged.
struct ProcessRow {
  double t_s = 0;
  std::uint32_t line = 0;
  double load_kn = 0;
  double feed_mm_min = 0;  ///< of the linear axes (X Y Z U V W) over the last period
  Pose commanded{}, actual{};
  bool coupled = false;
  double coupling_error_deg = 0;
};

/// What the log holds besides the rows.
struct ProcessLogSetup {
  AxisMask axes;         ///< the columns: commanded and actual of each
  double rate_hz = 100;  ///< rows per second of servo time (at most one per trace sample)
  double servo_period_s = 0.001;
  double radius_mm = 0;          ///< > 0: the helix error is also given in µm at this radius
  std::string program, machine;  ///< written into the SQLite file's `run` table
};

/// An observer of the hub's trace (program runs): every 1/rate seconds of servo time the sample is
/// a row. Rows go to a queue; a thread of its own writes them — to the OutputFile directly (CSV),
/// or into a SQLite database in a temporary folder whose bytes become the OutputFile at finish()
/// — so neither the tick nor the controller's thread waits for the disk. The OutputFile is
/// committed by the caller after finish(), as for any output.
class ProcessLog final : public controller::ControllerObserver {
 public:
  /// `out` must outlive the log. Controller's thread (setup).
  ProcessLog(ProcessLogSetup setup, LogFormat format, OutputFile& out);
  ~ProcessLog() override;
  ProcessLog(const ProcessLog&) = delete;
  ProcessLog& operator=(const ProcessLog&) = delete;

  /// Controller's thread (the hub calls it).
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override;
  /// Writes what is queued, ends the writer and (SQLite) hands the database to the OutputFile.
  /// False with `*error` set if anything failed. Any thread but the hub's callbacks; once.
  bool finish(std::string* error);
  /// Rows logged so far. Any thread.
  std::uint64_t rows() const;

 private:
  void write_loop();
  void write_rows(const std::vector<ProcessRow>& rows);

  struct Sqlite;
  ProcessLogSetup setup_;
  LogFormat format_;
  OutputFile& out_;
  std::unique_ptr<Sqlite> db_;
  std::uint64_t every_ticks_ = 1, next_tick_ = 0, previous_tick_ = 0;
  Pose previous_{};  ///< the commanded pose of the last sample (the feed)
  bool started_ = false;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<ProcessRow> queue_;
  bool stop_ = false;
  std::uint64_t rows_ = 0;
  std::string error_;
  std::thread writer_;
};

}  // namespace opencnc::process
