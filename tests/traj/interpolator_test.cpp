// SPDX-License-Identifier: GPL-3.0-or-later
// Interpolator on hand-made blocks: exact trapezoids, overrides, hold, markers, abort,
// starvation, single block, and the moving average of the jerk-limited mode.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "opencnc/traj/interpolator.hpp"

using namespace opencnc;
using namespace opencnc::traj;

namespace {

constexpr double kDt = 1e-3;

Pose at(double x, double y = 0) {
  Pose p;
  p[0] = x;
  p[1] = y;
  return p;
}

MotionBlock line(Pose a, Pose b, double cap, double accel, std::uint64_t segment) {
  MotionBlock m;
  m.kind = BlockKind::Line;
  m.base = a;
  double len = 0;
  for (int i = 0; i < kAxisCount; ++i) len += (b[i] - a[i]) * (b[i] - a[i]);
  len = std::sqrt(len);
  for (int i = 0; i < kAxisCount; ++i) m.lin[i] = (b[i] - a[i]) / len;
  m.length = len;
  m.v_cap = cap;
  m.feed = cap;
  m.accel = accel;
  m.feed_class = FeedClass::Feed;
  m.flags = kFeedOverrideAllowed | kFeedHoldAllowed;
  m.segment = m.segment_first = m.segment_last = segment;
  return m;
}

MotionBlock marker(MarkerKind kind, double value = 0, std::uint32_t action = 0) {
  MotionBlock m;
  m.kind = BlockKind::Marker;
  m.marker = kind;
  m.value = value;
  m.action = action;
  return m;
}

/// Fills in what the planner would: positions of markers, braking prefix, backward pass
/// (junctions between blocks limited to `junction`, stops at markers and at the start).
std::vector<MotionBlock> plan(std::vector<MotionBlock> blocks, double junction = 1e9) {
  double c = 0;
  Pose end{};
  for (MotionBlock& b : blocks) {
    if (b.kind == BlockKind::Marker) b.base = end;
    b.brake_prefix = c;
    c += 2 * b.accel * b.length;
    if (b.kind != BlockKind::Marker)
      end = [&] {
        Pose e = b.base;
        for (int i = 0; i < kAxisCount; ++i) e[i] += b.length * b.lin[i];
        return e;
      }();
  }
  double after = 0;
  bool prev_stop = true;
  std::vector<double> local(blocks.size());
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const MotionBlock& b = blocks[k];
    const bool stop = b.kind == BlockKind::Marker && b.marker != MarkerKind::Report;
    local[k] =
        b.kind == BlockKind::Marker ? (stop ? 0.0 : 1e300) : (prev_stop ? 0.0 : std::min(junction, b.v_cap));
    if (b.kind != BlockKind::Marker) prev_stop = false;
    if (stop) prev_stop = true;
  }
  for (std::size_t k = blocks.size(); k-- > 0;) {
    blocks[k].v_entry = std::min(local[k], std::sqrt(after * after + 2 * blocks[k].accel * blocks[k].length));
    after = blocks[k].v_entry;
  }
  for (std::size_t k = 0; k < blocks.size(); ++k) blocks[k].seq = k;
  return blocks;
}

struct Rig {
  std::unique_ptr<BlockQueue> queue = std::make_unique<BlockQueue>();
  InterpolatorConfig config;
  std::unique_ptr<Interpolator> interp;
  std::vector<TickOutput> trace;
  TickInput in;

  explicit Rig(int filter_ticks = 1) {
    config.period_s = kDt;
    config.filter_ticks = filter_ticks;
    interp = std::make_unique<Interpolator>(*queue, config, Pose{});
  }
  void publish(const std::vector<MotionBlock>& blocks) {
    for (const MotionBlock& b : blocks) ASSERT_TRUE(queue->try_push(b));
  }
  const TickOutput& step() {
    TickOutput out;
    interp->tick(in, out);
    trace.push_back(out);
    in.cycle_start = in.abort = in.sync_done = false;
    return trace.back();
  }
  /// Ticks until `state` (or `limit` ticks); returns the number of ticks taken.
  int run_until(RunState state, int limit = 100000) {
    for (int n = 1; n <= limit; ++n) {
      if (step().state == state) return n;
    }
    return -1;
  }
  /// Largest |second difference| / dt² along X over the trace.
  double max_accel_x() const {
    double a = 0;
    for (std::size_t i = 2; i < trace.size(); ++i) {
      a = std::max(a,
                   std::fabs(trace[i].position[0] - 2 * trace[i - 1].position[0] + trace[i - 2].position[0]) /
                       (kDt * kDt));
    }
    return a;
  }
  double max_speed_x() const {
    double v = 0;
    for (std::size_t i = 1; i < trace.size(); ++i) {
      v = std::max(v, std::fabs(trace[i].position[0] - trace[i - 1].position[0]) / kDt);
    }
    return v;
  }
};

}  // namespace

