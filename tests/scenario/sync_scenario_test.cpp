// SPDX-License-Identifier: GPL-3.0-or-later
// The interpreter in the loop: G-code programs that read what the machine answers at sync points
// (probe results, inputs, tool changes, program stops) through the whole controller, and the
// moves after them checked again with the real values.
#include <gtest/gtest.h>

#include <string>

#include "../control/test_profiles.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "opencnc/tools/tool_table_service.hpp"

#include <fmt/format.h>
#include <cmath>
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

/// The errors the log noted since the cursor was made, in words.
std::string noted_errors(EventCursor& c) {
  std::string out;
  for (const ControllerEvent& e : c.next(1 << 20)) {
    if (e.kind == ControllerEventKind::Note && e.severity == Severity::Error) out += e.text + " [" + e.code + "]\n";
  }
  return out;
}

// The simulated probe of the mill meets the top of a part at Z −50: the program probes it and
// machines relative to what it found, not to what it assumed.
TEST(SyncScenario, ProbeTheTopOfAPartAndMachineRelativeToIt) {
  Scenario s(control::test::mill());
  TempProgram p("probe.ngc",
                "G21 G90 G54\n"
                "G0 X10 Y10 Z0\n"
                "G38.2 Z-100 F300\n"
                "G0 Z[#5063+5]\n"
                "M2\n");
  s.on(control::Mode::Auto);
  EventCursor log(s.rig().controller().events());
  ASSERT_TRUE(s.run_file(p.path())) << s.message();
  const ControllerStatus st = s.status();
  EXPECT_NEAR(st.servo.commanded[Axis::Z], -45.0, 0.001);
  EXPECT_TRUE(st.servo.probe_tripped);
  EXPECT_NEAR(st.servo.probe_position[Axis::Z], -50.0, 0.001);
  std::vector<ControllerEvent> waits, dones;
  for (const ControllerEvent& e : log.next(1 << 20)) {
    if (e.kind == ControllerEventKind::SyncWait) waits.push_back(e);
    if (e.kind == ControllerEventKind::SyncDone) dones.push_back(e);
  }
  ASSERT_EQ(waits.size(), 1u);
  EXPECT_EQ(waits[0].sync, SyncKind::Probe);
  EXPECT_EQ(waits[0].location.line, 3u);
  ASSERT_EQ(dones.size(), 1u);
  EXPECT_NE(dones[0].text.find("tripped"), std::string::npos) << dones[0].text;
}

// Work offsets from a probed point. G10 L2 with #5063 puts Z0 of G54 where the probe tripped;
// G10 L20 Z0 where the machine stopped after the trip (a few µm further at F200, as in LinuxCNC).
// Either way the moves after it start from what the probe found, not from the probe move's end.
TEST(SyncScenario, WorkOffsetSetFromAProbedPoint) {
  for (const char* set : {"G10 L2 P1 Z[#5223 + #5063]", "G10 L20 P1 Z0"}) {
    Scenario s(control::test::mill());
    TempProgram p("touch.ngc", fmt::format("G21 G90 G54\n"
                                           "G0 X0 Y0 Z-20\n"
                                           "G38.2 Z-80 F200\n"
                                           "{}\n"
                                           "G0 Z2\n"
                                           "G1 X5 F600\n"
                                           "M2\n",
                                           set));
    s.on(control::Mode::Auto);
    ASSERT_TRUE(s.run_file(p.path())) << s.message();
    const bool at_trip = std::string(set).find("L2 ") != std::string::npos;
    // 2 mm above the part at −50 (the machine stops 0.0066 mm past the trip at 3.3 mm/s).
    EXPECT_NEAR(s.status().servo.commanded[Axis::Z], at_trip ? -48.0 : -48.0066, 0.001) << set;
    EXPECT_NEAR(s.status().servo.commanded[Axis::X], 5.0, 1e-9);
  }
}

