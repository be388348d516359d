// SPDX-License-Identifier: GPL-3.0-or-later
// Run from line: the line resolved to its first move, the approach there (the line's tool changed
// in, its spindle and coolant), the program resumed with the state it has at that line (a G55
// offset set before it); lines that make no move, lie past the end or after an input are refused
// with words and move nothing; the scan runs beside the controller, which keeps answering.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>

#include "../control/test_profiles.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/run_from_line/run_from_line.hpp"
#include "opencnc/run_from_line/setup.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

constexpr const char* kProgram =
    "G21 G90 F600\n"      // 1
    "G10 L2 P2 X10\n"     // 2
    "G55 G0 X0 Y0 Z5\n"   // 3
    "G1 Z0\n"             // 4
    "G1 X20\n"            // 5
    "G1 Y20\n"            // 6
    "G1 X0\n"             // 7
    "G0 Z5\n"             // 8
    "o<unused> sub\n"     // 9
    "  G1 X99\n"          // 10
    "o<unused> endsub\n"  // 11
    "M2\n";               // 12

std::shared_ptr<GcodeProgramSource> mill_source(
    const config::MachineProfile& profile = control::test::mill()) {
  Diagnostics d;
  return features::machine_setup(profile, d)->source();
}

/// The feature as every front end sets it up: run_from_line::setup on a machine of `source`'s.
std::shared_ptr<run_from_line::RunFromLineFeature> set_up_feature(
    const config::MachineProfile& profile, const std::shared_ptr<GcodeProgramSource>& source) {
  Diagnostics d;
  auto machine = MachineSetup::create(profile, {}, d);
  machine->source_config().tools = source->tools();
  run_from_line::setup(profile, *machine);
  return std::dynamic_pointer_cast<run_from_line::RunFromLineFeature>(machine->feature("run-from-line"));
}

struct Rig {
  explicit Rig(std::shared_ptr<GcodeProgramSource> source = mill_source(),
               const config::MachineProfile& profile = control::test::mill())
      : s(profile, source) {
    feature = set_up_feature(profile, source);
    EXPECT_TRUE(feature);
    EXPECT_TRUE(s.rig().controller().add_feature(feature));
    s.ticks(1);
  }
  /// The answer comes once the scan on the feature's thread has ended: the machine ticks meanwhile.
  Outcome run_from(std::uint32_t line) {
    Controller& c = s.rig().controller();
    const std::uint64_t id =
        c.submit(Request::feature("run-from-line", "start", run_from_line::RunFromLineArgs{line}));
    std::optional<Outcome> o;
    EXPECT_TRUE(s.until([&] { return (o = c.outcome(id)).has_value(); }, 1000000));
    return o.value_or(Outcome{});
  }
  Scenario s;
  std::shared_ptr<run_from_line::RunFromLineFeature> feature;
};

TEST(RunFromLineScenario, TheProgramStartsAtTheLineWithItsStateAfterTheApproach) {
  TempProgram p("part.ngc", kProgram);
  Rig r;
  r.s.on(control::Mode::Auto);
  r.s.must(Request::open(p.path()));
  const Outcome o = r.run_from(6);
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_NE(o.message.find("part.ngc:6"), std::string::npos) << o.message;
  // The approach (an auxiliary job) to the start of line 6's move: machine X 30 (G55 X20), Y 0, Z 0.
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Auxiliary; }, 1000));
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Program; }, 100000));
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::X], 30.0, 1e-9);
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::Z], 0.0, 1e-9);
  // The program from line 6 on, never an earlier line, in G55.
  std::uint32_t first_line = 0;
  ASSERT_TRUE(r.s.until(
      [&] {
        const ControllerStatus st = r.s.status();
        if (first_line == 0 && st.job == JobKind::Program && st.location.line > 0)
          first_line = st.location.line;
        if (st.job == JobKind::Program && (st.location.line == 6 || st.location.line == 7)) {  // M2 sets G54
          EXPECT_EQ(st.offsets.system, 2);
        }
        return !st.run_active && st.servo.state == control::State::Idle;
      },
      200000));
  EXPECT_EQ(first_line, 6u);
  const Pose end = r.s.status().servo.commanded;
  EXPECT_NEAR(end[Axis::X], 10.0, 1e-9);  // G55 X0
  EXPECT_NEAR(end[Axis::Y], 20.0, 1e-9);
  EXPECT_NEAR(end[Axis::Z], 5.0, 1e-9);
}