TEST(Interpolator, TrapezoidOnOneLineTakesTheExactTimeAndEndsOnThePoint) {
  Rig rig;
  rig.publish(plan({line(at(0), at(100), 100, 1000, 0), marker(MarkerKind::ProgramEnd)}));
  const int n = rig.run_until(RunState::Finished);
  // 0.1 s up to 100 mm/s (5 mm), 0.9 s at 100 mm/s, 0.1 s down: 1100 periods of motion.
  EXPECT_GE(n, 1100);
  EXPECT_LE(n, 1102);
  EXPECT_EQ(rig.trace.back().position[0], 100.0);
  EXPECT_LE(rig.max_speed_x(), 100.0 * (1 + 1e-9));
  EXPECT_LE(rig.max_accel_x(), 1000.0 * (1 + 1e-6));
  EXPECT_EQ(rig.queue->available(), 1u);  // the end marker stays: the commanded position is on it
}

TEST(Interpolator, FeedOverrideScalesTheSpeedAndChangesSmoothlyMidMove) {
  Rig rig;
  rig.publish(plan({line(at(0), at(100), 100, 1000, 0), marker(MarkerKind::ProgramEnd)}));
  rig.in.feed_override = 0.5;
  for (int i = 0; i < 500; ++i) rig.step();
  EXPECT_NEAR(rig.trace.back().path_velocity, 50.0, 1e-9);
  rig.in.feed_override = 0.2;  // drops at the acceleration limit, never a step
  for (int i = 0; i < 100; ++i) rig.step();
  EXPECT_NEAR(rig.trace.back().path_velocity, 20.0, 1e-9);
  rig.in.feed_override = 5.0;  // clamped to the configured maximum, then to the cap
  EXPECT_GT(rig.run_until(RunState::Finished), 0);
  EXPECT_LE(rig.max_speed_x(), 100.0 * (1 + 1e-9));
  EXPECT_LE(rig.max_accel_x(), 1000.0 * (1 + 1e-6));
  EXPECT_EQ(rig.trace.back().position[0], 100.0);
}

TEST(Interpolator, FeedHoldStopsOnThePathAndResumes) {
  Rig rig;
  rig.publish(plan({line(at(0), at(30, 40), 100, 1000, 0), marker(MarkerKind::ProgramEnd)}));
  for (int i = 0; i < 200; ++i) rig.step();
  rig.in.feed_hold = true;
  EXPECT_EQ(rig.step().state, RunState::Holding);
  const int n = rig.run_until(RunState::Held);
  EXPECT_GT(n, 0);
  EXPECT_LE(n, 101);  // 100 mm/s at 1000 mm/s²
  const Pose p = rig.trace.back().position;
  EXPECT_NEAR(p[1] / p[0], 40.0 / 30.0, 1e-12);  // on the line
  for (int i = 0; i < 50; ++i) EXPECT_EQ(rig.step().position, p);
  rig.in.feed_hold = false;
  EXPECT_GT(rig.run_until(RunState::Finished), 0);
  EXPECT_NEAR(rig.trace.back().position[1], 40.0, 1e-12);
  EXPECT_LE(rig.max_accel_x(), 600.0 * (1 + 1e-6));  // 1000 mm/s² along s, 3/5 of it on X
}