// M66 reads a real input, and the program branches on it.
TEST(SyncScenario, M66BranchesOnTheInputTheMachineReads) {
  const char* text =
      "G21 G90\n"
      "M66 P1 L0\n"
      "o100 if [#5399 EQ 1]\n"
      "  G0 X10\n"
      "o100 else\n"
      "  G0 X20\n"
      "o100 endif\n"
      "M2\n";
  for (const bool on : {true, false}) {
    Scenario s(control::test::mill());
    TempProgram p("m66.ngc", text);
    s.sim().set_digital_input(1, on);
    s.on(control::Mode::Auto);
    ASSERT_TRUE(s.run_file(p.path())) << s.message();
    EXPECT_NEAR(s.status().servo.commanded[Axis::X], on ? 10.0 : 20.0, 1e-9) << on;
  }
}

// A probe move that ends without contact: LinuxCNC's error, on the probe's line, and nothing after
// it moves.
TEST(SyncScenario, AProbeThatMissesStopsTheProgramWithLinuxCncsError) {
  Scenario s(control::test::mill());
  TempProgram p("miss.ngc",
                "G21 G90\n"
                "G0 X0 Y0 Z0\n"
                "G38.2 Z-30 F600\n"  // the part is at −50: no contact
                "G0 X50\n"
                "M2\n");
  s.on(control::Mode::Auto);
  EventCursor log(s.rig().controller().events());
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.idle(50000));
  const std::string errors = noted_errors(log);
  EXPECT_NE(errors.find("miss.ngc:3"), std::string::npos) << errors;
  EXPECT_NE(errors.find("G38.2 move finished without making contact"), std::string::npos) << errors;
  EXPECT_NE(errors.find("gcode.probe-no-contact"), std::string::npos) << errors;
  EXPECT_NEAR(s.status().servo.commanded[Axis::Z], -30.0, 1e-9);
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 0.0, 1e-9);  // the G0 X50 never ran
  EXPECT_EQ(s.status().runs_finished, 0u);
}

// The preflight assumes what rs274 assumes (the probe reaches the move's end): with that, the move
// after the probe would cross the Z soft limit. The program opens with a warning that names the
// line; with the real probe result the move is checked again before it runs.
TEST(SyncScenario, MovesThatRestOnAnAssumedValueAreCheckedAgainWithTheRealOne) {
  Scenario s(control::test::mill({"axis.z.min_limit=-120"}));
  TempProgram p("assumed.ngc",
                "G21 G90\n"
                "G0 X0 Y0 Z0\n"
                "G38.2 Z-110 F600\n"
                "G0 Z[#5063-40]\n"  // assumed: −150, beyond −120; real: −90
                "G0 Z0\n"
                "M2\n");
  s.on(control::Mode::Auto);
  const Outcome o = s.ask(Request::open(p.path()));
  ASSERT_TRUE(o.accepted) << s.message();
  bool warned = false;
  for (const Diagnostic& d : o.diagnostics.items()) {
    warned = warned || (d.severity == Severity::Warning && d.line == 4 && d.code == "control.soft-limit" &&
                        d.message.find("assumed") != std::string::npos);
  }
  EXPECT_TRUE(warned) << s.message();
  const std::optional<OpenProgram> open = s.rig().controller().open_program();
  ASSERT_TRUE(open.has_value());
  ASSERT_FALSE(open->preflight.summary.assumed_lines.empty());
  EXPECT_EQ(open->preflight.summary.assumed_lines.front().line, 4u);
  EXPECT_EQ(open->preflight.summary.sync_points, 1u);
  ASSERT_TRUE(s.start_and_finish()) << s.message();
  EXPECT_NEAR(s.status().servo.commanded[Axis::Z], 0.0, 1e-9);
}

// A probed value that drives a move past a soft limit: the machine stops before that move.
TEST(SyncScenario, AProbedValueThatCrossesASoftLimitStopsBeforeTheMove) {
  Scenario s(control::test::mill({"axis.z.min_limit=-120"}));
  TempProgram p("deep.ngc",
                "G21 G90\n"
                "G0 X0 Y0 Z0\n"
                "G38.2 Z-110 F600\n"
                "G0 Z[#5063-80]\n"  // real: −130, beyond −120
                "G0 X30\n"
                "M2\n");
  s.on(control::Mode::Auto);
  EventCursor log(s.rig().controller().events());
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.idle(50000));
  const std::string errors = noted_errors(log);
  EXPECT_NE(errors.find("deep.ngc:4"), std::string::npos) << errors;
  EXPECT_NE(errors.find("control.soft-limit"), std::string::npos) << errors;
  EXPECT_GT(s.status().servo.commanded[Axis::Z], -50.1);  // where the probe stopped
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 0.0, 1e-9);
  EXPECT_EQ(s.status().runs_finished, 0u);
}

