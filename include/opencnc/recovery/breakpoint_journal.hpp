// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::BreakpointJournal — the hub feature that writes the breakpoint record when a power-fail
// stop begins (at the signal, then completed where the motion came to rest), on a thread of its
// own through recovery::Journal, so neither the servo nor the controller waits for the disk.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "opencnc/controller/observer.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/recovery/breakpoint.hpp"
#include "opencnc/recovery/journal.hpp"

namespace opencnc::control {
class GcodeProgramSource;
}

namespace opencnc::recovery {

/// The breakpoint journal's writer, a Feature named "journal". Add it with
/// `Controller::add_feature(f, {servo period, true})`: it follows the status and the trace every
/// period. At the first period of a power-fail stop during a program it builds the record from
/// the trace sample and the status before the signal (the spindle, coolant, tool and coupling as
/// the program had them) and hands it to its writer thread, which makes it durable; once the
/// machine has come to rest (the power-loss fault) the record is completed with where it rests
/// and written again, then once more with the modal digest (a replay on the writer thread).
/// Requests: `Request::feature("journal", "show")` says what the journal holds.
class BreakpointJournal final : public control::Feature {
 public:
  /// Opens the journal in `dir` (created if missing); `source` gives the interpreter options of
  /// a file for the modal digest (null: the digest stays 0). Nullptr with `*error` on failure.
  /// Controller thread (or before the controller runs).
  static std::shared_ptr<BreakpointJournal> open(const std::string& dir,
                                                 std::shared_ptr<control::GcodeProgramSource> source,
                                                 std::string* error);
  ~BreakpointJournal() override;
  BreakpointJournal(const BreakpointJournal&) = delete;
  BreakpointJournal& operator=(const BreakpointJournal&) = delete;

  std::string_view name() const override { return "journal"; }
  void attached(control::FeatureHost& host) override { host_ = &host; }
  void on_event(const control::ControllerEvent& e) override;
  void on_status(const control::ControllerStatus& s) override;
  void on_trace(const control::TraceSample& s, const control::TraceContext& c) override;
  control::Outcome handle(const control::requests::Feature& request, control::FeatureHost& host) override;

  /// Waits until everything handed to the writer is durable (or failed). Any thread but the writer.
  void flush();
  /// The last record made durable by this writer (nullopt: none yet). Any thread.
  std::optional<BreakpointRecord> last_written() const;
  /// Signal to durable record of every power-fail stop's first write, milliseconds of wall
  /// time from the period the feature saw the signal in. Any thread.
  std::vector<double> latencies_ms() const;
  /// The last write's error ("" = none). Any thread.
  std::string last_error() const;

 private:
  using Clock = std::chrono::steady_clock;
  struct Work {
    BreakpointRecord record;
    std::optional<Clock::time_point> signal;  ///< the first record of a stop: its latency counts
    bool digest = false;                      ///< replay for the modal digest after writing
    bool hash_only = false;                   ///< hash the program just opened (no record)
    gcode::Options options;                   ///< the program's interpreter options (digest)
  };

  BreakpointJournal(std::unique_ptr<Journal> journal, std::shared_ptr<control::GcodeProgramSource> source);
  void post(Work w);
  void writer_loop();
  void write_one(Work& w);
  void begin_record(const control::TraceSample& s, const control::TraceContext& c);
  void complete_record();
  double period_s() const { return host_ != nullptr ? host_->profile().servo_period_s : 0.0; }

  std::unique_ptr<Journal> journal_;
  std::shared_ptr<control::GcodeProgramSource> source_;
  control::FeatureHost* host_ = nullptr;

  // Controller thread: the program, what the servo did before the signal, the stop under way.
  std::string path_;
  Pose program_start_{};
  std::optional<gcode::Options> options_;
  control::ServoStatus before_{};  ///< the last status before the signal (spindle, coolant, tool, coupling)
  std::uint64_t job_move_ = 0;
  double segment_offset_ = 0;
  double move_length_mm_ = 0;  ///< of the interrupted move
  bool stopping_ = false, completed_ = false;
  BreakpointRecord record_;

  // Shared with the writer thread.
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::vector<Work> queue_;
  bool busy_ = false, stop_ = false;
  std::optional<BreakpointRecord> written_;
  std::vector<double> latencies_ms_;
  std::string error_;
  // Writer thread only: the content hash of the program opened last.
  std::string hashed_path_;
  FileHash hash_;
  std::thread writer_;
};

}  // namespace opencnc::recovery
