// SPDX-License-Identifier: GPL-3.0-or-later
// Fault injection on the simulated plasma table (configs/plasma-table.toml, examples/plasma-nest.ngc):
// the arc lost in the middle of the first part's outline, the torch stage holds; the operator
// answers with the retrace — pause (torch out, up to the safe height), the torch jogged 20 mm back
// over the path, start (to the nearest point C, the program resumed at C's segment: M190 finds the
// plate and pierces again) — and the program runs to its end with the part's whole outline cut.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/retrace/retrace.hpp"

namespace opencnc::controller::test {
namespace {

using recovery::RetracePhase;

/// Where the arc burned: the commanded XY of every period with the torch cutting and arc-OK.
class Kerf final : public ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const TraceContext&) override {
    if (s.torch.phase != control::TorchPhase::Cutting || !s.torch.arc_ok) return;
    cells_[key(s.commanded[0], s.commanded[1])].push_back({s.commanded[0], s.commanded[1]});
  }
  /// The nearest point of the kerf's centre line to (x, y), within 1 mm (else 1e9).
  double distance(double x, double y) const {
    double best = 1e9;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j) {
        const auto it = cells_.find(key(x + i, y + j));
        if (it == cells_.end()) continue;
        for (const auto& [px, py] : it->second) best = std::min(best, std::hypot(px - x, py - y));
      }
    return best;
  }

 private:
  static std::pair<long, long> key(double x, double y) {
    return {static_cast<long>(std::floor(x)), static_cast<long>(std::floor(y))};
  }
  std::map<std::pair<long, long>, std::vector<std::pair<double, double>>> cells_;
};

/// The first part's outline (examples/plasma-nest.ngc: 200 x 120 at (100, 100)), every 0.25 mm:
/// the points farther than 0.2 mm from where the arc burned.
int uncut_points(const Kerf& k) {
  int uncut = 0;
  const double corners[5][2] = {{100, 100}, {300, 100}, {300, 220}, {100, 220}, {100, 100}};
  for (int e = 0; e < 4; ++e) {
    const double len = std::hypot(corners[e + 1][0] - corners[e][0], corners[e + 1][1] - corners[e][1]);
    for (double s = 0; s <= len; s += 0.25) {
      const double f = s / len;
      const double x = corners[e][0] + f * (corners[e + 1][0] - corners[e][0]);
      const double y = corners[e][1] + f * (corners[e + 1][1] - corners[e][1]);
      if (k.distance(x, y) > 0.2) ++uncut;
    }
  }
  return uncut;
}

struct Recovery {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<recovery::RetraceFeature> retrace;
  std::shared_ptr<Kerf> kerf;
  bool finished = false;
  int program_ends_finished = 0;
  double fault_x = 0;  ///< where the fault came, on the outline's lower edge
  std::vector<std::string> notes, refused;
  std::uint32_t pierces = 0;
  Pose paused_at{}, moved_to{};  ///< the torch after the pause, and after the jog or the step
};

/// The nest on the plasma table; `fault` (if any) is called once, on the first part's lower edge
/// at X > 200, cutting; then the retrace: pause, the torch jogged `back_mm` in X, start (to the
/// nearest point of the path) — or, with `by_step`, the retrace's own step `back_mm` along the
/// path from where the run held.
Recovery run(const std::function<void(SimRig&)>& fault, const std::function<void(SimRig&)>& cleared,
             double back_mm, bool by_step = false) {
  Recovery r;
  const config::MachineProfile profile =
      control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/plasma-table.toml", {}));
  Diagnostics d;
  std::shared_ptr<MachineSetup> setup = features::machine_setup(profile, d);
  r.retrace = std::dynamic_pointer_cast<recovery::RetraceFeature>(setup->feature("retrace"));
  EXPECT_TRUE(r.retrace);
  r.rig = std::make_unique<SimRig>(profile, *setup);
  r.kerf = std::make_shared<Kerf>();
  SimRig& rig = *r.rig;
  rig.controller().attach(r.kerf, ObserverOptions{0, true});
  EventCursor events(rig.controller().events());
  rig.step();
  EXPECT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  EXPECT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  const Outcome opened = rig.request(Request::open(OPENCNC_SOURCE_DIR "/examples/plasma-nest.ngc"), 100000);
  EXPECT_TRUE(opened.accepted) << opened.message;
  EXPECT_TRUE(rig.request(Request::simple(control::CommandKind::CycleStart)).accepted);
  int stage = fault ? 0 : 5;  // no fault: the reference run to its end
  std::uint64_t asked = 0;
  r.finished = rig.run_until(
      [&] {
        const ControllerStatus& st = rig.status();
        const control::ServoStatus& s = st.servo;
        for (const ControllerEvent& e : events.next()) {
          if (e.kind == ControllerEventKind::Note) r.notes.push_back(e.code);
          if (e.kind == ControllerEventKind::JobEnded && e.job == JobKind::Program &&
              e.end == JobEnd::Finished)
            ++r.program_ends_finished;
        }
        if (asked != 0) {
          const std::optional<Outcome> o = rig.controller().outcome(asked);
          if (!o) return false;
          if (!o->accepted) r.refused.push_back(o->message);
          asked = 0;
        }
        const bool paused = r.retrace->phase() == RetracePhase::Paused && s.state == control::State::Idle &&
                            s.mode == control::Mode::Manual;
        switch (stage) {
          case 0:  // cutting the first part's lower edge, past its middle
            if (s.torch.phase == control::TorchPhase::Cutting && std::fabs(s.commanded[1] - 100) < 0.01 &&
                s.commanded[0] > 200 && s.commanded[0] < 280) {
              r.fault_x = s.commanded[0];
              fault(rig);
              stage = 1;
            }
            return false;
          case 1:  // the torch stage held the run
            if (s.state != control::State::Held || s.path_velocity != 0) return false;
            EXPECT_FALSE(s.torch.torch_on);
            if (cleared) cleared(rig);
            asked = rig.controller().submit(Request::feature("retrace", "pause"));
            stage = 2;
            return false;
          case 2:  // paused: torch out, up at the safe height; jogged back over the path
            if (!paused) return false;
            r.paused_at = s.commanded;
            asked = rig.controller().submit(
                by_step ? Request::feature("retrace", "step", recovery::RetraceStep{back_mm})
                        : Request::jog_by(Axis::X, back_mm, 100));
            stage = 3;
            return false;
          case 3:
            if (!paused) return false;
            r.moved_to = s.commanded;
            asked = rig.controller().submit(Request::feature("retrace", "start"));
            stage = 4;
            return false;
          case 4:
            if (r.retrace->phase() == RetracePhase::Cutting && st.run_active) stage = 5;
            return false;
          default:
            r.pierces = s.torch.pierces;
            return !st.run_active && s.state == control::State::Idle &&
                   r.retrace->phase() == RetracePhase::Idle;
        }
      },
      600000);
  return r;
}