// At a manual tool change the interpreter waits: a tool length measured while it waits counts for
// the G43 after the M6, and the change is written through the tool-table service.
TEST(SyncScenario, ToolDataChangedDuringAToolChangeCountsAfterIt) {
  tools::ToolTable table;
  tools::ToolEntry t1;
  t1.tool = 1;
  t1.pocket = 1;
  t1.offset[Axis::Z] = 10.0;
  table.add(t1);
  auto tools = std::make_shared<tools::MemoryToolTable>(table);
  const config::MachineProfile profile = control::test::mill();
  Diagnostics d;
  auto base = features::machine_setup(profile, d)->source();
  GcodeSourceConfig c;
  c.options = base->options_for("", {});
  c.tools = tools;
  Scenario s(profile, std::make_shared<GcodeProgramSource>(c));
  TempProgram p("tool.ngc",
                "G21 G90\n"
                "T1 M6\n"
                "G43 H1\n"
                "G0 Z0\n"
                "M2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.wait == control::Wait::ManualToolChange; }, 20000));
  EXPECT_EQ(s.status().sync_wait, SyncKind::ToolChange);
  EXPECT_NE(s.status().wait_text.find("T1"), std::string::npos) << s.status().wait_text;
  // The operator measures the new tool: 25 mm long, not 10.
  tools::ToolEntry measured = tools->snapshot()->at_index(1);
  measured.offset[Axis::Z] = 25.0;
  ASSERT_TRUE(tools->update(1, measured, tools::ChangeSource::Operator, d));
  s.must(Request::simple(control::CommandKind::ToolChanged));
  ASSERT_TRUE(s.idle(20000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::Z], 25.0, 1e-9);  // Z0 of the tool tip
}

// G10 L1 in a running program changes the machine's tool table (and a G43 after it uses it).
TEST(SyncScenario, G10L1WritesTheMachinesToolTable) {
  tools::ToolTable table;
  tools::ToolEntry t2;
  t2.tool = 2;
  t2.pocket = 5;
  t2.comment = "drill";
  t2.offset[Axis::Z] = 30.0;
  table.add(t2);
  auto tools = std::make_shared<tools::MemoryToolTable>(table);
  const config::MachineProfile profile = control::test::mill();
  Diagnostics d;
  GcodeSourceConfig c;
  c.options = features::machine_setup(profile, d)->source()->options_for("", {});
  c.tools = tools;
  Scenario s(profile, std::make_shared<GcodeProgramSource>(c));
  TempProgram p("g10.ngc", "G21 G90\nT2 M6\nG10 L1 P2 Z42.5 R3\nG43 H2\nG0 Z0\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  ASSERT_TRUE(tools->snapshot()->at_index(1).offset[Axis::Z] == 30.0);  // the preflight wrote nothing
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until(
      [&] {
        if (s.status().servo.wait == control::Wait::ManualToolChange)
          s.rig().controller().submit(Request::simple(control::CommandKind::ToolChanged));
        return !s.status().run_active && s.status().servo.state == control::State::Idle;
      },
      50000));
  const tools::ToolEntry now = tools->snapshot()->at_index(1);
  EXPECT_EQ(now.offset[Axis::Z], 42.5);
  EXPECT_EQ(now.diameter, 6.0);
  EXPECT_EQ(now.pocket, 5);
  EXPECT_EQ(now.comment, "drill");
  EXPECT_NEAR(s.status().servo.commanded[Axis::Z], 42.5, 1e-9);
  EXPECT_EQ(tools->version(), 1u);
}

// M0: the interpreter stops reading at the stop; status says what the run waits for.
TEST(SyncScenario, TheInterpreterWaitsAtAProgramStop) {
  Scenario s(control::test::mill());
  TempProgram p("stop.ngc", "G21 G90\nG0 X5\nM0\nG0 X10\nG0 X20\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::Stopped; }, 20000));
  const ControllerStatus st = s.status();
  EXPECT_EQ(st.sync_wait, SyncKind::ProgramStop);
  EXPECT_EQ(st.interpreter_moves, 1u);  // nothing after the M0 has been read
  EXPECT_NE(st.wait_text.find("cycle start"), std::string::npos) << st.wait_text;
  EXPECT_NE(st.wait_text.find("stop.ngc:3"), std::string::npos) << st.wait_text;
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.idle(20000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 20.0, 1e-9);
  EXPECT_EQ(s.status().runs_finished, 1u);
}

// A feed move with G64 blends through the streaming path exactly as the whole program planned at
// once: the trace of a program opened as a file equals the trace of the same program opened as
// canonical calls, sample for sample.
TEST(SyncScenario, StreamingMovesExactlyAsTheWholeProgram) {
  std::string text = "G21 G90 G64 P0.01\nG0 X0 Y0\nF3000\n";
  for (int i = 1; i <= 3000; ++i)
    text += fmt::format("G1 X{:.3f} Y{:.3f}\n", 20 * std::cos(i * 0.01) + 0.001 * i, 20 * std::sin(i * 0.01));
  text += "M2\n";
  TempProgram p("spiral.ngc", text);
  std::vector<control::TraceSample> streamed, whole;
  {
    Scenario s(
        control::test::mill({"interpreter.readahead_moves=10"}));  // the least read-ahead: the planner asks
    s.on(control::Mode::Auto);
    ASSERT_TRUE(s.run_file(p.path(), 400000)) << s.message();
    streamed = s.samples();
  }
  {
    Scenario s(control::test::mill());
    s.on(control::Mode::Auto);
    // The same program interpreted up front (scan mode) into one canon::Program.
    gcode::Options o;
    o.axes = AxisMask::from_letters("XYZ");
    o.initial_units = canon::Units::Mm;
    o.user_units = canon::Units::Mm;
    o.extensions = gcode::standard_extensions(o.dialect);
    gcode::Interpreter interp(o);
    canon::ProgramBuilder b(o.axes, s.status().servo.commanded);
    b.program().set_sources(interp.sources());
    b.set_motion_control_mode(canon::MotionControl::Continuous, 0);
    ASSERT_TRUE(interp.open(p.path()));
    interp.start(b);
    ASSERT_EQ(interp.run(b), gcode::RunStatus::Finished);
    s.must(Request::open(std::make_shared<canon::Program>(b.take()), "spiral"));
    ASSERT_TRUE(s.start_and_finish(400000)) << s.message();
    whole = s.samples();
  }
  ASSERT_EQ(streamed.size(), whole.size());
  for (std::size_t i = 0; i < streamed.size(); ++i) {
    ASSERT_TRUE(streamed[i].commanded == whole[i].commanded && streamed[i].tick == whole[i].tick)
        << "sample " << i << " (move " << streamed[i].segment << "): X " << streamed[i].commanded[Axis::X]
        << " streamed, " << whole[i].commanded[Axis::X] << " whole";
  }
}

}  // namespace
}  // namespace opencnc::controller::test

