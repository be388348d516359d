// SPDX-License-Identifier: GPL-3.0-or-later
// The lathe cycle and spline modules inside the interpreter: replay to a segment in the
// middle of a cycle, spline state in InterpState, origins of the cycle's moves, and which
// line an error names.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

using namespace opencnc;
using namespace opencnc::gcode;

namespace {

struct Motion {
  canon::SegmentId id;
  Pose end;
  canon::BlockOrigin origin;
  bool operator==(const Motion& o) const { return id == o.id && end == o.end; }
};

class Recorder final : public canon::Sink {
 public:
  void begin_block(const canon::BlockOrigin& o) override { origin_ = o; }
  void straight_traverse(canon::SegmentId id, const Pose& e) override { motions.push_back({id, e, origin_}); }
  void straight_feed(canon::SegmentId id, const Pose& e) override { motions.push_back({id, e, origin_}); }
  void arc_feed(canon::SegmentId id, const canon::ArcFeed& a) override { motions.push_back({id, a.end, origin_}); }
  void nurbs_feed(canon::SegmentId id, int, std::span<const canon::NurbsPoint> p) override {
    Pose e{};
    e[0] = p.back().x;
    e[1] = p.back().y;
    motions.push_back({id, e, origin_});
  }
  std::vector<Motion> motions;

 private:
  canon::BlockOrigin origin_;
};

Options with_modules() {
  Options o;
  o.extensions = standard_extensions(Dialect::LinuxCnc);
  return o;
}

const char* kCycles =
    "G21 G18 G90 F100\n"            // 1
    "G0 X14 Z3\n"                   // 2
    "o100 sub\n"                    // 3
    "  G1 X3 Z1\n"                  // 4
    "  G1 Z-4\n"                    // 5
    "  G2 X6 Z-7 I3 K0\n"           // 6
    "  G1 X4.5 Z-11 A0.4\n"         // 7
    "  G1 X10 Z-18\n"               // 8
    "N77 o100 endsub\n"             // 9
    "N80 G71 Q100 X14 Z3 D0.3 I1.2\n"   // 10
    "G70 Q100 X14 Z3 D0.3 P2\n"     // 11
    "G17 G5.2 X1 Y1 P1\n"           // 12
    "X2 Y3 P2\n"                    // 13
    "X4 Y0 P1\n"                    // 14
    "G5.3\n"                        // 15
    "M2\n";

}  // namespace

// Replay to segment k (in the middle of a roughing cycle, of a finishing pass, at the NURBS)
// gives exactly the tail of the full run, with the same ids and the same final state.
TEST(LatheCycles, ReplayToASegmentInsideACycleIsExact) {
  Interpreter full(with_modules());
  Recorder all;
  full.open_text("p.ngc", kCycles);
  ASSERT_EQ(full.run(all), RunStatus::Finished);
  ASSERT_GT(all.motions.size(), 40u);
  for (std::size_t k : {std::size_t{3}, std::size_t{17}, all.motions.size() - 8, all.motions.size() - 1}) {
    SCOPED_TRACE(k);
    Options o = with_modules();
    o.quiet_until_segment = k;
    Interpreter part(o);
    Recorder tail;
    part.open_text("p.ngc", kCycles);
    ASSERT_EQ(part.run(tail), RunStatus::Finished);
    ASSERT_EQ(tail.motions.size(), all.motions.size() - k);
    for (std::size_t i = 0; i < tail.motions.size(); ++i) EXPECT_EQ(tail.motions[i], all.motions[k + i]);
    EXPECT_EQ(part.state(), full.state());
  }
}

// The cycle's moves belong to the G71 line (its file, line and call context) and carry the
// N label of the last line read, the profile's endsub, as rs274 prints them.
TEST(LatheCycles, MovesBelongToTheCycleLine) {
  Interpreter interp(with_modules());
  Recorder rec;
  interp.open_text("p.ngc", kCycles);
  ASSERT_EQ(interp.run(rec), RunStatus::Finished);
  const Motion& first = rec.motions[1];   // the G71 block's own rapid
  EXPECT_EQ(first.origin.line, 10u);
  EXPECT_EQ(std::string(first.origin.n_digits, first.origin.n_length), "80");
  const Motion& pass = rec.motions[5];
  EXPECT_EQ(pass.origin.line, 10u);
  EXPECT_EQ(pass.origin.context, 0u);
  EXPECT_EQ(std::string(pass.origin.n_digits, pass.origin.n_length), "77");
}

