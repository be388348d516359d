// SPDX-License-Identifier: GPL-3.0-or-later
// Flame retrace through the whole controller on the simulated flame cutter: the cut paused at A
// in the third part (feed hold, torch out, up to the safe height), the torch jogged to B beside
// the first part, start: to the nearest point C of the kerf-compensated path, the torch lit
// again, the program resumed at C's segment, stopping again at A; a step back along the path and
// a start from there; the program ends normally. Every move cut after each start has the
// segment id and the end point (to 1e-9 mm) of the same move of the whole program.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/retrace/retrace.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

using recovery::RetracePhase;

constexpr const char* kNest =
    "G21 G90 G17 G40 G64 P0.1\n"
    "F3000\n"
    "o<torch_on> sub\n"
    "  M64 P0\n"
    "  G4 P0.1\n"
    "  M64 P1\n"
    "  G4 P0.1\n"
    "  M64 P2\n"
    "  G4 P0.1\n"
    "o<torch_on> endsub\n"
    "o<torch_off> sub\n"
    "  M65 P2\n"
    "  M65 P1\n"
    "  M65 P0\n"
    "  G0 Z40\n"
    "o<torch_off> endsub\n"
    "o<part> sub\n"  // 40 x 40, one corner rounded, clockwise: G41 puts the kerf outside
    "  G0 Z40\n"
    "  G0 X[#1 - 5] Y#2\n"
    "  G0 Z5\n"
    "  o<torch_on> call\n"
    "  G1 Z3\n"
    "  G41 D1 G1 X#1 Y#2\n"
    "  G1 Y[#2 + 40]\n"
    "  G1 X[#1 + 30]\n"
    "  G2 X[#1 + 40] Y[#2 + 30] I0 J-10\n"
    "  G1 Y#2\n"
    "  G1 X#1\n"
    "  G40 G1 X[#1 - 5]\n"
    "  o<torch_off> call\n"
    "o<part> endsub\n"
    "#<k> = 0\n"
    "o1 while [#<k> LT 3]\n"
    "  o<part> call [20 + 60 * #<k>] [20]\n"
    "  #<k> = [#<k> + 1]\n"
    "o1 endwhile\n"
    "G0 X0 Y0\n"
    "M2\n";

/// The moves of every program job as the machine passes them (from the trace's program window).
class CutMoves final : public ControllerObserver {
 public:
  struct Cut {
    canon::SegmentId segment;
    Pose end;
    canon::MoveKind kind;
  };
  void on_trace(const control::TraceSample& s, const TraceContext& c) override {
    if (c.job != JobKind::Program || c.program == nullptr || s.activity != control::Activity::Program) return;
    auto& next = next_[c.job_id];
    for (std::uint64_t m = std::max<std::uint64_t>(next, c.program->first_held_move());
         m <= s.segment && m < c.program->size(); ++m)
      cuts_[c.job_id].push_back({c.program->segment_of(m), c.program->end(m), c.program->move(m).kind});
    next = std::max<std::uint64_t>(next, s.segment + 1);
  }
  std::map<std::uint32_t, std::vector<Cut>> cuts_;

 private:
  std::map<std::uint32_t, std::uint64_t> next_;
};

config::MachineProfile flame_cutter(std::vector<std::string> sets = {}) {
  for (const char* s :
       {"process.cutting.ignite_s=0.2", "process.cutting.preheat_s=0.3", "process.cutting.pierce_s=0.2"})
    sets.emplace_back(s);
  const config::ProfileLoad load =
      config::load_profile(OPENCNC_SOURCE_DIR "/configs/flame-cutter.toml", sets);
  EXPECT_TRUE(load.profile.has_value());
  return *load.profile;
}

/// The whole program as the controller's G-code source runs it, every move kept.
canon::Program whole_program(const config::MachineProfile& profile, const std::string& path) {
  Diagnostics d;
  auto source = features::machine_setup(profile, d)->source();
  auto stream = source->execute(path, Pose{}, {});
  while (stream->state() == StreamState::Reading) stream->read(100000);
  EXPECT_EQ(stream->state(), StreamState::Finished);
  const canon::Program& p = stream->program();
  canon::Program copy(p.axes());
  copy.set_start(p.start());
  for (std::size_t m = 0; m < p.size(); ++m) {
    canon::Move mv = p.move(m);
    copy.append(mv, p.end(m));
    if (copy.size() == 1) copy.set_first_segment(p.segment_of(0));
  }
  return copy;
}