TEST(ArcLossRecovery, AnArcLostMidPartIsRetracedBackAlongThePathPiercedAgainAndThePartCompleted) {
  const Recovery whole = run({}, {}, 0);  // no fault: the reference
  ASSERT_TRUE(whole.finished);
  EXPECT_EQ(uncut_points(*whole.kerf), 0) << "the uninterrupted run cuts the whole outline";

  const Recovery r = run([](SimRig& rig) { rig.machine().inject_arc_loss(); }, {}, -20);
  ASSERT_TRUE(r.finished);
  EXPECT_TRUE(r.refused.empty()) << r.refused.front();
  EXPECT_NE(std::find(r.notes.begin(), r.notes.end(), "control.torch.arc-lost"), r.notes.end());
  EXPECT_EQ(r.program_ends_finished, 1) << "the resumed program ran to its end";
  const std::vector<recovery::RetraceRecord> rec = r.retrace->records();
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_NEAR(rec[0].a[1], 100, 1e-6) << "held on the lower edge";
  EXPECT_GT(rec[0].a[0], r.fault_x) << "A: where the run stood, braked after the loss";
  EXPECT_LT(rec[0].a[0], r.fault_x + 2);
  EXPECT_NEAR(rec[0].c[1], 100, 1e-6) << "C on the lower edge";
  EXPECT_NEAR(rec[0].c[0], rec[0].a[0] - 20, 1e-6) << "20 mm back along the path, before the loss";
  EXPECT_NEAR(rec[0].distance_mm, 0, 1e-6) << "B straight above the path";
  EXPECT_EQ(r.pierces, whole.pierces + 1) << "pierced again at C";
  EXPECT_EQ(uncut_points(*r.kerf), 0) << "the part's whole outline is cut";
}

// The retrace's own step from the hold: 20 mm back along the path from where the run held, on
// the outline's lower edge. The nest's lead-in and the lower edge are collinear lines of one feed,
// which the planner runs as one block: the run's move and offset name the lead-in, 110 mm into
// it, and the index must carry the offset on into the edge (it stopped at the lead-in's end).
TEST(ArcLossRecovery, TheRetracesStepFromTheHoldGoesBackAlongTheEdgeTheRunHeldOn) {
  const Recovery r = run([](SimRig& rig) { rig.machine().inject_arc_loss(); }, {}, -20, true);
  ASSERT_TRUE(r.finished);
  EXPECT_TRUE(r.refused.empty()) << r.refused.front();
  const std::vector<recovery::RetraceRecord> rec = r.retrace->records();
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_NEAR(r.paused_at[1], 100, 1e-6) << "held on the lower edge";
  EXPECT_NEAR(r.moved_to[1], 100, 1e-6) << "stepped along the lower edge";
  EXPECT_NEAR(r.moved_to[0], rec[0].a[0] - 20, 1e-6) << "20 mm back from A along the path";
  EXPECT_NEAR(rec[0].c[0], rec[0].a[0] - 20, 1e-6) << "C where the step ended";
  EXPECT_NEAR(rec[0].distance_mm, 0, 1e-6);
  EXPECT_EQ(uncut_points(*r.kerf), 0) << "the part's whole outline is cut";
}

// The torch's breakaway switch (digital input 1 of plasma-table.toml) trips mid-part: the torch
// stage puts the torch out and holds; the operator seats the torch (the switch closes again) and
// answers with the retrace: the part is completed as after an arc loss.
TEST(ArcLossRecovery, ABreakawayMidPartHoldsAndTheRetraceCompletesThePart) {
  const Recovery whole = run({}, {}, 0);
  ASSERT_TRUE(whole.finished);
  const Recovery r = run([](SimRig& rig) { rig.machine().set_digital_input(1, true); },
                         [](SimRig& rig) { rig.machine().set_digital_input(1, false); }, -20);
  ASSERT_TRUE(r.finished);
  EXPECT_TRUE(r.refused.empty()) << r.refused.front();
  EXPECT_NE(std::find(r.notes.begin(), r.notes.end(), "control.torch.breakaway"), r.notes.end());
  EXPECT_EQ(std::find(r.notes.begin(), r.notes.end(), "control.torch.arc-lost"), r.notes.end())
      << "the torch was put out, not lost";
  EXPECT_EQ(r.program_ends_finished, 1);
  EXPECT_EQ(r.pierces, whole.pierces + 1) << "pierced again at C";
  EXPECT_EQ(uncut_points(*r.kerf), 0) << "the part's whole outline is cut";
}

}  // namespace
}  // namespace opencnc::controller::test
