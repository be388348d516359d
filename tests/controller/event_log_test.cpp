// SPDX-License-Identifier: GPL-3.0-or-later
// The event log's fixed-size entries: every field read back as written, long strings cut with a mark
// at a character boundary, the call chain kept, the ring overwritten in order once full.
#include <gtest/gtest.h>

#include <string>

#include "opencnc/controller/events.hpp"

namespace opencnc::controller::test {
namespace {

ControllerEvent full_event() {
  ControllerEvent e;
  e.tick = 123456789;
  e.kind = ControllerEventKind::JobEnded;
  e.severity = Severity::Error;
  e.code = "control.edm.short";
  e.text = "part.ngc:12:1: the short did not clear";
  e.servo.kind = control::EventKind::Fault;
  e.servo.fault.kind = control::FaultKind::Stall;
  e.servo.value = 2.5;
  e.request_id = 77;
  e.accepted = true;
  e.job = JobKind::Auxiliary;
  e.job_id = 9;
  e.end = JobEnd::Fault;
  e.sync = SyncKind::Probe;
  e.segment = 4242;
  e.location.file = "part.ngc";
  e.location.line = 12;
  e.location.calls = {"o<rough> called at part.ngc:3", "o<pass> called at rough.ngc:8"};
  return e;
}

TEST(EventLogEntries, KeepEveryField) {
  EventLog log(2);
  log.append(full_event());
  const auto got = EventCursor(log, true).next();
  ASSERT_EQ(got.size(), 1u);
  const ControllerEvent& e = got[0];
  const ControllerEvent want = full_event();
  EXPECT_EQ(e.seq, 1u);
  EXPECT_EQ(e.tick, want.tick);
  EXPECT_EQ(e.kind, want.kind);
  EXPECT_EQ(e.severity, want.severity);
  EXPECT_EQ(e.code, want.code);
  EXPECT_EQ(e.text, want.text);
  EXPECT_EQ(e.servo.kind, want.servo.kind);
  EXPECT_EQ(e.servo.fault.kind, want.servo.fault.kind);
  EXPECT_EQ(e.servo.value, want.servo.value);
  EXPECT_EQ(e.request_id, want.request_id);
  EXPECT_TRUE(e.accepted);
  EXPECT_EQ(e.job, want.job);
  EXPECT_EQ(e.job_id, want.job_id);
  EXPECT_EQ(e.end, want.end);
  EXPECT_EQ(e.sync, want.sync);
  EXPECT_EQ(e.segment, want.segment);
  EXPECT_EQ(e.location.file, want.location.file);
  EXPECT_EQ(e.location.line, want.location.line);
  EXPECT_EQ(e.location.calls, want.location.calls);
}

TEST(EventLogEntries, CutLongStringsWithAMarkAtACharacterBoundary) {
  EventLog log(1);
  ControllerEvent e;
  e.text = std::string(kEventTextBytes - 1, 'a');  // fits exactly
  e.code = std::string(kEventCodeBytes, 'c');      // one byte too many
  e.location.file = std::string(kEventFileBytes * 2, 'f');
  log.append(e);
  auto got = EventCursor(log, true).next().at(0);
  EXPECT_EQ(got.text, e.text);
  EXPECT_EQ(got.code.size(), kEventCodeBytes - 1);
  EXPECT_TRUE(got.code.ends_with("\xE2\x80\xA6")) << got.code;
  EXPECT_EQ(got.code.substr(0, kEventCodeBytes - 4), std::string(kEventCodeBytes - 4, 'c'));
  EXPECT_TRUE(got.location.file.ends_with("\xE2\x80\xA6"));
  EXPECT_LT(got.location.file.size(), kEventFileBytes);

  std::string umlauts;  // two-byte characters across the cut: none may be split
  while (umlauts.size() < kEventTextBytes + 8) umlauts += "\xC3\xBC";
  for (const std::string& lead : {std::string(), std::string("x")}) {
    e.text = lead + umlauts;
    log.append(e);
    got = EventCursor(log, true).next().at(0);
    ASSERT_TRUE(got.text.ends_with("\xE2\x80\xA6"));
    const std::string kept = got.text.substr(lead.size(), got.text.size() - lead.size() - 3);
    EXPECT_EQ(kept.size() % 2, 0u) << "a character was split";
    EXPECT_EQ(kept, umlauts.substr(0, kept.size()));
    EXPECT_LT(got.text.size(), kEventTextBytes);
  }
}

TEST(EventLogEntries, ALongCallChainIsCutInItsLastKeptCall) {
  EventLog log(1);
  ControllerEvent e;
  for (int i = 0; i < 20; ++i)
    e.location.calls.push_back("o<sub" + std::to_string(i) + "> called at deep.ngc:1");
  log.append(e);
  const auto got = EventCursor(log, true).next().at(0);
  ASSERT_FALSE(got.location.calls.empty());
  ASSERT_LT(got.location.calls.size(), e.location.calls.size());
  for (std::size_t i = 0; i + 1 < got.location.calls.size(); ++i)
    EXPECT_EQ(got.location.calls[i], e.location.calls[i]);
  EXPECT_TRUE(got.location.calls.back().ends_with("\xE2\x80\xA6"));
}

TEST(EventLogEntries, TheRingOverwritesTheOldestInOrder) {
  EventLog log(3);
  for (int i = 1; i <= 10; ++i) {
    ControllerEvent e;
    e.text = "event " + std::to_string(i);
    log.append(e);
  }
  EventCursor c(log, true);
  const auto got = c.next();
  ASSERT_EQ(got.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(got[i].seq, 8 + i);
    EXPECT_EQ(got[i].text, "event " + std::to_string(8 + i));
  }
  EXPECT_EQ(log.last(), 10u);
}

}  // namespace
}  // namespace opencnc::controller::test