namespace opencnc::controller::test {
namespace {

/// The most moves a run's program window held at once.
class WindowWatch final : public ControllerObserver {
 public:
  void on_trace(const control::TraceSample&, const TraceContext& c) override {
    if (c.program == nullptr) return;
    most = std::max(most, c.program->size() - c.program->first_held_move());
    moves = std::max<std::uint64_t>(moves, c.first_move + c.program->size());
  }
  std::size_t most = 0;
  std::uint64_t moves = 0;
};

// A program far longer than the read-ahead runs in a window of the moves around the machine: what
// the machine has passed is freed as it goes. (Chords of 0.5 mm round a circle: the blends keep
// within P of every corner, so a zigzag of hairpins would crawl at each of them.)
TEST(StreamScenario, ALongProgramRunsInABoundedWindow) {
  Scenario s(control::test::mill());
  TempProgram p("long.ngc",
                "G21 G90 G64 P0.01 F6000\n"
                "#1 = 0\n"
                "o1 while [#1 lt 120000]\n"
                "  G1 X[50 * cos[#1 * 0.573]] Y[50 * sin[#1 * 0.573]]\n"
                "  #1 = [#1 + 1]\n"
                "o1 endwhile\n"
                "M2\n");
  auto watch = std::make_shared<WindowWatch>();
  s.rig().controller().attach(watch, ObserverOptions{0, true});
  s.on(control::Mode::Auto);
  ASSERT_TRUE(s.run_file(p.path(), 2'000'000)) << s.message();
  EXPECT_EQ(watch->moves, 120000u) << watch->most;
  EXPECT_GT(watch->most, 2000u);   // the read-ahead and the planner's window
  EXPECT_LT(watch->most, 60000u);  // far from all of it: released chunk by chunk
  const std::optional<OpenProgram> open = s.rig().controller().open_program();
  EXPECT_EQ(open->preflight.summary.moves, 120000u);
}

}  // namespace
}  // namespace opencnc::controller::test

