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

#include "opencnc/broaching/breakpoint.hpp"
#include "opencnc/broaching/journal.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::controller {
class GcodeProgramSource;
}

namespace opencnc::recovery {

/// `Request::feature("journal", "resume", ResumeArgs{…})`: how far the axes may be from where the
/// record says they rest.
struct ResumeArgs {
  double tolerance_mm = 0.01;   ///< linear axes
  double tolerance_deg = 0.01;  ///< rotary axes
  /// Run-in: the master backs off this far along the interrupted move (the slave on the law)
  /// before the program cuts on, so the drives have settled at the cutting speed by the time the
  /// tool reaches the breakpoint (they lag differently while they break away from rest). 0: none;
  /// never more than the move's part already cut.
  double run_in_mm = 2.0;
  double run_in_speed_mm_min = 600;  ///< of the master, backing off
};

/// `Request::feature("journal", "retract", RetractArgs{…})`: along the master (Z) by `distance_mm`,
/// the slave (C) held on the law; onward in the interrupted move's direction, or back.
struct RetractArgs {
  double distance_mm = 0;
  bool onward = false;
  double speed_mm_min = 100;  ///< of the master
};

/// Where a recovery choice is.
enum class RecoveryPhase : std::uint8_t { None, Opening, RunningIn, Resuming, Retracting, Done, Failed };

/// The breakpoint journal's writer, a Feature named "journal". Add it with
/// `Controller::add_feature(f, {servo period, true})`: it follows the status and the trace every
/// period. At the first period of a power-fail stop during a program it builds the record from
/// the trace sample and the status before the signal (the spindle, coolant, tool and coupling as
/// the program had them) and hands it to its writer thread, which makes it durable; once the
/// machine has come to rest (the power-loss fault) the record is completed with where it rests
/// and written again, then once more with the modal digest (a replay on the writer thread).
/// Requests: `Request::feature("journal", "show")` says what the journal holds; after the power
/// returns, with a valid record, "resume" (ResumeArgs), "retract" (RetractArgs) and "discard" —
/// each clears the valid flag once it has completed (docs/broaching.md, "Recovery").
class BreakpointJournal final : public controller::Feature {
 public:
  /// Opens the journal in `dir` (created if missing); `source` gives the interpreter options of
  /// a file for the modal digest (null: the digest stays 0). Nullptr with `*error` on failure.
  /// Controller thread (or before the controller runs).
  static std::shared_ptr<BreakpointJournal> open(const std::string& dir,
                                                 std::shared_ptr<controller::GcodeProgramSource> source,
                                                 std::string* error);
  ~BreakpointJournal() override;
  BreakpointJournal(const BreakpointJournal&) = delete;
  BreakpointJournal& operator=(const BreakpointJournal&) = delete;

  std::string_view name() const override { return "journal"; }
  void attached(controller::FeatureHost& host) override { host_ = &host; }
  void on_event(const controller::ControllerEvent& e) override;
  void on_status(const controller::ControllerStatus& s) override;
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override;
  controller::Outcome handle(const controller::requests::Feature& request,
                             controller::FeatureHost& host) override;

  /// Waits until everything handed to the writer is durable (or failed). Any thread but the writer.
  void flush();
  /// The last record made durable by this writer (nullopt: none yet). Any thread.
  std::optional<BreakpointRecord> last_written() const;
  /// Signal to durable record of every power-fail stop's first write, milliseconds of wall
  /// time from the period the feature saw the signal in. Any thread.
  std::vector<double> latencies_ms() const;
  /// The last write's error ("" = none). Any thread.
  std::string last_error() const;
  /// How the writer makes a record durable and at what priority, in words: the journal's way
  /// (Journal::how), the thread's scheduling (SCHED_FIFO 70, or why not) and its I/O priority
  /// (real-time class, or why not); the way alone until the writer thread has started. Any thread.
  std::string writer_status() const;
  /// Where the last recovery choice is, and why it failed. Controller thread.
  RecoveryPhase phase() const noexcept { return phase_; }
  const std::string& recovery_error() const noexcept { return recovery_error_; }

 private:
  using Clock = std::chrono::steady_clock;
  struct Work {
    BreakpointRecord record;
    std::optional<Clock::time_point> signal;  ///< the first record of a stop: its latency counts
    bool digest = false;                      ///< replay for the modal digest after writing
    bool hash_only = false;                   ///< hash the program just opened (no record)
    gcode::Options options;                   ///< the program's interpreter options (digest)
  };

  BreakpointJournal(std::unique_ptr<Journal> journal, std::shared_ptr<controller::GcodeProgramSource> source);
  void post(Work w);
  void writer_loop();
  void write_one(Work& w);
  void set_writer_status(bool fifo, bool rt_io);
  void begin_record(const control::TraceSample& s, const controller::TraceContext& c);
  void complete_record();
  // Recovery (breakpoint_recovery.cpp).
  controller::Outcome start_resume(const BreakpointRecord& r, const ResumeArgs& args,
                                   controller::FeatureHost& host);
  controller::Outcome start_retract(const BreakpointRecord& r, const RetractArgs& args,
                                    controller::FeatureHost& host);
  std::shared_ptr<const canon::Program> along_helix(const BreakpointRecord& r, double distance_mm,
                                                    bool onward, double speed_mm_min,
                                                    controller::FeatureHost& host, std::string* why) const;
  void recovery_event(const controller::ControllerEvent& e);
  void run_in();
  void finish_recovery(bool ok, std::string why);
  void clear_valid();
  double period_s() const { return host_ != nullptr ? host_->profile().servo_period_s : 0.0; }

  std::unique_ptr<Journal> journal_;
  std::shared_ptr<controller::GcodeProgramSource> source_;
  controller::FeatureHost* host_ = nullptr;

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
  // The recovery under way: its phase, the request it waits for, the record it acts on.
  RecoveryPhase phase_ = RecoveryPhase::None;
  std::uint64_t pending_ = 0;
  BreakpointRecord recovering_;
  ResumeArgs resume_args_;
  std::string recovery_error_;

  // Shared with the writer thread.
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::vector<Work> queue_;
  bool busy_ = false, stop_ = false;
  std::optional<BreakpointRecord> written_;
  std::vector<double> latencies_ms_;
  std::string error_;
  std::string writer_status_;
  // Writer thread only: the content hash of the program opened last.
  std::string hashed_path_;
  FileHash hash_;
  bool fifo_ = false, rt_io_ = false;  ///< what the writer thread was granted
  std::thread writer_;
};

}  // namespace opencnc::recovery
