// SPDX-License-Identifier: GPL-3.0-or-later
// The controller's event log: every servo event, note, answer, job start and end and sync point,
// numbered, kept in a ring of fixed-size entries allocated once, which any number of readers follow
// with cursors of their own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "opencnc/control/command.hpp"
#include "opencnc/controller/controller_status.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::controller {

enum class ControllerEventKind : std::uint8_t {
  Servo,          ///< `servo`: what the servo reported (state changes, faults, homing, …)
  Note,           ///< something for the operator to read: a program's (MSG,…), a fault or error in words
  Answer,         ///< request `request_id` was answered (`accepted`, refusal `code`, `text`)
  ProgramOpened,  ///< a main program passed its preflight and is open (`text` = its name)
  JobStarted,     ///< job `job_id` (`job`) started
  JobEnded,       ///< job `job_id` ended (`end`, at `segment`, `location`)
  SyncWait,       ///< the interpreter waits at sync point `sync` (`location`) for the machine
  SyncDone,       ///< the machine answered sync point `sync`; the interpreter reads on
};

/// "servo", "note", "answer", "program-opened", "job-started", "job-ended", "sync-wait", "sync-done".
const char* to_string(ControllerEventKind k) noexcept;

/// One entry of the log. Which fields apply depends on `kind`.
struct ControllerEvent {
  std::uint64_t seq = 0;   ///< its number in the log: 1, 2, 3 … (never reused)
  std::uint64_t tick = 0;  ///< servo period when the controller saw it
  ControllerEventKind kind = ControllerEventKind::Note;
  Severity severity = Severity::Note;
  std::string code;  ///< stable problem code (control.*, gcode.*) or ""
  std::string text;  ///< in words
  control::ServoEvent servo{};
  std::uint64_t request_id = 0;
  bool accepted = false;
  JobKind job = JobKind::None;
  std::uint32_t job_id = 0;
  JobEnd end = JobEnd::Finished;
  SyncKind sync = SyncKind::None;
  std::uint64_t segment = 0;
  SourceLocation location;
};

/// What one entry of the log keeps of the strings of a ControllerEvent, in bytes (with the
/// terminating zero). A longer string is cut at a UTF-8 character boundary and ends in "…".
inline constexpr std::size_t kEventCodeBytes = 48;
inline constexpr std::size_t kEventTextBytes = 240;
inline constexpr std::size_t kEventFileBytes = 96;
/// The call chain (SourceLocation::calls), all calls together.
inline constexpr std::size_t kEventCallsBytes = 112;

struct StoredEvent;  // one fixed-size entry of the ring (events.cpp)

/// The numbered, bounded log. Its memory is allocated and touched once, at construction: a long
/// job's events never grow it. append() from the controller thread; reads from any thread.
class EventLog {
 public:
  explicit EventLog(std::size_t capacity = 16384);
  ~EventLog();
  EventLog(const EventLog&) = delete;
  EventLog& operator=(const EventLog&) = delete;
  /// Numbers `e` and copies it into the ring (strings cut to the capacities above), overwriting
  /// the oldest entry when full; returns its number. Allocates nothing.
  std::uint64_t append(const ControllerEvent& e);
  /// The number of the newest entry (0 while empty).
  std::uint64_t last() const;
  /// Up to `max` entries numbered after `after`, oldest first. `*lost` (if given) is set to how
  /// many entries after `after` were dropped before they could be read.
  std::vector<ControllerEvent> read_after(std::uint64_t after, std::size_t max, std::uint64_t* lost) const;

 private:
  mutable std::mutex mutex_;
  std::size_t capacity_;
  std::unique_ptr<StoredEvent[]> ring_;  // entry n lives at (n - 1) % capacity_
  std::uint64_t next_ = 1;
};

/// One reader's place in the log: an HMI, a recorder and a logger each keep their own and never
/// take each other's events. Any thread (one cursor per thread).
class EventCursor {
 public:
  /// Starts after the newest entry (`from_start`: at the oldest one still kept).
  explicit EventCursor(const EventLog& log, bool from_start = false);
  /// The entries since the last call (at most `max`).
  std::vector<ControllerEvent> next(std::size_t max = 4096);
  /// Entries dropped before this cursor read them (it fell behind by more than the capacity).
  std::uint64_t lost() const noexcept { return lost_; }
  std::uint64_t position() const noexcept { return after_; }

 private:
  const EventLog* log_;
  std::uint64_t after_ = 0;
  std::uint64_t lost_ = 0;
};

}  // namespace opencnc::controller
