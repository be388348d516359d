// SPDX-License-Identifier: GPL-3.0-or-later
// The holes pass on canonical calls of the test's own: a small hole slowed, held, overcut and put
// out before its end; an open or a large cut handed on unchanged; a split segment noted by the
// builder.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/cutting/hole_pass.hpp"
#include "opencnc/machine/plasma.hpp"

namespace opencnc::cutting::test {
namespace {

/// What reaches the builder: moves with their feed, and the torch's codes.
class Recorder final : public canon::Sink {
 public:
  struct Call {
    std::string what;  ///< "line", "arc", "M190" …
    canon::SegmentId id = 0;
    Pose end{};
    double feed = 0;
    double length = 0;
  };
  void set_feed_rate(double f) override { feed_ = f; }
  void straight_traverse(canon::SegmentId id, const Pose& end) override {
    calls.push_back({"rapid", id, end, feed_, 0});
    pos_ = end;
  }
  void straight_feed(canon::SegmentId id, const Pose& end) override {
    calls.push_back({"line", id, end, feed_, std::hypot(end[0] - pos_[0], end[1] - pos_[1])});
    pos_ = end;
  }
  void arc_feed(canon::SegmentId id, const canon::ArcFeed& a) override {
    const double r = std::hypot(pos_[0] - a.first_center, pos_[1] - a.second_center);
    const double a0 = std::atan2(pos_[1] - a.second_center, pos_[0] - a.first_center);
    const double a1 = std::atan2(a.end[1] - a.second_center, a.end[0] - a.first_center);
    double sweep = a1 - a0;
    if (a.rotation > 0 && sweep <= 1e-9) sweep += 2 * std::numbers::pi;
    if (a.rotation < 0 && sweep >= -1e-9) sweep -= 2 * std::numbers::pi;
    calls.push_back({"arc", id, a.end, feed_, std::fabs(sweep) * r});
    pos_ = a.end;
  }
  void process_code(const canon::ProcessCode& c) override {
    calls.push_back({"M" + std::to_string(c.code), 0, pos_, feed_, 0});
  }
  std::vector<Call> calls;

