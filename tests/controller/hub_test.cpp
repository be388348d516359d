// SPDX-License-Identifier: GPL-3.0-or-later
// The controller as a hub: observers with cursors of their own on the numbered event log, status
// at a set rate, features that answer requests of their own and run auxiliary programs beside the
// main one, typed requests.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/events.hpp"
#include "opencnc/controller/sim_rig.hpp"

namespace opencnc::controller::test {
namespace {

/// Keeps what it is told.
class Recorder final : public ControllerObserver {
 public:
  void on_event(const ControllerEvent& e) override { events.push_back(e); }
  void on_status(const ControllerStatus& s) override { status_ticks.push_back(s.servo.tick); }
  void on_trace(const control::TraceSample& s, const TraceContext& c) override {
    ++samples;
    if (s.activity == control::Activity::Program && c.program != nullptr) ++with_program;
  }
  std::vector<ControllerEvent> events;
  std::vector<std::uint64_t> status_ticks;
  std::uint64_t samples = 0, with_program = 0;

  std::size_t count(ControllerEventKind k) const {
    std::size_t n = 0;
    for (const auto& e : events) n += e.kind == k ? 1 : 0;
    return n;
  }
};

/// A line along X from where the machine is.
std::shared_ptr<const canon::Program> line_x(const Pose& from, double to, double feed = 1200) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"), from);
  b.set_feed_rate(feed);
  Pose end = from;
  end[Axis::X] = to;
  b.straight_feed(0, end);
  b.program_end();
  return std::make_shared<const canon::Program>(b.take());
}

bool run_until_idle(SimRig& rig, std::uint64_t max_ticks = 100000) {
  return rig.run_until(
      [&] { return !rig.status().run_active && rig.status().servo.state == control::State::Idle; },
      max_ticks);
}

TEST(EventLog, NumbersEntriesAndCursorsCountWhatTheyMissed) {
  EventLog log(4);
  EventCursor early(log);
  for (int i = 0; i < 3; ++i) {
    ControllerEvent e;
    e.text = std::to_string(i);
    EXPECT_EQ(log.append(e), static_cast<std::uint64_t>(i + 1));
  }
  EventCursor late(log);  // from now on
  auto got = early.next();
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].seq, 1u);
  EXPECT_EQ(got[2].text, "2");
  EXPECT_TRUE(late.next().empty());
  for (int i = 3; i < 10; ++i) log.append(ControllerEvent{});
  got = early.next();  // only the newest four are kept: three were dropped before it read them
  EXPECT_EQ(got.size(), 4u);
  EXPECT_EQ(got.front().seq, 7u);
  EXPECT_EQ(early.lost(), 3u);
  EventCursor all(log, true);
  EXPECT_EQ(all.next(2).size(), 2u);  // at most what was asked
  EXPECT_EQ(all.next().size(), 2u);
}

// The answers are kept in slots built with the controller: the last 4096 requests' answers can be
// read, older ones are gone, and answering more never grows the controller.
TEST(Hub, KeepsTheAnswersOfTheLatestRequestsInFixedSlots) {
  SimRig rig(control::test::mill());
  Controller& c = rig.controller();
  const std::uint64_t first = c.submit(Request::set_mode(control::Mode::Auto));
  std::uint64_t last = first;
  for (int i = 0; i < 4200; ++i) last = c.submit(Request::set_mode(control::Mode::Manual));
  ASSERT_TRUE(rig.run_until([&] { return c.outcome(last).has_value() && c.outcome(last - 4095).has_value(); },
                            20000));
  EXPECT_FALSE(c.outcome(first).has_value());  // 4200 later answers took its place
  const std::optional<Outcome> o = c.outcome(last);
  ASSERT_TRUE(o.has_value());
  EXPECT_EQ(o->accepted, o->refusal == control::Refusal::None);
  EXPECT_FALSE(c.outcome(last + 1).has_value());  // not asked yet
}

TEST(Hub, ObserversEachSeeEveryEventFromWhenTheyAttached) {
  SimRig rig(control::test::mill());
  auto first = std::make_shared<Recorder>();
  auto second = std::make_shared<Recorder>();
  rig.controller().attach(first, ObserverOptions{0.01, true});
  rig.step();
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  rig.controller().attach(second);
  rig.step();
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(rig.request(Request::open(line_x(rig.status().servo.commanded, 10), "line")).accepted);
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  ASSERT_TRUE(run_until_idle(rig));
  rig.run(20);
  // Both saw the job start and end; neither took them from the other.
  EXPECT_EQ(first->count(ControllerEventKind::JobStarted), 1u);
  EXPECT_EQ(second->count(ControllerEventKind::JobStarted), 1u);
  EXPECT_EQ(first->count(ControllerEventKind::JobEnded), 1u);
  EXPECT_EQ(second->count(ControllerEventKind::JobEnded), 1u);
  // The first one attached before machine-on: it saw that answer, the second did not.
  EXPECT_GT(first->count(ControllerEventKind::Answer), second->count(ControllerEventKind::Answer));
  for (std::size_t i = 1; i < first->events.size(); ++i) EXPECT_EQ(first->events[i].seq, first->events[i - 1].seq + 1);
  // Status every 10 ms of servo time; traces for the one that asked, with the program's window.
  ASSERT_GE(first->status_ticks.size(), 2u);
  EXPECT_EQ(first->status_ticks[1] - first->status_ticks[0], 10u);
  EXPECT_TRUE(second->status_ticks.empty());
  EXPECT_GT(first->with_program, 400u);  // 10 mm at 20 mm/s
  EXPECT_EQ(second->samples, 0u);
}

