// SPDX-License-Identifier: GPL-3.0-or-later
// Recovery after a power failure, through the whole controller on the simulated broach: the mains
// fail during a cutting stroke, the journal keeps the breakpoint; a second machine powers up where
// the axes rest (absolute encoders) and resumes — the groove it cuts matches the uninterrupted
// run's within 1 µm —, retracts along the helix within 1 µm, or refuses a changed program or a
// moved axis with the record left valid.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>
#include "../control/test_profiles.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/broaching/recovery_wait.hpp"

namespace opencnc::recovery {
namespace {

using control::CommandKind;
using control::State;
using controller::Request;
using controller::SimRig;

constexpr double kCutS = 3.2;  // into the first cutting stroke
/// A short broaching job (the demo job's first strokes, shortened so that ASan runs stay short):
/// groove 1 with one stroke, then groove 2 at C 180° with one stroke.
const char* const kJob =
    "G21 G90 G94 G17 G40 G49\nG64 P0.005\nG0 X-0.5\nG0 Z-10 C0\nM171 P600\nG1 X0.1 F60\n"
    "G1 Z310 F3000\nG1 X-0.4 F60\nG0 Z-10\nM175\nG0 C180\nM171 P600\nG1 X0.1 F60\nG1 Z110 F3000\n"
    "G1 X-0.4 F60\nG0 Z-10\nM175\nM2\n";

/// Two strokes of 0.1 mm each in one groove (the second to X 0.2): a resume in the second meets
/// 0.2 mm of chip on an uncut bore (5.75 kN, above the hold level), 0.1 mm on the real one.
const char* const kTwoStrokes =
    "G21 G90 G94 G17 G40 G49\nG64 P0.005\nG0 X-0.5\nG0 Z-10 C0\nM171 P600\nG1 X0.1 F60\n"
    "G1 Z110 F3000\nG1 X-0.4 F60\nG0 Z-10\nG1 X0.2 F60\nG1 Z110 F3000\nG1 X-0.3 F60\nG0 Z-10\nM175\nM2\n";

std::filesystem::path fresh_dir(const std::string& what);

/// A short job as a file of its own.
std::string job_file(const char* text = kJob) {
  const auto path = fresh_dir("job") / "job.ngc";
  std::ofstream(path) << text;
  return path.string();
}

std::filesystem::path fresh_dir(const std::string& what) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-recovery-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
       "-" + what + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Every period's feedback of X, Z, C and whether C was coupled.
class Samples final : public controller::ControllerObserver {
 public:
  struct Row {
    double x, z, c;
    bool coupled;
    controller::JobKind job;
  };
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override {
    rows.push_back({s.actual[Axis::X], s.actual[Axis::Z], s.actual[Axis::C], s.coupled, c.job});
  }
  std::vector<Row> rows;
};

/// A broach with the journal writer in `dir`; `sets` model where the axes power up.
struct Machine {
  Machine(const std::filesystem::path& dir, std::vector<std::string> sets = {})
      : profile(
            control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml", sets))) {
    Diagnostics d;
    auto machine =
        features::machine_setup(profile, d, controller::MachineSetup::Options::with("journal", dir.string()));
    EXPECT_TRUE(machine) << (d.items().empty() ? "" : d.items()[0].format());
    rig = std::make_unique<SimRig>(profile, *machine);
    journal = std::dynamic_pointer_cast<BreakpointJournal>(machine->feature("journal"));
    EXPECT_TRUE(journal);
    samples = std::make_shared<Samples>();
    rig->controller().attach(samples, controller::ObserverOptions{0, true});
    rig->step();
    EXPECT_TRUE(rig->request(Request::simple(CommandKind::MachineOn)).accepted);
    EXPECT_TRUE(rig->request(Request::set_mode(control::Mode::Auto)).accepted);
  }
  /// Runs `program` and cuts the mains `cut_s` into it; the record once written.
  BreakpointRecord cut_mains(const std::string& program, double cut_s) {
    EXPECT_TRUE(rig->request(Request::open(program), 100000).accepted);
    EXPECT_TRUE(rig->request(Request::simple(CommandKind::CycleStart)).accepted);
    EXPECT_TRUE(rig->run_until([&] { return rig->status().servo.time_s >= cut_s; }, 100000));
    rig->machine().set_mains_ok(false);
    EXPECT_TRUE(rig->run_until([&] { return rig->status().servo.state == State::Faulted; }, 5000));
    rig->run(3);
    journal->flush();
    return journal->last_written().value_or(BreakpointRecord{});
  }
  /// Asks for a recovery choice and runs until it has completed or failed.
  controller::Outcome choose(const std::string& action, std::any args = {}) {
    const controller::Outcome o = rig->request(Request::feature("journal", action, std::move(args)), 100000);
    if (o.accepted) {
      rig->run_until(
          [&] {
            const RecoveryPhase p = journal->phase();
            return p == RecoveryPhase::Done || p == RecoveryPhase::Failed;
          },
          400000);
    }
    journal->flush();
    return o;
  }
  config::MachineProfile profile;
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<BreakpointJournal> journal;
  std::shared_ptr<Samples> samples;
};

/// Where the record's axes rest, as a machine with absolute encoders powers up there.
std::vector<std::string> power_up_at(const BreakpointRecord& r, double z_moved = 0) {
  std::vector<std::string> sets;
  for (const auto& [name, axis] : {std::pair{"x", Axis::X}, {"z", Axis::Z}, {"c", Axis::C}}) {
    const double at = r.actual[axis] + (axis == Axis::Z ? z_moved : 0);
    sets.push_back(fmt::format("axis.{}.sim.start_position={:.17g}", name, at));
    sets.push_back(fmt::format("axis.{}.homing.position={:.17g}", name, at));
  }
  return sets;
}

/// The largest distance on the bore (µm) between C of `rows` and C of `ref` at the same Z, over
/// the coupled rows of the stroke at infeed `x` with Z in [z0, z1] (`ref` interpolated in Z).
double groove_deviation_um(const std::vector<Samples::Row>& rows, const std::vector<Samples::Row>& ref,
                           double x, double z0, double z1, double radius_mm, int* compared) {
  std::vector<std::pair<double, double>> line;  // the reference stroke: (z, c), z increasing
  for (const auto& r : ref) {
    if (r.coupled && std::fabs(r.x - x) < 0.002 && (line.empty() || r.z > line.back().first))
      line.push_back({r.z, r.c});
  }
  double worst = 0;
  *compared = 0;
  for (const auto& r : rows) {
    if (r.job != controller::JobKind::Program) continue;  // the run-in
    if (r.z > z1) break;  // the stroke's end: the rows after belong to later strokes
    if (!r.coupled || std::fabs(r.x - x) >= 0.002 || r.z < z0 || r.z > z1) continue;
    const auto it = std::lower_bound(line.begin(), line.end(), std::pair{r.z, -1e300});
    if (it == line.begin() || it == line.end()) continue;
    const auto& [za, ca] = *(it - 1);
    const auto& [zb, cb] = *it;
    const double c = ca + (cb - ca) * (r.z - za) / (zb - za);
    worst = std::max(worst,
                     std::fabs(std::remainder(r.c - c, 360.0)) * std::numbers::pi / 180 * radius_mm * 1000);
    ++*compared;
  }
  return worst;
}

// The uninterrupted stroke against the resumed one from the rest point to the stroke's end.
TEST(PowerFailRecovery, ResumedGrooveMatchesTheUninterruptedRun) {
  const std::string kProgram = OPENCNC_SOURCE_DIR "/examples/broach-constant.ngc";
  Machine reference(fresh_dir("ref"));
  ASSERT_TRUE(reference.rig->request(Request::open(kProgram), 100000).accepted);
  ASSERT_TRUE(reference.rig->request(Request::simple(CommandKind::CycleStart)).accepted);
  ASSERT_TRUE(reference.rig->run_until(
      [&] { return reference.rig->status().servo.commanded[Axis::Z] >= 609.9; }, 100000));

  const auto dir = fresh_dir("journal");
  BreakpointRecord r;
  std::vector<float> bore;
  {
    Machine cut(dir);
    r = cut.cut_mains(kProgram, kCutS);
    ASSERT_TRUE(r.valid && r.stage == BreakpointStage::AtRest);
    const std::span<const float> b = cut.rig->machine().broach_bore();
    bore.assign(b.begin(), b.end());
  }
  // The machine powers up with the groove cut so far (the workpiece keeps it) and the load
  // guard's own levels: the run-in and the rest of the groove meet no chip they have cut already.
  Machine after(dir, power_up_at(r));
  ASSERT_TRUE(after.rig->machine().restore_broach_bore(bore));
  const controller::Outcome o = after.choose("resume");
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_EQ(after.journal->phase(), RecoveryPhase::Done) << after.journal->recovery_error();
  EXPECT_EQ(after.rig->status().runs_finished, 2u);  // the run-in (auxiliary), then the program
  int compared = 0;
  const double dev = groove_deviation_um(after.samples->rows, reference.samples->rows, 0.1, r.actual[Axis::Z],
                                         609.0, after.profile.coupling.radius_mm, &compared);
  EXPECT_GT(compared, 5000);  // the rest of the stroke, period by period
  EXPECT_LE(dev, 1.0);
  const auto cleared = after.journal->last_written();
  ASSERT_TRUE(cleared.has_value());
  EXPECT_FALSE(cleared->valid);  // cleared once the resumed program finished
  EXPECT_LT(after.rig->status().servo.load_kn, 4.0);
}

// Without the groove cut before (a fresh workpiece where the record says it was cut), the
// resumed stroke meets the groove's whole depth as a chip: the load guard holds the feed, and the
// wait for the choice ends with the reason instead of waiting for a resume nobody gives.
TEST(PowerFailRecovery, ResumesIntoTheGrooveCutBeforeWithTheLoadGuardsLevels) {
  const std::string kProgram = job_file(kTwoStrokes);
  const auto dir = fresh_dir("journal");
  BreakpointRecord r;
  std::vector<float> bore;
  {
    Machine cut(dir);
    r = cut.cut_mains(kProgram, 6.0);  // in the second stroke
    ASSERT_NEAR(r.actual[Axis::X], 0.2, 1e-3);
    const std::span<const float> b = cut.rig->machine().broach_bore();
    bore.assign(b.begin(), b.end());
  }
  {
    Machine uncut(dir, power_up_at(r));  // the bore not restored
    const controller::Outcome o = uncut.rig->request(Request::feature("journal", "resume"), 100000);
    ASSERT_TRUE(o.accepted) << o.message;
    const std::string why = run_recovery(*uncut.rig, *uncut.journal, {60.0, 2.0});
    EXPECT_NE(why.find("the feed was held (load 5."), std::string::npos) << why;
    EXPECT_EQ(uncut.journal->phase(), RecoveryPhase::Failed);
    EXPECT_LT(uncut.rig->status().servo.time_s, 10.0);  // ended at the hold, far from the bound
    uncut.journal->flush();
    EXPECT_TRUE(uncut.journal->last_written()->valid);  // the choice is still the operator's
  }
  Machine after(dir, power_up_at(r));
  ASSERT_TRUE(after.rig->machine().restore_broach_bore(bore));
  const controller::Outcome o = after.rig->request(Request::feature("journal", "resume"), 100000);
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_EQ(run_recovery(*after.rig, *after.journal, {60.0, 2.0}), "");
  EXPECT_EQ(after.rig->status().servo.load_action, control::LoadAction::None);
  after.journal->flush();
  EXPECT_FALSE(after.journal->last_written()->valid);
}

// A stroke written as two lines (Z to 150, then on to 310 at the same feed): the planner runs
// them as one block, whose offset the servo counts from the first line's start. The mains fail in
// the second line: the record names it (its line, its start, the offset within it), and the resume
// goes on forward from where the axes rest — never back through the cut to the first line's end
// (it did before stop 34: the tool dragged backwards over 100 mm of groove).
TEST(PowerFailRecovery, AStrokeOfTwoJoinedLinesResumesForwardFromTheSecond) {
  const char* const kSplit =
      "G21 G90 G94 G17 G40 G49\nG64 P0.005\nG0 X-0.5\nG0 Z-10 C0\nM171 P600\nG1 X0.1 F60\n"
      "G1 Z150 F3000\nG1 Z310 F3000\nG1 X-0.4 F60\nG0 Z-10\nM175\nM2\n";
  const std::string kProgram = job_file(kSplit);
  const auto dir = fresh_dir("journal");
  BreakpointRecord r;
  {
    Machine cut(dir);
    r = cut.cut_mains(kProgram, 6.5);
    ASSERT_TRUE(r.valid && r.stage == BreakpointStage::AtRest);
    ASSERT_GT(r.actual[Axis::Z], 160) << "in the second line";
  }
  EXPECT_EQ(r.line, 8u) << "the second line of the stroke";
  EXPECT_NEAR(r.move_start[Axis::Z], 150, 1e-9);
  EXPECT_NEAR(r.move_end[Axis::Z], 310, 1e-9);
  EXPECT_GT(r.move_remaining_mm, 0);
  EXPECT_GT(r.segment_offset_mm, 0);
  Machine after(dir, power_up_at(r));
  const controller::Outcome o = after.choose("resume");
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_EQ(after.journal->phase(), RecoveryPhase::Done) << after.journal->recovery_error();
  // After the run-in (an auxiliary job: back along the helix by its length, within the move), the
  // program's Z only goes forward while C is coupled in the cut.
  double last = -1e300, backwards = 0;
  for (const Samples::Row& row : after.samples->rows) {
    if (row.job != controller::JobKind::Program || !row.coupled || row.x < 0.05) continue;
    if (last > -1e300) backwards = std::max(backwards, last - row.z);
    last = row.z;
  }
  EXPECT_LT(backwards, 1e-3) << "Z went back by " << backwards << " mm in the cut";
  EXPECT_GT(last, 309.9);
  EXPECT_FALSE(after.journal->last_written()->valid);
}

// In the second groove (its law engaged at C 180°, after the first groove's M171 … M175): only the
// law that holds at the segment re-engages, with its origin, and the job finishes.
TEST(PowerFailRecovery, ResumesInTheSecondGroove) {
  const std::string kProgram = job_file();
  const auto dir = fresh_dir("journal");
  BreakpointRecord r;
  {
    Machine cut(dir);
    r = cut.cut_mains(kProgram, 14.5);
    ASSERT_EQ(r.coupling.slave_origin, 180.0);
  }
  Machine after(dir, power_up_at(r));
  const controller::Outcome o = after.choose("resume");
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_EQ(after.journal->phase(), RecoveryPhase::Done) << after.journal->recovery_error();
  EXPECT_EQ(after.rig->status().servo.fault.kind, control::FaultKind::None);
  EXPECT_FALSE(after.journal->last_written()->valid);
}

TEST(PowerFailRecovery, RetractKeepsTheHelix) {
  const std::string kProgram = job_file();
  const auto dir = fresh_dir("journal");
  BreakpointRecord r;
  {
    Machine cut(dir);
    r = cut.cut_mains(kProgram, kCutS);
  }
  Machine after(dir, power_up_at(r));
  const controller::Outcome o = after.choose("retract", RetractArgs{40.0, false, 600.0});
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_EQ(after.journal->phase(), RecoveryPhase::Done) << after.journal->recovery_error();
  EXPECT_NEAR(after.rig->status().servo.commanded[Axis::Z], r.actual[Axis::Z] - 40.0, 1e-9);
  // The breakaway included: the drives' friction compensation puts the Coulomb friction into both
  // velocity integrators at the start (empty after the power-up), so C does not lag Z while they
  // build it (3.27 µm before; 0.14 µm measured, in the second period).
  double worst_um = 0;
  int n = 0;
  for (const auto& row : after.samples->rows) {
    if (row.job != controller::JobKind::Auxiliary) continue;
    const double law =
        r.coupling.slave_origin + 360.0 * (row.z - r.coupling.master_origin) / r.coupling.pitch_mm;
    const double e = std::fabs(std::remainder(row.c - law, 360.0)) * std::numbers::pi / 180 *
                     after.profile.coupling.radius_mm * 1000;
    worst_um = std::max(worst_um, e);
    ++n;
  }
  EXPECT_GT(n, 3000);  // 40 mm at 10 mm/s
  EXPECT_LE(worst_um, 1.0);
  EXPECT_FALSE(after.journal->last_written()->valid);
}

TEST(PowerFailRecovery, AChangedProgramOrAMovedAxisIsRefused) {
  const auto dir = fresh_dir("journal");
  const std::string program =
      (dir.parent_path() / ("recovery-job-" + std::to_string(::getpid()) + ".ngc")).string();
  std::ofstream(program) << kJob;
  BreakpointRecord r;
  {
    Machine cut(dir);
    r = cut.cut_mains(program, kCutS);
  }
  {
    Machine moved(dir, power_up_at(r, 0.5));
    const controller::Outcome o = moved.choose("resume");
    EXPECT_FALSE(o.accepted);
    EXPECT_NE(o.message.find("Z is 0.5000 mm from where it came to rest"), std::string::npos) << o.message;
    EXPECT_TRUE(moved.journal->last_written()->valid);
  }
  std::ofstream(program, std::ios::app) << "(edited after the power failure)\n";
  Machine after(dir, power_up_at(r));
  const controller::Outcome o = after.choose("resume");
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("changed since the power failed"), std::string::npos) << o.message;
  EXPECT_TRUE(after.journal->last_written()->valid);  // the choice is still the operator's
  const controller::Outcome d = after.choose("discard");
  EXPECT_TRUE(d.accepted);
  EXPECT_FALSE(after.journal->last_written()->valid);
  std::filesystem::remove(program);
}

}  // namespace
}  // namespace opencnc::recovery
