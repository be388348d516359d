// SPDX-License-Identifier: GPL-3.0-or-later
// The event log: a numbered ring of fixed-size entries under a mutex, read by cursors; names of
// kinds and ends.
#include "opencnc/controller/events.hpp"

#include <algorithm>
#include <cstring>
#include <string_view>

namespace opencnc::controller {

/// One entry as the ring keeps it: plain bytes, so appending copies and never allocates.
struct StoredEvent {
  std::uint64_t seq = 0;
  std::uint64_t tick = 0;
  std::uint64_t request_id = 0;
  std::uint64_t segment = 0;
  control::ServoEvent servo{};
  std::uint32_t job_id = 0;
  std::uint32_t line = 0;
  ControllerEventKind kind = ControllerEventKind::Note;
  Severity severity = Severity::Note;
  JobKind job = JobKind::None;
  JobEnd end = JobEnd::Finished;
  SyncKind sync = SyncKind::None;
  bool accepted = false;
  char code[kEventCodeBytes];
  char text[kEventTextBytes];
  char file[kEventFileBytes];
  char call_chain[kEventCallsBytes];
};

static_assert(std::is_trivially_copyable_v<StoredEvent>);

namespace {

constexpr std::string_view kCut = "\xE2\x80\xA6";  // "…": the string was longer than its field

/// Writes strings one after another into a field of `n` bytes, zero-terminated; what does not fit
/// is cut at a character boundary and the field ends in "…".
class FieldWriter {
 public:
  FieldWriter(char* out, std::size_t n) noexcept : out_(out), n_(n) { out_[0] = '\0'; }
  void add(std::string_view s) noexcept {
    if (cut_) return;
    const std::size_t take = std::min(s.size(), n_ - 1 - used_);
    std::memcpy(out_ + used_, s.data(), take);
    used_ += take;
    if (take < s.size()) {  // too long: make room for the mark, not in the middle of a character
      std::size_t end = n_ - 1 - kCut.size();
      while (end > 0 && (static_cast<unsigned char>(out_[end]) & 0xC0U) == 0x80U) --end;
      std::memcpy(out_ + end, kCut.data(), kCut.size());
      used_ = end + kCut.size();
      cut_ = true;
    }
    out_[used_] = '\0';
  }

 private:
  char* out_;
  std::size_t n_;
  std::size_t used_ = 0;
  bool cut_ = false;
};

void put(char* out, std::size_t n, std::string_view s) noexcept {
  FieldWriter(out, n).add(s);
}

void store(StoredEvent& s, const ControllerEvent& e) noexcept {
  s.seq = e.seq;
  s.tick = e.tick;
  s.request_id = e.request_id;
  s.segment = e.segment;
  s.servo = e.servo;
  s.job_id = e.job_id;
  s.line = e.location.line;
  s.kind = e.kind;
  s.severity = e.severity;
  s.job = e.job;
  s.end = e.end;
  s.sync = e.sync;
  s.accepted = e.accepted;
  put(s.code, sizeof s.code, e.code);
  put(s.text, sizeof s.text, e.text);
  put(s.file, sizeof s.file, e.location.file);
  FieldWriter chain(s.call_chain, sizeof s.call_chain);
  for (std::size_t i = 0; i < e.location.calls.size(); ++i) {
    if (i > 0) chain.add("\n");
    chain.add(e.location.calls[i]);
  }
}

ControllerEvent load(const StoredEvent& s) {
  ControllerEvent e;
  e.seq = s.seq;
  e.tick = s.tick;
  e.request_id = s.request_id;
  e.segment = s.segment;
  e.servo = s.servo;
  e.job_id = s.job_id;
  e.location.line = s.line;
  e.kind = s.kind;
  e.severity = s.severity;
  e.job = s.job;
  e.end = s.end;
  e.sync = s.sync;
  e.accepted = s.accepted;
  e.code = s.code;
  e.text = s.text;
  e.location.file = s.file;
  for (std::string_view chain = s.call_chain; !chain.empty();) {  // the calls, '\n' between them
    const std::size_t nl = chain.find('\n');
    e.location.calls.emplace_back(chain.substr(0, nl));
    chain = nl == std::string_view::npos ? std::string_view{} : chain.substr(nl + 1);
  }
  return e;
}

}  // namespace

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

EventLog::EventLog(std::size_t capacity)
    : capacity_(capacity == 0 ? 1 : capacity), ring_(std::make_unique<StoredEvent[]>(capacity_)) {
  // make_unique value-initialises: every page of the ring is written now, so the resident memory
  // is the same after the first event as after the millionth.
}

EventLog::~EventLog() = default;

std::uint64_t EventLog::append(const ControllerEvent& e) {
  std::lock_guard lock(mutex_);
  const std::uint64_t seq = next_++;
  StoredEvent& s = ring_[(seq - 1) % capacity_];
  store(s, e);
  s.seq = seq;
  return seq;
}

std::uint64_t EventLog::last() const {
  std::lock_guard lock(mutex_);
  return next_ - 1;
}

std::vector<ControllerEvent> EventLog::read_after(std::uint64_t after, std::size_t max,
                                                  std::uint64_t* lost) const {
  std::lock_guard lock(mutex_);
  std::vector<ControllerEvent> out;
  if (lost != nullptr) *lost = 0;
  const std::uint64_t kept = std::min<std::uint64_t>(next_ - 1, capacity_);
  if (kept == 0) return out;
  const std::uint64_t first = next_ - kept;
  if (after + 1 < first) {
    if (lost != nullptr) *lost = first - (after + 1);
    after = first - 1;
  }
  for (std::uint64_t seq = after + 1; seq < next_ && out.size() < max; ++seq)
    out.push_back(load(ring_[(seq - 1) % capacity_]));
  return out;
}

EventCursor::EventCursor(const EventLog& log, bool from_start) : log_(&log) {
  after_ = from_start ? 0 : log.last();
}

std::vector<ControllerEvent> EventCursor::next(std::size_t max) {
  std::uint64_t lost = 0;
  std::vector<ControllerEvent> out = log_->read_after(after_, max, &lost);
  lost_ += lost;
  if (!out.empty())
    after_ = out.back().seq;
  else if (lost > 0)
    after_ += lost;
  return out;
}

}  // namespace opencnc::controller