TEST(Hub, AnObserverThatThrowsIsDetachedWithANote) {
  struct Bad final : ControllerObserver {
    void on_event(const ControllerEvent&) override { throw std::runtime_error("disk full"); }
  };
  SimRig rig(control::test::mill());
  auto log = std::make_shared<Recorder>();
  const std::uint64_t bad = rig.controller().attach(std::make_shared<Bad>());
  rig.controller().attach(log);
  rig.step();
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  rig.run(3);
  bool noted = false;
  for (const auto& e : log->events) noted = noted || (e.code == "control.observer" && e.text.find("disk full") != std::string::npos);
  EXPECT_TRUE(noted);
  rig.controller().detach(bad);  // detaching one that is gone is harmless
  rig.run(3);
}

/// A feature of the kind the tool guard or path retrace are: it answers requests of its own and
/// runs a program of its own beside the operator's.
class CheckRoutine final : public Feature {
 public:
  std::string_view name() const override { return "check"; }
  void attached(FeatureHost& host) override { attached_to = &host.profile(); }
  Outcome handle(const requests::Feature& r, FeatureHost& host) override {
    Outcome o;
    if (r.action != "probe-x") {
      o.refusal = control::Refusal::BadValue;
      o.message = "unknown action " + r.action;
      return o;
    }
    const double to = std::any_cast<double>(r.args);
    host.submit(Request::run_auxiliary("check X", line_x(host.current_status().servo.commanded, to)));
    o.accepted = true;
    return o;
  }
  void on_event(const ControllerEvent& e) override {
    if (e.kind == ControllerEventKind::JobEnded && e.job == JobKind::Auxiliary) ++auxiliary_ends;
  }
  const config::MachineProfile* attached_to = nullptr;
  int auxiliary_ends = 0;
};

TEST(Hub, AFeatureRunsAProgramOfItsOwnAndTheOpenProgramStays) {
  SimRig rig(control::test::mill());
  auto check = std::make_shared<CheckRoutine>();
  ASSERT_TRUE(rig.controller().add_feature(check));
  EXPECT_FALSE(rig.controller().add_feature(std::make_shared<CheckRoutine>()));  // the name is taken
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  EXPECT_NE(check->attached_to, nullptr);
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(rig.request(Request::open(line_x(rig.status().servo.commanded, 30), "main")).accepted);
  // The feature's request: its own program runs, the open one stays open.
  ASSERT_TRUE(rig.request(Request::feature("check", "probe-x", 12.0)).accepted);
  ASSERT_TRUE(rig.run_until([&] { return rig.status().job == JobKind::Auxiliary; }, 100));
  EXPECT_EQ(rig.status().job_name, "check X");
  EXPECT_EQ(rig.status().program_name, "main");
  ASSERT_TRUE(run_until_idle(rig));
  EXPECT_EQ(check->auxiliary_ends, 1);
  EXPECT_NEAR(rig.status().servo.commanded[Axis::X], 12.0, 1e-9);
  EXPECT_EQ(rig.status().program_name, "main");
  // Cycle start runs the main program (from where the machine stands now).
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  ASSERT_TRUE(run_until_idle(rig));
  EXPECT_NEAR(rig.status().servo.commanded[Axis::X], 30.0, 1e-9);
  // Unknown features and actions are refused with words.
  const Outcome none = rig.request(Request::feature("nothing", "x"));
  EXPECT_FALSE(none.accepted);
  EXPECT_NE(none.message.find("nothing"), std::string::npos);
  const Outcome bad = rig.request(Request::feature("check", "fly"));
  EXPECT_EQ(bad.refusal, control::Refusal::BadValue);
  EXPECT_NE(bad.message.find("fly"), std::string::npos);
}

TEST(Hub, AuxiliaryProgramsNeedAutoModeAndAnIdleMachine) {
  SimRig rig(control::test::mill());
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  const auto p = line_x(rig.status().servo.commanded, 5);
  EXPECT_EQ(rig.request(Request::run_auxiliary("x", p)).refusal, control::Refusal::WrongMode);  // Manual
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(rig.request(Request::run_auxiliary("x", p)).accepted);
  EXPECT_EQ(rig.request(Request::run_auxiliary("y", p)).refusal, control::Refusal::Busy);
  ASSERT_TRUE(run_until_idle(rig));
}

TEST(Requests, CarryTypedFieldsToTheServo) {
  const auto mist = to_command(Request::coolant(control::Coolant::Mist, true));
  ASSERT_TRUE(mist.has_value());
  EXPECT_EQ(mist->kind, control::CommandKind::Coolant);
  EXPECT_EQ(mist->coolant, control::Coolant::Mist);
  EXPECT_TRUE(mist->flag);
  const auto jog = to_command(Request::jog_by(Axis::Z, -1.5, 4));
  EXPECT_EQ(jog->axis, index(Axis::Z));
  EXPECT_EQ(jog->value, -1.5);
  EXPECT_EQ(jog->value2, 4);
  EXPECT_EQ(to_command(Request::home())->axis, -1);
  EXPECT_EQ(to_command(Request::rapid_override(0.5))->kind, control::CommandKind::SetRapidOverride);
  EXPECT_FALSE(to_command(Request::open("part.ngc")).has_value());   // the controller's own
  EXPECT_FALSE(to_command(Request::block_delete(true)).has_value());
  EXPECT_EQ(Request::mdi("G0 X1").name(), "mdi");
  EXPECT_EQ(Request::feature("journal", "save").name(), "journal.save");
}

TEST(Requests, TheControllersOwnStartRunIsRefused) {
  SimRig rig(control::test::mill());
  const Outcome o = rig.request(Request::simple(control::CommandKind::StartRun));
  EXPECT_EQ(o.refusal, control::Refusal::BadValue);
}

}  // namespace
}  // namespace opencnc::controller::test
