// SPDX-License-Identifier: GPL-3.0-or-later
// canon::Program as a window on a stream: what is released is freed, what is kept reads as before,
// indices never change.
#include <gtest/gtest.h>

#include <string>

#include "opencnc/canon/program_builder.hpp"

using namespace opencnc;
using namespace opencnc::canon;

namespace {

/// Move k of a test stream: lines and arcs, a new feed every 7 moves, a comment every 5.
void append_move(ProgramBuilder& b, int k) {
  BlockOrigin o;
  o.line = static_cast<std::uint32_t>(k + 1);
  b.begin_block(o);
  if (k % 7 == 0) b.set_feed_rate(100 + k % 1000);
  if (k % 5 == 0) b.comment("move " + std::to_string(k));
  Pose end;
  end[Axis::X] = k * 0.1;
  end[Axis::Y] = (k % 2) * 0.1;
  if (k % 3 == 0) {
    ArcFeed a;
    a.first_end = end[Axis::X];
    a.second_end = end[Axis::Y];
    a.first_center = end[Axis::X] - 0.05;
    a.second_center = 0.05;
    a.rotation = 1;
    a.end = end;
    b.arc_feed(static_cast<SegmentId>(k), a);
  } else {
    b.straight_feed(static_cast<SegmentId>(k), end);
  }
}

TEST(ProgramWindow, ReleasedFrontIsFreedAndTheRestReadsAsBefore) {
  constexpr int kMoves = 100000;
  ProgramBuilder whole, window;
  for (int k = 0; k < kMoves; ++k) append_move(whole, k);
  std::size_t peak = 0;
  for (int k = 0; k < kMoves; ++k) {
    append_move(window, k);
    // A reader 20000 moves behind the writer frees what it has passed.
    if (k > 20000 && k % 1000 == 0) {
      const std::size_t move = static_cast<std::size_t>(k - 20000);
      std::size_t action = window.program().first_held_action();
      while (action < window.program().action_count() && window.program().action(action).before_move < move) ++action;
      window.program().release_before(move, action);
    }
    peak = std::max(peak, window.program().memory_bytes());
  }
  const Program& w = window.program();
  const Program& p = whole.program();
  EXPECT_EQ(w.size(), p.size());
  EXPECT_EQ(w.action_count(), p.action_count());
  EXPECT_GT(w.first_held_move(), 50000u);
  EXPECT_LT(peak, p.memory_bytes() / 2);  // bounded by the distance between writer and reader
  for (std::size_t id = w.first_held_move() + 1; id < w.size(); ++id) {
    ASSERT_EQ(w.end(id), p.end(id)) << id;
    ASSERT_EQ(w.start_of(id), p.start_of(id)) << id;
    ASSERT_EQ(w.feed(id), p.feed(id)) << id;
    ASSERT_EQ(w.move(id).line, p.move(id).line);
    if (w.move(id).kind == MoveKind::Arc) {
      ASSERT_EQ(w.arc(id).center[0], p.arc(id).center[0]) << id;
    }
  }
  for (std::size_t a = w.first_held_action(); a < w.action_count(); ++a) {
    ASSERT_EQ(w.action(a).kind, p.action(a).kind);
    if (w.action(a).kind == ActionKind::Comment) {
      ASSERT_EQ(w.text(w.action(a).text), p.text(p.action(a).text));
    }
  }
}

TEST(ProgramWindow, AContinuationKeepsTheSettingsAndTheNumbering) {
  ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.use_length_units(Units::Inch);
  b.set_motion_control_mode(MotionControl::Continuous, 0.001);
  b.disable_feed_override();
  b.set_feed_rate(10);
  b.straight_feed(4, Pose{{1, 0, 0}});
  Pose start{{20, 5, 0}};
  auto next = b.continuation(start);
  next->straight_feed(5, Pose{{2, 0, 0}});
  const Program& p = next->program();
  EXPECT_EQ(p.start(), start);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p.end(0)[Axis::X], 50.8);   // inches still
  EXPECT_EQ(p.feed(0), 254.0);          // 10 in/min in mm/min
  EXPECT_EQ(p.segment_of(0), 5u);
  ASSERT_EQ(p.action_count(), 2u);      // path control and the override switch, before move 0
  EXPECT_EQ(p.action(0).kind, ActionKind::MotionControl);
  EXPECT_EQ(p.action(0).before_move, 0u);
  EXPECT_EQ(p.action(1).kind, ActionKind::FeedOverrideDisable);
}

}  // namespace