// G5.2 control points are state: equal programs give equal states and digests point by point,
// and G5.3 clears them.
TEST(Splines, ControlPointsArePartOfTheState) {
  const char* program = "G21 F100\nG5.2 X1 Y1 P1 L4\nX2 Y3 P2\nX4 Y0 P1\nX5 Y1 P1\nG5.3\nM2\n";
  Interpreter a(with_modules()), b(with_modules());
  Recorder ra, rb;
  a.open_text("s.ngc", program);
  b.open_text("s.ngc", program);
  std::uint64_t last = 0;
  for (int step = 0; step < 5; ++step) {
    ASSERT_EQ(a.step(ra), RunStatus::Ok);
    ASSERT_EQ(b.step(rb), RunStatus::Ok);
    EXPECT_EQ(a.state(), b.state());
    EXPECT_EQ(a.state().digest(), b.state().digest());
    if (step >= 1) {
      EXPECT_NE(a.state().digest(), last);   // every G5.2 point changes the state
    }
    last = a.state().digest();
  }
  EXPECT_EQ(a.state().spline.points.size(), 5u);
  EXPECT_EQ(a.state().spline.order, 4);
  ASSERT_EQ(a.step(ra), RunStatus::Ok);   // G5.3
  EXPECT_TRUE(a.state().spline.points.empty());
  EXPECT_EQ(a.state().modal.motion, -1);
  EXPECT_EQ(a.state().position.current[0], 5.0);
  ASSERT_EQ(ra.motions.size(), 1u);
}

// An error in a profile line names that line; an error of the cycle's words names the cycle.
TEST(LatheCycles, ErrorsNameTheLineAtFault) {
  {
    Interpreter interp(with_modules());
    Recorder rec;
    interp.open_text("p.ngc", "G21 G18 F100\nG0 X12 Z2\no1 sub\nG1 X5 Z0\nG2 X7 Z-3\no1 endsub\nG71 Q1 I1\nM2\n");
    ASSERT_EQ(interp.run(rec), RunStatus::Error);
    const auto& d = interp.diagnostics().items().back();
    EXPECT_EQ(d.code, "gcode.lathe-profile-arc-centre-missing");
    EXPECT_EQ(d.line, 5u);
  }
  {
    Interpreter interp(with_modules());
    Recorder rec;
    interp.open_text("p.ngc", "G21 G18 F100\nG0 X12 Z2\no1 sub\nG1 X5 Z0\nG1 X7 Z-3\no1 endsub\nG71 Q1 I0\nM2\n");
    ASSERT_EQ(interp.run(rec), RunStatus::Error);
    const auto& d = interp.diagnostics().items().back();
    EXPECT_EQ(d.code, "gcode.lathe-depth-not-positive");
    EXPECT_EQ(d.line, 7u);
  }
}

// MDI runs a cycle whose profile is a subprogram file on the search path, and the session
// goes on afterwards with the machine's own letters (U is not an axis here).
TEST(LatheCycles, RunFromMdiWithAProfileFile) {
  const std::string dir = ::testing::TempDir() + "opencnc_lathe_mdi";
  std::filesystem::create_directories(dir);
  { std::ofstream(dir + "/500.ngc") << "o500 sub\nG1 X5 Z0\nG1 W-5\nG1 U6\no500 endsub\n"; }
  Options o = with_modules();
  o.subroutine_path = {dir};
  Interpreter interp(o);
  Recorder rec;
  ASSERT_EQ(interp.execute_mdi("G21 G18 F100", rec), RunStatus::Ok);
  ASSERT_EQ(interp.execute_mdi("G0 X12 Z2", rec), RunStatus::Ok);
  ASSERT_EQ(interp.execute_mdi("G71 Q500 D0.2 I1", rec), RunStatus::Ok);
  EXPECT_GT(rec.motions.size(), 10u);
  EXPECT_EQ(interp.execute_mdi("G71 Q501 D0.2 I1", rec), RunStatus::Error);   // no such sub: an error, no read
  EXPECT_EQ(interp.execute_mdi("G1 U1", rec), RunStatus::Error);
  EXPECT_EQ(interp.execute_mdi("G0 X20", rec), RunStatus::Ok);
  std::filesystem::remove_all(dir);
}