namespace opencnc::controller::test {
namespace {

// The program's own dialect comment wins over the profile's default, and an O-numbered Fanuc
// program runs as `opencnc check --dialect fanuc` reads it (nothing is put in front of it).
TEST(DialectScenario, RunReadsTheProgramInItsOwnDialect) {
  const char* fanuc = "%\nO0001 (BRACKET)\nG21 G90 G54\nG0 X10. Y5.\nG1 X20. F600\nM30\n%\n";
  {
    Scenario s(control::test::mill({"interpreter.dialect=\"fanuc\""}));
    TempProgram p("o0001.nc", fanuc);
    s.on(control::Mode::Auto);
    ASSERT_TRUE(s.run_file(p.path())) << s.message();
    EXPECT_NEAR(s.status().servo.commanded[Axis::X], 20.0, 1e-9);
  }
  {
    Scenario s(control::test::mill());  // LinuxCNC by default: the comment says Fanuc
    TempProgram p("marked.nc", std::string("(dialect: fanuc)\n") + (fanuc + 2));
    s.on(control::Mode::Auto);
    ASSERT_TRUE(s.run_file(p.path())) << s.message();
    EXPECT_NEAR(s.status().servo.commanded[Axis::Y], 5.0, 1e-9);
  }
}

}  // namespace
}  // namespace opencnc::controller::test

namespace opencnc::controller::test {
namespace {

// Status says exactly where in the program the machine is: the move, the path length into it, the
// line and the calls that led there (what a breakpoint journal records).
TEST(StatusScenario, SaysTheMoveThePlaceInItAndTheCallStack) {
  Scenario s(control::test::mill());
  TempProgram p("calls.ngc",
                "o<side> sub\n"
                "  G1 X[#1] F600\n"
                "o<side> endsub\n"
                "G21 G90\n"
                "G0 X0 Y0\n"
                "o<side> call [40]\n"
                "M2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.commanded[Axis::X] > 10.0; }, 20000));
  const ControllerStatus st = s.status();
  EXPECT_EQ(st.job, JobKind::Program);
  EXPECT_EQ(st.run_segment, 1u);  // the second move: the G0 was the first
  EXPECT_NEAR(st.segment_offset, st.servo.commanded[Axis::X], 1e-9);  // the move starts at X0
  EXPECT_EQ(st.location.line, 2u);
  ASSERT_EQ(st.location.calls.size(), 1u);
  EXPECT_NE(st.location.calls[0].find("calls.ngc:6"), std::string::npos) << st.location.calls[0];
  EXPECT_NE(to_string(st.location).find("calls.ngc:2"), std::string::npos) << to_string(st.location);
  ASSERT_TRUE(s.idle(20000));
}

}  // namespace
}  // namespace opencnc::controller::test

namespace opencnc::controller::test {
namespace {

// MDI lines meet the machine too: a probe typed by the operator sets #5063 for the next line.
TEST(MdiSyncScenario, AProbeInMdiSetsItsParameters) {
  Scenario s(control::test::mill());
  s.on(control::Mode::Mdi);
  s.must(Request::mdi("G21 G90 G0 X5 Y5 Z0"));
  ASSERT_TRUE(s.idle(20000));
  s.must(Request::mdi("G38.2 Z-100 F300"));
  ASSERT_TRUE(s.idle(50000));
  EXPECT_TRUE(s.status().servo.probe_tripped);
  s.must(Request::mdi("G0 Z[#5063+5]"));
  ASSERT_TRUE(s.idle(20000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::Z], -45.0, 0.001);
}

}  // namespace
}  // namespace opencnc::controller::test