 private:
  double feed_ = 0;
  Pose pos_{};
};

config::PlasmaHoles holes() {
  config::PlasmaHoles h;
  h.diameter_mm = 32;
  h.speed_share = 0.6;
  h.overcut_mm = 4;
  h.arc_off_mm = 2;
  return h;
}

Pose at(double x, double y) {
  Pose p{};
  p[0] = x;
  p[1] = y;
  p[2] = 15;
  return p;
}

canon::ProcessCode code(int m) {
  canon::ProcessCode c;
  c.code = m;
  c.group = m == machine::kTorchOnCode || m == machine::kTorchOffCode ? machine::kTorchOnCode
                                                                      : machine::kThcHoldCode;
  return c;
}

/// A hole of radius `r` at (cx, cy): lead-in from the centre, one turn, out.
void hole(canon::Sink& s, double cx, double cy, double r, canon::SegmentId& id) {
  s.straight_traverse(id++, at(cx, cy));
  s.process_code(code(machine::kTorchOnCode));
  s.set_feed_rate(1500);
  s.straight_feed(id++, at(cx + r, cy));
  canon::ArcFeed a;
  a.first_end = cx + r;
  a.second_end = cy;
  a.first_center = cx;
  a.second_center = cy;
  a.rotation = 1;
  a.axis_end = 15;
  a.end = at(cx + r, cy);
  s.arc_feed(id++, a);
  s.process_code(code(machine::kTorchOffCode));
}

std::string sequence(const Recorder& r) {
  std::string s;
  for (const auto& c : r.calls) s += c.what + " ";
  return s;
}

TEST(HolePass, ASmallHoleIsSlowedHeldOvercutAndPutOutBeforeItsEnd) {
  Recorder out;
  HolePass pass(holes());
  pass.set_next(out);
  canon::SegmentId id = 0;
  hole(pass, 100, 100, 12, id);  // 24 mm across
  pass.straight_traverse(id++, at(0, 0));
  pass.flush();
  EXPECT_EQ(pass.holes(), 1);
  // M190, the hold, the lead-in, the circle, the overcut with the torch out 2 mm before its end,
  // back along the overcut to the contour's end (where the interpreter goes on from).
  EXPECT_EQ(sequence(out), "rapid M190 M192 line arc arc M191 arc arc M193 rapid ");
  double cut = 0, after_off = 0;
  bool off = false;
  for (const auto& c : out.calls) {
    if (c.what == "M191") off = true;
    if (c.what == "line" || c.what == "arc") {
      EXPECT_NEAR(c.feed, 900, 1e-9) << "60 % of F1500";
      (off ? after_off : cut) += c.length;
    }
  }
  const double circle = 2 * std::numbers::pi * 12;
  EXPECT_NEAR(cut, 12 + circle + 4 - 2, 1e-6) << "lead-in, the turn, the overcut up to the arc-off point";
  EXPECT_NEAR(after_off, 2 + 4, 1e-6) << "the overcut's last 2 mm, then its 4 mm back";
  EXPECT_NEAR(out.calls[8].end[0], 112, 1e-9) << "back at the circle's start and end";
  EXPECT_NEAR(out.calls[8].end[1], 100, 1e-9);
  EXPECT_NEAR(out.calls.back().feed, 1500, 1e-9) << "the programmed feed again after the hole";
  // The overcut's pieces carry the circle's segment id (the builder notes the split).
  EXPECT_EQ(out.calls[5].id, out.calls[4].id);
  EXPECT_EQ(out.calls[7].id, out.calls[4].id);
  EXPECT_EQ(out.calls[8].id, out.calls[4].id);
}

// After a hole the pass stands where the program's contour ended: an arc that follows it (no
// rapid between) starts there, on its own circle.
TEST(HolePass, AnArcAfterAHoleStartsWhereTheProgramSaysItDoes) {
  Recorder out;
  HolePass pass(holes());
  pass.set_next(out);
  canon::SegmentId id = 0;
  hole(pass, 100, 100, 12, id);
  canon::ArcFeed a;
  a.plane = canon::Plane::XY;
  a.first_end = 112;
  a.second_end = 120;
  a.first_center = 112;
  a.second_center = 110;
  a.rotation = 1;
  a.axis_end = 15;
  a.end = at(112, 120);
  pass.arc_feed(id++, a);  // a half circle of radius 10 from (112, 100)
  pass.flush();
  const auto& last = out.calls.back();
  ASSERT_EQ(last.what, "arc");
  EXPECT_NEAR(last.length, std::numbers::pi * 10, 1e-9) << "from (112, 100): its radius is 10 at both ends";
}

TEST(HolePass, LargeOrOpenCutsAreHandedOnUnchanged) {
  Recorder out;
  HolePass pass(holes());
  pass.set_next(out);
  canon::SegmentId id = 0;
  hole(pass, 475, 175, 20, id);  // 40 mm across: above the diameter
  pass.straight_traverse(id++, at(0, 0));
  pass.process_code(code(machine::kTorchOnCode));  // a short open cut
  pass.set_feed_rate(2400);
  pass.straight_feed(id++, at(10, 0));
  pass.process_code(code(machine::kTorchOffCode));
  pass.flush();
  EXPECT_EQ(pass.holes(), 0);
  EXPECT_EQ(sequence(out), "rapid M190 line arc M191 rapid M190 line M191 ");
  EXPECT_NEAR(out.calls[2].feed, 1500, 1e-9);
  EXPECT_NEAR(out.calls[7].feed, 2400, 1e-9);
}

TEST(HolePass, ACallItDoesNotHandleHandsOnWhatItHolds) {
  Recorder out;
  HolePass pass(holes());
  pass.set_next(out);
  pass.straight_traverse(0, at(0, 0));
  pass.process_code(code(machine::kTorchOnCode));
  pass.straight_feed(1, at(5, 0));
  EXPECT_EQ(sequence(out), "rapid M190 ") << "held while it may still be a hole";
  pass.dwell(1.0);  // not the pass's: what it holds goes first
  EXPECT_EQ(sequence(out), "rapid M190 line ");
}

TEST(HolePass, TheBuilderNotesASegmentSplitByAPass) {
  canon::ProgramBuilder b(kXyzabc, Pose{});
  b.note_repeated_ids_as_splits(true);  // as the hub's pipeline does with a pass over the calls
  HolePass pass(holes());
  pass.set_next(b);
  canon::SegmentId id = 0;
  hole(pass, 100, 100, 12, id);
  pass.straight_traverse(id++, at(0, 0));
  pass.flush();
  const canon::Program& p = b.program();
  // rapid, lead-in, the circle, the overcut in two pieces (split where the torch goes out) and
  // back in one, rapid: 7 moves for 4 segments.
  ASSERT_EQ(p.size(), 7u);
  EXPECT_EQ(p.segment_of(2), 2u);
  EXPECT_EQ(p.segment_of(5), 2u);
  EXPECT_EQ(p.segment_of(6), 3u) << "the rapid after the hole keeps its id";
  EXPECT_EQ(p.first_move_of(3), 6u);
  EXPECT_EQ(p.moves_of(2), 4u);
}

}  // namespace
}  // namespace opencnc::cutting::test