TEST(Interpolator, MarkersStopWaitAndReport) {
  Rig rig;
  rig.publish(plan({line(at(0), at(10), 100, 1000, 0), marker(MarkerKind::Dwell, 0.25, 1),
                    line(at(10), at(20), 100, 1000, 1), marker(MarkerKind::Report, 0, 2),
                    line(at(20), at(30), 100, 1000, 2), marker(MarkerKind::ProgramStop, 0, 3),
                    line(at(30), at(40), 100, 1000, 3), marker(MarkerKind::Sync, 0, 4),
                    marker(MarkerKind::OptionalStop, 0, 5), line(at(40), at(50), 100, 1000, 4),
                    marker(MarkerKind::ProgramEnd, 0, 6)}));
  EXPECT_GT(rig.run_until(RunState::Dwelling), 0);
  EXPECT_EQ(rig.trace.back().position[0], 10.0);
  const int dwell = rig.run_until(RunState::Running);
  EXPECT_EQ(dwell, 250);  // 0.25 s
  EXPECT_GT(rig.run_until(RunState::WaitingCycleStart), 0);
  EXPECT_EQ(rig.trace.back().position[0], 30.0);
  int reports = 0, dwells = 0;
  for (const TickOutput& o : rig.trace) {
    for (int i = 0; i < o.event_count; ++i) {
      reports += o.events[static_cast<std::size_t>(i)].kind == MarkerKind::Report;
      dwells += o.events[static_cast<std::size_t>(i)].kind == MarkerKind::Dwell;
    }
  }
  EXPECT_EQ(reports, 1);
  EXPECT_EQ(dwells, 1);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(rig.step().state, RunState::WaitingCycleStart);
  rig.in.cycle_start = true;
  EXPECT_GT(rig.run_until(RunState::WaitingSync), 0);
  EXPECT_EQ(rig.trace.back().position[0], 40.0);
  rig.in.sync_done = true;
  rig.in.optional_stop = false;  // M1 passes when the switch is off
  EXPECT_GT(rig.run_until(RunState::Finished), 0);
  EXPECT_EQ(rig.trace.back().position[0], 50.0);
}

TEST(Interpolator, AbortStopsUnderControlAndDropsTheQueue) {
  Rig rig;
  rig.publish(plan({line(at(0), at(100), 100, 1000, 0), marker(MarkerKind::ProgramEnd)}));
  for (int i = 0; i < 300; ++i) rig.step();
  rig.in.abort = true;
  EXPECT_EQ(rig.step().state, RunState::Aborting);
  EXPECT_GT(rig.run_until(RunState::Aborted), 0);
  EXPECT_EQ(rig.queue->available(), 0u);
  EXPECT_LT(rig.trace.back().position[0], 100.0);
  EXPECT_LE(rig.max_accel_x(), 1000.0 * (1 + 1e-6));
  EXPECT_EQ(rig.step().state, RunState::Aborted);
}

// A power-fail stop short of energy: the abort brakes at the scale times the block's budget, so
// it rests in 1/scale of the time and distance; the scale is ignored while not aborting, and the
// path's budget is reported for the servo's estimate.
TEST(Interpolator, AnAbortBrakesAtItsDecelerationScale) {
  auto stop = [](double scale) {
    Rig rig;
    rig.publish(plan({line(at(0), at(100), 100, 1000, 0), marker(MarkerKind::ProgramEnd)}));
    rig.in.abort_decel_scale = scale;  // not aborting yet: no effect on the acceleration
    for (int i = 0; i < 300; ++i) rig.step();
    EXPECT_EQ(rig.trace.back().path_acceleration, 1000.0);
    EXPECT_LE(rig.max_accel_x(), 1000.0 * (1 + 1e-6));
    const double x0 = rig.trace.back().position[0];
    rig.in.abort = true;
    const int ticks = rig.run_until(RunState::Aborted);
    EXPECT_LE(rig.max_accel_x(), 1000.0 * std::max(1.0, scale) * (1 + 1e-6));
    return std::pair{ticks, rig.trace.back().position[0] - x0};
  };
  const auto [t1, d1] = stop(1.0);
  const auto [t3, d3] = stop(3.0);
  EXPECT_NEAR(d1, 100.0 * 100.0 / (2 * 1000.0), 0.1);  // v²/2a from 100 mm/s
  EXPECT_NEAR(d3, d1 / 3, 0.1);
  EXPECT_LT(t3, t1 / 2);
  EXPECT_EQ(stop(0.5), stop(1.0));  // never softer than planned
}

