// SPDX-License-Identifier: GPL-3.0-or-later
// Faults on the simulated machine: e-stop mid-move, amplifier fault, following error, limit
// switch, soft limit at tick time, mains loss (a controlled stop on the path), with the axis and
// the value named.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "opencnc/canon/program_builder.hpp"
#include "servo_harness.hpp"
#include "test_profiles.hpp"

namespace opencnc::control::test {
namespace {

Pose xyz(double x, double y = 0, double z = 0) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

/// A diagonal XY move at `feed`, M2.
canon::Program diagonal(double to, double feed) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_feed_rate(feed);
  b.straight_feed(0, xyz(to, to));
  b.program_end();
  return b.take();
}

void start(ServoHarness& h, const canon::Program& p) {
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  ASSERT_EQ(h.send_mode(Mode::Auto), Refusal::None);
  ASSERT_EQ(h.run(p, Mode::Auto), Refusal::None);
}

TEST(Faults, EstopMidMoveStopsAndRefusesMotionUntilReset) {
  ServoHarness h(mill());
  start(h, diagonal(100, 6000));
  h.tick(300);
  ASSERT_GT(h.status().path_velocity, 50);
  h.sim().set_estop_pressed(true);
  h.tick(2);  // the machine samples the chain at the end of a period, the servo reads it next
  EXPECT_EQ(h.state(), State::EStopped);
  EXPECT_FALSE(h.status().drives_enabled);
  EXPECT_FALSE(h.sim().drives_powered());
  EXPECT_EQ(h.last(EventKind::RunEnded)->run_end, RunEnd::EStopped);
  h.tick(500);  // the axes coast to rest; the command follows them
  const ServoStatus& s = h.status();
  EXPECT_EQ(s.commanded[Axis::X], s.joints[0].actual);
  EXPECT_EQ(h.channels().blocks.available(), 0u);
  EXPECT_EQ(h.send(CommandKind::MachineOn), Refusal::EStopActive);
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::EStopInput);  // button still pressed
  h.sim().set_estop_pressed(false);
  h.tick();
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::None);
  EXPECT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  EXPECT_EQ(h.state(), State::Idle);
  EXPECT_EQ(h.run(diagonal(0, 6000), Mode::Auto), Refusal::None);  // from where it stands
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 5000));
  EXPECT_NEAR(h.status().commanded[Axis::X], 0.0, 1e-12);
}

TEST(Faults, AmplifierFaultNamesTheAxis) {
  ServoHarness h(mill());
  start(h, diagonal(100, 6000));
  h.tick(200);
  h.sim().set_amp_fault(1, true);
  h.tick(2);
  EXPECT_EQ(h.state(), State::Faulted);
  const Fault f = h.status().fault;
  EXPECT_EQ(f.kind, FaultKind::AmpFault);
  EXPECT_EQ(f.axis, index(Axis::Y));
  EXPECT_FALSE(h.status().drives_enabled);
  EXPECT_EQ(h.last(EventKind::RunEnded)->run_end, RunEnd::Faulted);
  ASSERT_TRUE(h.last(EventKind::Fault));
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::FaultPersists);
  h.sim().set_amp_fault(1, false);
  h.tick();
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::None);
  EXPECT_EQ(h.state(), State::Off);
}

TEST(Faults, FollowingErrorBeyondTheProfileLimit) {
  // 3 µm allowed: the drives lag more than that while accelerating at 1000 mm/s².
  ServoHarness h(mill({"axis.x.max_following_error=0.003"}));
  start(h, diagonal(100, 6000));
  ASSERT_TRUE(h.until([&] { return h.state() == State::Faulted; }, 2000));
  const Fault f = h.status().fault;
  EXPECT_EQ(f.kind, FaultKind::FollowingError);
  EXPECT_EQ(f.axis, index(Axis::X));
  EXPECT_GT(std::fabs(f.value), 0.003);
  EXPECT_EQ(f.limit, 0.003);
}