// With jerk-limited axes the approach and the program from the line run as without them.
TEST(RunFromLineScenario, WithJerkLimitsTheProgramStartsAtTheLineAfterTheApproach) {
  TempProgram p("part.ngc", kProgram);
  const config::MachineProfile profile =
      control::test::mill({"axis.x.max_jerk=20000", "axis.y.max_jerk=20000", "axis.z.max_jerk=20000"});
  Rig r(mill_source(profile), profile);
  r.s.on(control::Mode::Auto);
  r.s.must(Request::open(p.path()));
  const Outcome o = r.run_from(6);
  ASSERT_TRUE(o.accepted) << o.message;
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Program; }, 100000));
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::X], 30.0, 1e-9);
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::Z], 0.0, 1e-9);
  std::uint32_t first_line = 0;
  ASSERT_TRUE(r.s.until(
      [&] {
        const ControllerStatus st = r.s.status();
        if (first_line == 0 && st.job == JobKind::Program && st.location.line > 0)
          first_line = st.location.line;
        return !st.run_active && st.servo.state == control::State::Idle;
      },
      200000));
  EXPECT_EQ(first_line, 6u);
  const Pose end = r.s.status().servo.commanded;
  EXPECT_NEAR(end[Axis::X], 10.0, 1e-9);
  EXPECT_NEAR(end[Axis::Y], 20.0, 1e-9);
  EXPECT_NEAR(end[Axis::Z], 5.0, 1e-9);
}

TEST(RunFromLineScenario, LinesWithoutAMovePastTheEndOrAfterAnInputAreRefused) {
  TempProgram p("part.ngc", kProgram);
  Rig r;
  r.s.on(control::Mode::Auto);
  r.s.must(Request::open(p.path()));
  const Pose before = r.s.status().servo.commanded;
  Outcome o = r.run_from(10);  // in a subroutine that is never called
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("line 10 makes no move"), std::string::npos) << o.message;
  o = r.run_from(40);
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("line 40 is past the program's end (line 12; its last move is on line 8)"),
            std::string::npos)
      << o.message;
  o = r.run_from(0);
  EXPECT_EQ(o.refusal, control::Refusal::BadValue);
  r.s.ticks(50);
  EXPECT_FALSE(r.s.status().run_active);
  EXPECT_EQ(r.s.status().servo.commanded, before);

  TempProgram q("input.ngc", "G21 G90 F600\nG1 X5\nM66 P0 L0\nG1 X10\nM2\n");
  r.s.must(Request::open(q.path()));
  o = r.run_from(4);
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("after the input value at "), std::string::npos) << o.message;
  EXPECT_TRUE(r.run_from(2).accepted);                                                   // before it: fine
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Program; }, 100000));  // after the approach
  ASSERT_TRUE(r.s.idle(200000));
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::X], 10.0, 1e-9);
  // Manual mode: refused
  r.s.must(Request::set_mode(control::Mode::Manual));
  EXPECT_EQ(r.run_from(2).refusal, control::Refusal::WrongMode);
}


// The approach's last leg runs at the line's move's feed per minute: under G93 the move's own
// (length × F), under G95 F × the spindle speed set before it; a G95 line under G96 (no rpm known)
// is refused.
TEST(RunFromLineScenario, TheApproachFeedIsPerMinuteUnderInverseTimeAndPerRevolution) {
  TempProgram p("feeds.ngc",
                "G21 G90 G94 F600\n"  // 1
                "S1000 M3\n"          // 2
                "G0 X0 Y0 Z5\n"       // 3
                "G1 Z0\n"             // 4
                "G93 G1 X30 F2\n"     // 5: 30 mm in 1/2 min: 60 mm/min
                "G95 G1 X40 F0.1\n"   // 6: 0.1 mm/rev at 1000 rpm: 100 mm/min
                "S2500\n"             // 7
                "G1 Y10\n"            // 8: 250 mm/min
                "G94 G1 X0 F300\n"    // 9
                "M2\n");              // 10
  Diagnostics d;
  const auto source = features::machine_setup(control::test::mill(), d)->source();
  const double expected[][2] = {{4, 600}, {5, 60}, {6, 100}, {8, 250}, {9, 300}};
  for (const auto& [line, feed] : expected) {
    std::string why;
    const auto at =
        run_from_line::find_line_start(*source, p.path(), Pose{}, static_cast<std::uint32_t>(line), {}, &why);
    ASSERT_TRUE(at.has_value()) << why;
    EXPECT_NEAR(at->feed_mm_per_min, feed, 1e-9) << "line " << line;
  }
  TempProgram q("no-speed.ngc", "G21 G90 G96 S100 D3000 M3\nG95 G1 X5 F0.1\nM2\n");
  std::string why;
  EXPECT_FALSE(run_from_line::find_line_start(*source, q.path(), Pose{}, 2, {}, &why).has_value());
  EXPECT_NE(why.find("line 2 feeds per revolution (G95) and no spindle speed in rpm is set before it"),
            std::string::npos)
      << why;
}