void pause_jog_back_start_stop_again_at_a_step_back_and_cut_to_the_end(
    const config::MachineProfile& profile) {
  Scenario s(profile);
  auto feature = std::dynamic_pointer_cast<recovery::RetraceFeature>(s.machine().feature("retrace"));
  ASSERT_TRUE(feature);
  auto cuts = std::make_shared<CutMoves>();
  s.rig().controller().attach(cuts, ObserverOptions{0, true});
  TempProgram p("nest.ngc", kNest);
  const canon::Program whole = whole_program(profile, p.path());
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  const auto phase_is = [&](RetracePhase ph) {
    return [&, ph] { return feature->phase() == ph && s.status().servo.state == control::State::Idle; };
  };

  // A: in the third part's left side, the torch cutting.
  ASSERT_TRUE(s.until(
      [&] {
        return s.status().servo.commanded[Axis::X] > 130 && s.status().servo.commanded[Axis::Z] < 3.5 &&
               s.status().servo.commanded[Axis::Y] > 40;
      },
      60000));
  EXPECT_EQ(s.status().servo.digital_out & 0x7u, 0x7u);
  s.must(Request::feature("retrace", "pause"));
  ASSERT_TRUE(s.until(phase_is(RetracePhase::Paused), 20000));
  ASSERT_TRUE(s.until([&] { return s.status().servo.mode == control::Mode::Manual; }, 100));
  const Pose a = s.status().servo.commanded;
  EXPECT_EQ(s.status().servo.digital_out & 0x7u, 0u) << "the torch is out";
  EXPECT_DOUBLE_EQ(a[2], 40.0) << "at the safe height";

  // B: 2 mm above the first part's top edge (its kerf path at Y 61), jogged.
  s.must(Request::jog_by(Axis::X, 35 - a[0], 100));
  ASSERT_TRUE(s.idle());
  s.must(Request::jog_by(Axis::Y, 63 - a[1], 100));
  ASSERT_TRUE(s.idle());
  recovery::RetraceStart start;
  start.stop_at_a = true;
  s.must(Request::feature("retrace", "start", start));
  ASSERT_TRUE(
      s.until([&] { return feature->phase() == RetracePhase::Cutting && s.status().run_active; }, 20000));
  EXPECT_EQ(s.status().servo.digital_out & 0x7u, 0x7u) << "lit again";
  ASSERT_TRUE(s.until(phase_is(RetracePhase::Paused), 60000)) << "stops again at A";
  const Pose a2 = s.status().servo.commanded;
  EXPECT_NEAR(a2[0], a[0], 0.2) << "stopped again at A";
  EXPECT_NEAR(a2[1], a[1], 0.2);

  // A step 5 mm back along the path, then on from there to the end.
  ASSERT_TRUE(s.until([&] { return s.status().servo.mode == control::Mode::Manual; }, 100));
  s.must(Request::feature("retrace", "step", recovery::RetraceStep{-5}));
  ASSERT_TRUE(s.until(phase_is(RetracePhase::Paused), 20000));
  ASSERT_TRUE(s.until([&] { return s.status().servo.mode == control::Mode::Manual; }, 100));
  EventCursor log(s.rig().controller().events());
  s.must(Request::feature("retrace", "start"));
  ASSERT_TRUE(
      s.until([&] { return feature->phase() == RetracePhase::Idle && !s.status().run_active; }, 60000));
  int ended = 0;
  for (const ControllerEvent& e : log.next(1 << 20)) {
    if (e.kind != ControllerEventKind::JobEnded || e.job != JobKind::Program) continue;
    EXPECT_EQ(e.end, JobEnd::Finished) << "the program ends normally";
    ++ended;
  }
  EXPECT_EQ(ended, 1);

  const std::vector<recovery::RetraceRecord> r = feature->records();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_NEAR(r[0].c[0], 35.0, 1e-9);
  EXPECT_NEAR(r[0].c[1], 61.0, 1e-9);  // the top edge at Y 60, half the 2 mm kerf outside
  EXPECT_NEAR(r[0].distance_mm, 2.0, 1e-9);
  EXPECT_NE(r[0].line.find("nest.ngc:25 (in o<part> called at"), std::string::npos)
      << r[0].line;  // G1 X[#1 + 30], in o<part>
  EXPECT_LT(r[1].distance_mm, 1e-6) << "the step ends on the path";
  EXPECT_NEAR(std::hypot(r[1].c[0] - a2[0], r[1].c[1] - a2[1]), 5.0, 1e-6) << "5 mm back along the side";

  // Both resumed jobs cut the whole program's moves from C on: ids and end points.
  ASSERT_GE(cuts->cuts_.size(), 3u);
  int resumed = 0;
  for (const auto& [job, list] : cuts->cuts_) {
    if (job == cuts->cuts_.begin()->first) continue;  // the first run, from the start
    ASSERT_FALSE(list.empty());
    const recovery::RetraceRecord& rec = r[static_cast<std::size_t>(resumed++)];
    EXPECT_EQ(list.front().segment, rec.segment);
    std::size_t m = whole.first_move_of(list.front().segment);
    for (const CutMoves::Cut& c : list) {
      ASSERT_LT(m, whole.size());
      ASSERT_EQ(c.segment, whole.segment_of(m));
      ASSERT_EQ(c.kind, whole.move(m).kind);
      for (int ax = 0; ax < 3; ++ax)
        ASSERT_NEAR(c.end[ax], whole.end(m)[ax], 1e-9) << "segment " << c.segment;
      ++m;
    }
    if (resumed == 2) {
      EXPECT_EQ(m, whole.size()) << "the last run went to the program's end";
    }
  }
  EXPECT_EQ(resumed, 2);
}

TEST(RetraceScenario, PauseJogBackStartStopAgainAtAStepBackAndCutToTheEnd) {
  pause_jog_back_start_stop_again_at_a_step_back_and_cut_to_the_end(flame_cutter());
}

// The same with jerk-limited axes (the planner's curvature-continuous blends and the tick's
// jerk-limited average): the retrace works as before.
TEST(RetraceScenario, WithJerkLimitsTheRetraceWorksTheSame) {
  pause_jog_back_start_stop_again_at_a_step_back_and_cut_to_the_end(
      flame_cutter({"axis.x.max_jerk=20000", "axis.y.max_jerk=20000", "axis.z.max_jerk=20000"}));
}

}  // namespace
}  // namespace opencnc::controller::test