TEST(Faults, LoadPushingAnAxisAwayIsAFollowingError) {
  ServoHarness h(mill());
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  h.tick(10);
  h.sim().set_external_effort(2, 6000);  // more than the Z drive's 4 kN peak
  ASSERT_TRUE(h.until([&] { return h.state() == State::Faulted; }, 2000));
  EXPECT_EQ(h.status().fault.kind, FaultKind::FollowingError);
  EXPECT_EQ(h.status().fault.axis, index(Axis::Z));
  EXPECT_GT(std::fabs(h.status().fault.value), 0.5);
}

TEST(Faults, SoftLimitAtTickTimeStopsTheMachine) {
  // The harness does not preflight (the controller does): the tick's own check must catch it.
  ServoHarness h(mill({"axis.x.max_limit=50.0"}));
  start(h, diagonal(60, 3000));
  ASSERT_TRUE(h.until([&] { return h.state() == State::Faulted; }, 5000));
  const Fault f = h.status().fault;
  EXPECT_EQ(f.kind, FaultKind::SoftLimit);
  EXPECT_EQ(f.axis, index(Axis::X));
  EXPECT_GT(f.value, 50.0);
  EXPECT_LT(f.value, 50.0 + 50 / std::sqrt(2.0) * 1e-3);  // caught in the period that crossed
  EXPECT_EQ(f.limit, 50.0);
  EXPECT_FALSE(h.status().drives_enabled);
}

// Mains lost with a UPS: the motion decelerates on the path within the axis limits (a
// controlled stop, drives on), then the machine is Faulted until mains come back.
TEST(Faults, MainsLossIsAControlledStopOnThePath) {
  ServoHarness h(mill({"power.ups=true"}));
  start(h, diagonal(100, 6000));
  h.tick(500);
  h.sim().set_mains_ok(false);
  std::vector<double> x;
  for (int i = 0; i < 2000 && h.state() != State::Faulted; ++i) {
    h.tick();
    if (h.state() != State::Faulted) {
      EXPECT_TRUE(h.status().drives_enabled);
      x.push_back(h.status().commanded[Axis::X]);
      EXPECT_EQ(h.status().commanded[Axis::X], h.status().commanded[Axis::Y]);  // on the path
    }
  }
  ASSERT_EQ(h.state(), State::Faulted);
  EXPECT_EQ(h.status().fault.kind, FaultKind::PowerLoss);
  EXPECT_EQ(h.last(EventKind::RunEnded)->run_end, RunEnd::Faulted);
  EXPECT_LT(x.back(), 100.0);
  ASSERT_GT(x.size(), 10u);
  for (std::size_t i = 2; i < x.size(); ++i) {  // per-axis acceleration within 1000 mm/s²
    EXPECT_LE(std::fabs(x[i] - 2 * x[i - 1] + x[i - 2]) / 1e-6, 1000 * (1 + 1e-6)) << i;
  }
  EXPECT_LE(std::fabs(x[x.size() - 1] - x[x.size() - 2]), 1e-3);  // at rest before the drives went off
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::FaultPersists);
  h.sim().set_mains_ok(true);
  h.tick();
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::None);
}

TEST(Faults, MainsLossDuringAJogDeceleratesBeforeTheDrivesGoOff) {
  ServoHarness h(mill({"power.ups=true"}));
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  ASSERT_EQ(h.send_mode(Mode::Manual), Refusal::None);
  ASSERT_EQ(h.jog(Axis::X, 80), Refusal::None);
  h.tick(300);
  h.sim().set_mains_ok(false);
  std::vector<double> x;
  for (int i = 0; i < 2000 && h.state() != State::Faulted; ++i) {
    h.tick();
    if (h.state() != State::Faulted) {
      EXPECT_TRUE(h.status().drives_enabled);
      x.push_back(h.status().commanded[Axis::X]);
    }
  }
  ASSERT_EQ(h.state(), State::Faulted);
  EXPECT_EQ(h.status().fault.kind, FaultKind::PowerLoss);
  ASSERT_GT(x.size(), 50u);  // 80 mm/s at 1000 mm/s² take 80 periods to stop
  for (std::size_t i = 2; i < x.size(); ++i) {
    EXPECT_LE(std::fabs(x[i] - 2 * x[i - 1] + x[i - 2]) / 1e-6, 1000 * (1 + 1e-6)) << i;
  }
}

}  // namespace
}  // namespace opencnc::control::test