constexpr const char* kTwoTools =
    "G21 G90 G94 F600\n"  // 1
    "T1 M6 G43\n"         // 2: configs/mill-3axis.tbl: T1 Z45
    "S1000 M3\n"          // 3
    "G0 X0 Y0 Z5\n"       // 4
    "G1 Z0\n"             // 5
    "G1 X20\n"            // 6
    "G0 Z5\n"             // 7
    "T2 M6 G43\n"         // 8: T2 Z62.5
    "S2000 M4 M8\n"       // 9
    "G0 X10 Y10 Z5\n"     // 10
    "G1 Z-2 F300\n"       // 11
    "G1 X30\n"            // 12
    "G0 Z5\n"             // 13
    "M2\n";               // 14

// Started on a line after the second T M6 with no tool in the spindle: the approach changes T2
// in (the manual change the operator confirms), starts the spindle counterclockwise at 2000 rpm
// and the flood, then moves to the line's start with T2's length offset; the program runs on from
// there. A second start from the line, T2 now in the spindle, changes nothing.
TEST(RunFromLineScenario, TheApproachChangesToTheLinesToolThenStartsTheSpindleAndCoolant) {
  TempProgram p("tools.ngc", kTwoTools);
  Rig r;
  r.s.on(control::Mode::Auto);
  r.s.must(Request::open(p.path()));
  ASSERT_EQ(r.s.status().servo.tool, 0);
  const Outcome o = r.run_from(12);
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_NE(o.message.find("with tool 2 changed in"), std::string::npos) << o.message;
  ASSERT_TRUE(r.s.until([&] { return r.s.status().servo.wait == control::Wait::ManualToolChange; }, 5000));
  EXPECT_EQ(r.s.status().job, JobKind::Auxiliary);
  EXPECT_EQ(r.s.status().servo.prepared_tool, 2);
  EXPECT_FALSE(r.s.status().servo.flood);  // nothing after the change has run
  const Pose at_change = r.s.status().servo.commanded;
  r.s.must(Request::simple(control::CommandKind::ToolChanged));
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Program; }, 100000));
  ControllerStatus st = r.s.status();
  EXPECT_EQ(st.servo.tool, 2);
  EXPECT_TRUE(st.servo.flood);
  EXPECT_EQ(st.servo.spindle_direction, machine::SpindleDirection::Counterclockwise);
  EXPECT_NEAR(st.servo.spindle_rpm, 2000.0, 1e-9);
  // Line 12's move starts at X10 Y10 Z−2 with T2's 62.5 mm: machine Z 60.5.
  EXPECT_NEAR(st.servo.commanded[Axis::X], 10.0, 1e-9);
  EXPECT_NEAR(st.servo.commanded[Axis::Y], 10.0, 1e-9);
  EXPECT_NEAR(st.servo.commanded[Axis::Z], 60.5, 1e-9);
  EXPECT_NE(at_change, st.servo.commanded);
  ASSERT_TRUE(r.s.until(
      [&] {
        const ControllerStatus now = r.s.status();
        EXPECT_NE(now.servo.wait, control::Wait::ManualToolChange);  // no change after line 12
        return !now.run_active && now.servo.state == control::State::Idle;
      },
      200000));
  st = r.s.status();
  EXPECT_NEAR(st.servo.commanded[Axis::X], 30.0, 1e-9);
  EXPECT_NEAR(st.servo.commanded[Axis::Z], 67.5, 1e-9);  // G0 Z5 with T2
  EXPECT_NEAR(st.offsets.tool[Axis::Z], 62.5, 1e-9);

  // Again from line 12: T2 is in the spindle, so the approach goes straight there.
  const Outcome again = r.run_from(12);
  ASSERT_TRUE(again.accepted) << again.message;
  EXPECT_EQ(again.message.find("changed in"), std::string::npos) << again.message;
  ASSERT_TRUE(r.s.until(
      [&] {
        EXPECT_NE(r.s.status().servo.wait, control::Wait::ManualToolChange);
        return r.s.status().job == JobKind::Program;
      },
      100000));
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::Z], 60.5, 1e-9);
  ASSERT_TRUE(r.s.idle(200000));
}

