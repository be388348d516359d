// SPDX-License-Identifier: GPL-3.0-or-later
// The tick's two queues: the urgent lane and the controller's queue taken in the order of sending,
// the urgent one whole even past the per-period cap, and a stop dropping what was sent before it
// that would start something (control.superseded).
#include <gtest/gtest.h>

#include "opencnc/canon/program_builder.hpp"
#include "servo_harness.hpp"
#include "test_profiles.hpp"

namespace opencnc::control::test {
namespace {

Command command(CommandKind k, std::uint64_t id, std::uint64_t seq) {
  Command c;
  c.kind = k;
  c.id = id;
  c.seq = seq;
  return c;
}

/// The servo's answer to command `id` among the events so far (None = accepted).
std::optional<Refusal> answer(const ServoHarness& h, std::uint64_t id) {
  for (const ServoEvent& e : h.events()) {
    if ((e.kind == EventKind::Accepted || e.kind == EventKind::Refused) && e.command_id == id)
      return e.refusal;
  }
  return std::nullopt;
}

/// The order in which the servo answered the commands with these ids.
std::vector<std::uint64_t> answer_order(const ServoHarness& h) {
  std::vector<std::uint64_t> ids;
  for (const ServoEvent& e : h.events()) {
    if ((e.kind == EventKind::Accepted || e.kind == EventKind::Refused) && e.command_id >= 100)
      ids.push_back(e.command_id);
  }
  return ids;
}

canon::Program long_line() {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_feed_rate(600);
  Pose end;
  end[Axis::X] = 200;
  b.straight_feed(0, end);
  b.program_end();
  return b.take();
}

TEST(ServoUrgentLane, BothQueuesAreTakenInTheOrderOfSending) {
  ServoHarness h(mill());
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  ServoChannels& ch = h.channels();
  // Sent 1, 2, 3, 4 — two on each lane, interleaved.
  ASSERT_TRUE(ch.commands.try_push(command(CommandKind::SetSingleBlock, 101, 1)));
  ASSERT_TRUE(ch.urgent.try_push(command(CommandKind::FeedHold, 102, 2)));
  ASSERT_TRUE(ch.commands.try_push(command(CommandKind::SetOptionalStop, 103, 3)));
  ASSERT_TRUE(ch.urgent.try_push(command(CommandKind::JogStop, 104, 4)));
  h.tick();
  EXPECT_EQ(answer_order(h), (std::vector<std::uint64_t>{101, 102, 103, 104}));
}

TEST(ServoUrgentLane, TheUrgentQueueIsTakenWholePastThePerPeriodCap) {
  ServoHarness h(mill());
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  ServoChannels& ch = h.channels();
  // A controller queue far longer than one period takes (16), all sent before the e-stop.
  for (std::uint64_t k = 0; k < 40; ++k) {
    Command c = command(CommandKind::SetFeedOverride, 200 + k, 1 + k);
    c.value = 1;
    ASSERT_TRUE(ch.commands.try_push(c));
  }
  ASSERT_TRUE(ch.urgent.try_push(command(CommandKind::EStop, 100, 41)));
  h.tick();
  EXPECT_EQ(h.servo().state(), State::EStopped) << "the e-stop waited behind the queue";
  EXPECT_EQ(answer(h, 100), Refusal::None);
  EXPECT_LT(ch.commands.available(), 40u);
  EXPECT_GT(ch.commands.available(), 0u) << "the controller's queue keeps its per-period cap";
}

TEST(ServoUrgentLane, AStopDropsTheStartsSentBeforeItButNotTheOnesAfter) {
  ServoHarness h(mill());
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  ASSERT_EQ(h.send_mode(Mode::Auto), Refusal::None);
  ASSERT_EQ(h.run(long_line(), Mode::Auto), Refusal::None);
  h.tick(200);
  ServoChannels& ch = h.channels();
  // A feed hold overtakes a resume sent before it (the resume still in the controller's hands).
  ASSERT_TRUE(ch.urgent.try_push(command(CommandKind::FeedHold, 100, 10)));
  h.tick();
  ASSERT_EQ(h.servo().state(), State::Held);
  ASSERT_TRUE(ch.commands.try_push(command(CommandKind::Resume, 101, 9)));
  h.tick();
  EXPECT_EQ(answer(h, 101), Refusal::Superseded);
  EXPECT_EQ(h.servo().state(), State::Held);
  // A resume sent after the hold resumes.
  ASSERT_TRUE(ch.commands.try_push(command(CommandKind::Resume, 102, 11)));
  h.tick();
  EXPECT_EQ(answer(h, 102), Refusal::None);
  EXPECT_EQ(h.servo().state(), State::Running);
  // An e-stop overtakes a reset and a machine-on sent before it: the machine stays e-stopped.
  ASSERT_TRUE(ch.urgent.try_push(command(CommandKind::EStop, 103, 14)));
  h.tick();
  ASSERT_TRUE(ch.commands.try_push(command(CommandKind::Reset, 104, 12)));
  ASSERT_TRUE(ch.commands.try_push(command(CommandKind::MachineOn, 105, 13)));
  h.tick();
  EXPECT_EQ(answer(h, 104), Refusal::Superseded);
  EXPECT_EQ(answer(h, 105), Refusal::Superseded);
  EXPECT_EQ(h.servo().state(), State::EStopped);
  // Settings sent before it are applied (a stop drops only what would start something).
  Command single = command(CommandKind::SetSingleBlock, 106, 12);
  single.flag = true;
  ASSERT_TRUE(ch.commands.try_push(single));
  h.tick();
  EXPECT_EQ(answer(h, 106), Refusal::None);
}

}  // namespace
}  // namespace opencnc::control::test
