// SPDX-License-Identifier: GPL-3.0-or-later
// The event log: a numbered ring under a mutex, read by cursors; names of kinds and ends.
#include "opencnc/controller/events.hpp"

namespace opencnc::control {

const char* to_string(ControllerEventKind k) noexcept {
  switch (k) {
    case ControllerEventKind::Servo:
      return "servo";
    case ControllerEventKind::Note:
      return "note";
    case ControllerEventKind::Answer:
      return "answer";
    case ControllerEventKind::ProgramOpened:
      return "program-opened";
    case ControllerEventKind::JobStarted:
      return "job-started";
    case ControllerEventKind::JobEnded:
      return "job-ended";
    case ControllerEventKind::SyncWait:
      return "sync-wait";
    case ControllerEventKind::SyncDone:
      return "sync-done";
  }
  return "";
}

const char* to_string(JobKind k) noexcept {
  switch (k) {
    case JobKind::None:
      return "";
    case JobKind::Program:
      return "program";
    case JobKind::Mdi:
      return "mdi";
    case JobKind::Auxiliary:
      return "auxiliary";
  }
  return "";
}

const char* to_string(JobEnd e) noexcept {
  switch (e) {
    case JobEnd::Finished:
      return "finished";
    case JobEnd::Aborted:
      return "aborted";
    case JobEnd::Error:
      return "error";
    case JobEnd::Fault:
      return "fault";
  }
  return "";
}

EventLog::EventLog(std::size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

std::uint64_t EventLog::append(ControllerEvent e) {
  std::lock_guard lock(mutex_);
  e.seq = next_++;
  if (ring_.size() == capacity_) ring_.pop_front();
  ring_.push_back(std::move(e));
  return ring_.back().seq;
}

std::uint64_t EventLog::last() const {
  std::lock_guard lock(mutex_);
  return next_ - 1;
}

std::vector<ControllerEvent> EventLog::read_after(std::uint64_t after, std::size_t max, std::uint64_t* lost) const {
  std::lock_guard lock(mutex_);
  std::vector<ControllerEvent> out;
  if (lost != nullptr) *lost = 0;
  if (ring_.empty()) return out;
  const std::uint64_t first = ring_.front().seq;
  if (after + 1 < first) {
    if (lost != nullptr) *lost = first - (after + 1);
    after = first - 1;
  }
  for (std::size_t i = static_cast<std::size_t>(after + 1 - first); i < ring_.size() && out.size() < max; ++i)
    out.push_back(ring_[i]);
  return out;
}

EventCursor::EventCursor(const EventLog& log, bool from_start) : log_(&log) {
  after_ = from_start ? 0 : log.last();
}

std::vector<ControllerEvent> EventCursor::next(std::size_t max) {
  std::uint64_t lost = 0;
  std::vector<ControllerEvent> out = log_->read_after(after_, max, &lost);
  lost_ += lost;
  if (!out.empty()) after_ = out.back().seq;
  else if (lost > 0) after_ += lost;
  return out;
}

}  // namespace opencnc::control