// With a tool-change position the approach changes the tool there, as the program's M6 does: Z
// up alone first, then across; the operator's dialog comes there, and the approach goes on from
// there to the line, whose segment is found with the M6 moves counted as the program counts them.
TEST(RunFromLineScenario, TheApproachChangesTheToolAtTheToolChangePosition) {
  TempProgram p("tools.ngc", kTwoTools);
  const config::MachineProfile profile = control::test::mill({"tool_change.position={X=-50,Y=40,Z=150}"});
  Rig r(mill_source(profile), profile);
  r.s.on(control::Mode::Auto);
  r.s.must(Request::open(p.path()));
  const Outcome o = r.run_from(12);
  ASSERT_TRUE(o.accepted) << o.message;
  double xy_while_z_rose = 0;  // the machine starts at its origin
  ASSERT_TRUE(r.s.until(
      [&] {
        const Pose c = r.s.status().servo.commanded;
        if (c[Axis::Z] < 150.0 - 1e-9)
          xy_while_z_rose = std::max({xy_while_z_rose, std::abs(c[Axis::X]), std::abs(c[Axis::Y])});
        return r.s.status().servo.wait == control::Wait::ManualToolChange;
      },
      10000));
  EXPECT_EQ(xy_while_z_rose, 0.0);
  const Pose at_change = r.s.status().servo.commanded;
  EXPECT_NEAR(at_change[Axis::X], -50.0, 1e-9);
  EXPECT_NEAR(at_change[Axis::Y], 40.0, 1e-9);
  EXPECT_NEAR(at_change[Axis::Z], 150.0, 1e-9);
  r.s.must(Request::simple(control::CommandKind::ToolChanged));
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Program; }, 100000));
  // Line 12's move starts at X10 Y10 Z−2 with T2's 62.5 mm, reached from the tool-change position.
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::X], 10.0, 1e-9);
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::Z], 60.5, 1e-9);
  ASSERT_TRUE(r.s.idle(200000));
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::X], 30.0, 1e-9);  // line 12, then G0 Z5
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::Z], 67.5, 1e-9);
  EXPECT_EQ(r.s.status().servo.tool, 2);
}

/// The mill's program source, whose execute() (the run-from-line scan) waits until released:
/// a scan that lasts as long as the test wants.
class GatedSource final : public ProgramSource {
 public:
  explicit GatedSource(std::shared_ptr<GcodeProgramSource> inner) : inner_(std::move(inner)) {}
  Preflight preflight(const std::string& path, const Pose& start, const LoadOptions& options,
                      MoveCheck& check) override {
    return inner_->preflight(path, start, options, check);
  }
  std::unique_ptr<ProgramStream> execute(const std::string& path, const Pose& start,
                                         const LoadOptions& options) override {
    std::unique_lock lock(mutex_);
    entered_ = true;
    changed_.notify_all();
    changed_.wait(lock, [&] { return open_; });
    return inner_->execute(path, start, options);
  }
  std::unique_ptr<ProgramStream> mdi(std::string_view line, const Pose& start) override {
    return inner_->mdi(line, start);
  }
  bool wait_entered() {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, std::chrono::seconds(10), [&] { return entered_; });
  }
  void release() {
    std::lock_guard lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }

 private:
  std::shared_ptr<GcodeProgramSource> inner_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool entered_ = false, open_ = false;
};