// A coupling code's marker (kWaitInPosition) waits at rest for the servo's in-position, then
// releases and reports; a G4 of no time does not wait for it.
TEST(Interpolator, AWaitInPositionMarkerHoldsUntilTheDrivesStandInPosition) {
  for (const bool flagged : {true, false}) {
    Rig rig;
    std::vector<MotionBlock> blocks = {line(at(0), at(10), 100, 1000, 0), marker(MarkerKind::Dwell, 0, 7),
                                       line(at(10), at(20), 100, 1000, 1), marker(MarkerKind::ProgramEnd)};
    if (flagged) blocks[1].flags |= kWaitInPosition;
    rig.publish(plan(blocks));
    rig.in.in_position = false;
    const int at_marker = rig.run_until(RunState::Dwelling, 2000);
    ASSERT_GT(at_marker, 0);
    for (int i = 0; i < 50; ++i) rig.step();
    const TickOutput& waiting = rig.trace.back();
    EXPECT_EQ(waiting.waiting_in_position, flagged);
    if (flagged) {
      EXPECT_EQ(waiting.position[0], 10.0);  // at rest on the marker
    } else {
      EXPECT_GT(waiting.position[0], 10.0);  // gone on
    }
    bool reported = false;
    for (const TickOutput& o : rig.trace)
      for (int e = 0; e < o.event_count; ++e)
        reported = reported || o.events[static_cast<std::size_t>(e)].action == 7;
    EXPECT_EQ(reported, !flagged);  // the marker's action follows its release
    rig.in.in_position = true;
    EXPECT_GT(rig.run_until(RunState::Finished), 0);
    EXPECT_FALSE(rig.trace.back().waiting_in_position);
    EXPECT_EQ(rig.trace.back().position[0], 20.0);
  }
}

TEST(Interpolator, StopsAtTheEndOfTheQueuedDataAndGoesOnWhenMoreArrives) {
  Rig rig;
  std::vector<MotionBlock> blocks =
      plan({line(at(0), at(50), 100, 1000, 0), line(at(50), at(100), 100, 1000, 1),
            marker(MarkerKind::ProgramEnd)});
  rig.publish({blocks[0]});
  EXPECT_GT(rig.run_until(RunState::Starved), 0);
  EXPECT_EQ(rig.trace.back().position[0], 50.0);
  EXPECT_LE(rig.max_accel_x(), 1000.0 * (1 + 1e-6));
  rig.publish({blocks[1], blocks[2]});
  EXPECT_GT(rig.run_until(RunState::Finished), 0);
  EXPECT_EQ(rig.trace.back().position[0], 100.0);
}

TEST(Interpolator, SingleBlockStopsAtEachMoveEnd) {
  Rig rig;
  rig.publish(plan({line(at(0), at(50), 100, 1000, 0), line(at(50), at(100), 100, 1000, 1),
                    marker(MarkerKind::ProgramEnd)},
                   100.0));
  rig.in.single_block = true;
  EXPECT_GT(rig.run_until(RunState::WaitingCycleStart), 0);
  EXPECT_EQ(rig.trace.back().position[0], 50.0);
  rig.in.cycle_start = true;
  EXPECT_GT(rig.run_until(RunState::Finished), 0);
  EXPECT_EQ(rig.trace.back().position[0], 100.0);
}

TEST(Interpolator, MovingAverageLimitsJerkAndSettlesOnTheEndPoint) {
  constexpr int kTicks = 20;  // T = 20 ms: jerk ≤ 2·A/T = 100000 mm/s³
  Rig rig(kTicks);
  rig.publish(plan({line(at(0), at(100), 100, 1000, 0), marker(MarkerKind::ProgramEnd)}));
  const int n = rig.run_until(RunState::Finished);
  EXPECT_GT(n, 1100 + kTicks - 2);
  double jerk = 0;
  for (std::size_t i = 3; i < rig.trace.size(); ++i) {
    const double* x[4] = {&rig.trace[i].position[0], &rig.trace[i - 1].position[0],
                          &rig.trace[i - 2].position[0], &rig.trace[i - 3].position[0]};
    jerk = std::max(jerk, std::fabs(*x[0] - 3 * *x[1] + 3 * *x[2] - *x[3]) / (kDt * kDt * kDt));
  }
  EXPECT_LE(jerk, 2 * 1000 / (kTicks * kDt) * (1 + 1e-6));
  EXPECT_GT(jerk, 1000 / (kTicks * kDt) * 0.9);
  EXPECT_LE(rig.max_accel_x(), 1000.0 * (1 + 1e-6));
  EXPECT_EQ(rig.trace.back().position[0], 100.0);
}
