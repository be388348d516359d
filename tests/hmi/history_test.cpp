// SPDX-License-Identifier: GPL-3.0-or-later
// The machining history: the recorder turns the event log into job rows (program, outcome,
// machining time, alarms); audit rows; both read back newest first.
#include <gtest/gtest.h>
#include <unistd.h>

#include "opencnc/hmi/history.hpp"

namespace opencnc::hmi {
namespace {

std::filesystem::path fresh_db(const char* name) {
  const auto d = std::filesystem::temp_directory_path() /
                 (std::string("opencnc-history-") + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d / "history.sqlite";
}

controller::ControllerEvent event(controller::ControllerEventKind kind, std::uint64_t tick) {
  controller::ControllerEvent e;
  e.kind = kind;
  e.tick = tick;
  e.job = controller::JobKind::Program;
  e.job_id = 7;
  return e;
}

TEST(History, TheRecorderWritesEachJobWithItsAlarms) {
  std::string error;
  auto h = History::open(fresh_db("jobs"), &error);
  ASSERT_TRUE(h) << error;
  HistoryRecorder r(*h, 0.001);
  auto started = event(controller::ControllerEventKind::JobStarted, 1000);
  started.text = "bracket.ngc";
  r.on_event(started);
  auto alarm = event(controller::ControllerEventKind::Note, 1500);
  alarm.severity = Severity::Warning;
  alarm.code = "control.interlock";
  alarm.text = "interlock held the feed";
  r.on_event(alarm);
  auto mdi = event(controller::ControllerEventKind::JobStarted, 1600);
  mdi.job = controller::JobKind::Mdi;  // not a job of the history, and it does not end the program's
  r.on_event(mdi);
  auto ended = event(controller::ControllerEventKind::JobEnded, 3500);
  ended.end = controller::JobEnd::Aborted;
  ended.location.line = 42;
  r.on_event(ended);
  h->flush();
  const auto jobs = h->jobs(10);
  ASSERT_EQ(jobs.size(), 1u);
  EXPECT_EQ(jobs[0].program, "bracket.ngc");
  EXPECT_EQ(jobs[0].outcome, "aborted");
  EXPECT_DOUBLE_EQ(jobs[0].machining_s, 2.5);
  EXPECT_EQ(jobs[0].end_line, 42u);
  ASSERT_EQ(jobs[0].alarms.size(), 1u);
  EXPECT_EQ(jobs[0].alarms[0], "interlock held the feed [control.interlock]");
  EXPECT_FALSE(jobs[0].started_utc.empty());
  EXPECT_EQ(h->failures(), 0u);
}

TEST(History, AuditRowsComeBackNewestFirstAndSurviveAReopen) {
  std::string error;
  const auto path = fresh_db("audit");
  {
    auto h = History::open(path, &error);
    ASSERT_TRUE(h) << error;
    h->add(AuditRecord{0, "2026-11-26T03:00:00Z", "operator", "127.0.0.1:5000", "POST /api/v1/commands",
                       R"({"kind":"cycle-start"})", 200, "accepted"});
    h->add(AuditRecord{0, "2026-11-26T03:00:01Z", "", "127.0.0.1:5001", "POST /api/v1/commands", "{}", 401,
                       "no valid token"});
  }
  auto h = History::open(path, &error);
  ASSERT_TRUE(h) << error;
  const auto rows = h->audit(10);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].status, 401);
  EXPECT_EQ(rows[1].role, "operator");
  EXPECT_EQ(rows[1].body, R"({"kind":"cycle-start"})");
}

TEST(History, AFolderThatIsNotThereIsAnError) {
  std::string error;
  EXPECT_FALSE(History::open("/nonexistent-folder/h.sqlite", &error));
  EXPECT_NE(error.find("/nonexistent-folder/h.sqlite"), std::string::npos);
}

}  // namespace
}  // namespace opencnc::hmi