// While the scan runs on its thread the controller answers: the status goes on, a feed override
// is accepted, a cycle start and a second run from line are refused with the reason, the machine
// stays idle; once the scan ends the request gets its answer and the program runs from the line.
TEST(RunFromLineScenario, TheControllerAnswersWhileTheScanRunsAndNothingStarts) {
  TempProgram p("part.ngc", kProgram);
  Scenario s(control::test::mill(),
             mill_source());  // no feature: the test's own run from line, on a gated source
  auto gate = std::make_shared<GatedSource>(mill_source());
  ASSERT_TRUE(s.rig().controller().add_feature(std::make_shared<run_from_line::RunFromLineFeature>(gate)));
  struct Open {  // a failed assertion still lets the scan's thread end before the rig goes
    std::shared_ptr<GatedSource> gate;
    ~Open() { gate->release(); }
  } open{gate};
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  Controller& c = s.rig().controller();
  const std::uint64_t id =
      c.submit(Request::feature("run-from-line", "start", run_from_line::RunFromLineArgs{6}));
  s.ticks(2);
  ASSERT_TRUE(gate->wait_entered());
  const std::uint64_t tick = s.status().servo.tick;
  s.ticks(100);
  EXPECT_GE(s.status().servo.tick, tick + 100);  // the status goes on
  EXPECT_FALSE(c.outcome(id).has_value());
  EXPECT_TRUE(s.ask(Request::feed_override(0.5)).accepted);
  const Outcome start = s.ask(Request::simple(control::CommandKind::CycleStart));
  EXPECT_EQ(start.refusal, control::Refusal::FeatureCheck);
  EXPECT_NE(start.message.find("run from line 6: the scan of the program is under way"), std::string::npos)
      << start.message;
  EXPECT_EQ(s.ask(Request::feature("run-from-line", "start", run_from_line::RunFromLineArgs{7})).refusal,
            control::Refusal::Busy);
  EXPECT_FALSE(s.status().run_active);
  EXPECT_EQ(s.status().servo.state, control::State::Idle);
  gate->release();
  std::optional<Outcome> o;
  ASSERT_TRUE(s.until([&] { return (o = c.outcome(id)).has_value(); }, 1000000));
  ASSERT_TRUE(o->accepted) << o->message;
  EXPECT_NE(o->message.find("part.ngc:6"), std::string::npos) << o->message;
  ASSERT_TRUE(s.until([&] { return s.status().job == JobKind::Program; }, 100000));
  ASSERT_TRUE(s.idle(200000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 10.0, 1e-9);
}


// A G10 L1 before the line is written to the table when the program runs, not when it is
// scanned: the scan reads the live table and writes a copy of its own, dropped before the next.
TEST(RunFromLineScenario, TheScanReadsTheLiveToolTableAndWritesOnlyItsOwnCopy) {
  tools::ToolTable table;
  tools::ToolEntry t1;
  t1.tool = 1;
  t1.pocket = 1;
  t1.offset[Axis::Z] = 45;
  ASSERT_TRUE(table.add(t1));
  auto live = std::make_shared<tools::MemoryToolTable>(table);
  auto scan = std::make_shared<run_from_line::ScanToolTable>(live);
  Diagnostics d;
  std::optional<GcodeSourceConfig> config = GcodeProgramSource::config_for(control::test::mill(), d);
  ASSERT_TRUE(config);
  config->tools = scan;
  GcodeProgramSource source(std::move(*config));
  TempProgram p("g10.ngc", "G21 G90\nT1 M6\nG10 L1 P1 Z99\nG43\nG0 X1 Z5\nM2\n");
  std::string why;
  const auto at = run_from_line::find_line_start(source, p.path(), Pose{}, 5, {}, &why);
  ASSERT_TRUE(at.has_value()) << why;
  EXPECT_NEAR(at->tool_offset[Axis::Z], 99.0, 1e-9);  // the program's own G10 holds at the line
  EXPECT_EQ(at->tool, 1);
  EXPECT_NEAR(live->snapshot()->tool(1)->offset[Axis::Z], 45.0, 1e-9);
  EXPECT_NEAR(scan->snapshot()->tool(1)->offset[Axis::Z], 99.0, 1e-9);
  const std::uint64_t version = scan->version();
  scan->reset();
  EXPECT_GT(scan->version(), version);
  EXPECT_NEAR(scan->snapshot()->tool(1)->offset[Axis::Z], 45.0, 1e-9);
}

}  // namespace
}  // namespace opencnc::controller::test
