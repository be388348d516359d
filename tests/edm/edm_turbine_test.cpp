// SPDX-License-Identifier: GPL-3.0-or-later
// The turbine channel (examples/edm-turbine-channel.ngc) without any dwell through the whole
// controller on configs/edm-5axis.toml: the finishing cycle holds the final depth until the square
// orbit is full, the side walls burn by their removal rate, and the figures of issue 28 are met;
// adaptive control against fixed parameters on the same job and seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "edm_rig.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/edm/edm_recorder.hpp"
#include "opencnc/edm/sequence.hpp"
#include "opencnc/features/features.hpp"

namespace opencnc::controller::test {
namespace {

/// The example with every G4 taken out: the finishing cycle alone gives the orbit its time.
std::string channel_without_dwell() {
  std::ifstream in(OPENCNC_SOURCE_DIR "/examples/edm-turbine-channel.ngc");
  std::string line, out;
  while (std::getline(in, line))
    if (line.rfind("G4", 0) != 0) out += line + "\n";
  return out;
}

/// Per condition: machining periods, those in band, and where the others were.
class PerCondition final : public ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const TraceContext&) override {
    const control::EdmStatus& e = s.edm;
    if (!e.on && burning && last == machine::GapState::Arc) ++arcs_at_burn_end;
    if (e.generator) last = e.gap_state;
    if (!e.on) burning = false;
    if (e.on && e.generator && e.gap_state != machine::GapState::Open) burning = true;
    if (!burning || !e.generator) return;
    const auto c = static_cast<std::size_t>(std::clamp(e.condition, 0, 4) + (e.finishing ? 5 : 0));
    ++n[c];
    const double ref = e.servo_reference_v;
    if (std::fabs(e.gap_voltage_v - ref) <= 0.1 * ref)
      ++in[c];
    else if (e.gap_state == machine::GapState::Open)
      ++open[c];
    else if (e.gap_voltage_v > ref)
      ++above[c];
    if (e.gap_state == machine::GapState::Short) ++shorts[c];
  }
  std::string text() const {
    std::ostringstream o;
    for (int c = 0; c < 10; ++c)
      if (n[c] > 0)
        o << "condition " << c % 5 << (c >= 5 ? " finishing" : "") << ": " << n[c] << " periods, in band "
          << static_cast<double>(in[c]) / n[c] << ", open " << static_cast<double>(open[c]) / n[c]
          << ", above " << static_cast<double>(above[c]) / n[c] << ", shorted " << shorts[c] << "\n";
    return o.str();
  }
  bool burning = false;
  machine::GapState last = machine::GapState::Open;
  int arcs_at_burn_end = 0;
  long open[10] = {};
  long n[10] = {}, in[10] = {}, above[10] = {}, shorts[10] = {};
};

struct Channel {
  std::unique_ptr<SimRig> rig;
  std::shared_ptr<edm::EdmRecorder> recorder;
  std::shared_ptr<PerCondition> per;
  bool finished = false;
  double seconds = 0;  ///< the run's machine time
  edm::EdmReport report() const { return recorder->report(); }
  const machine::SimEdmProcess& sim() const { return rig->machine().edm(); }
};

Channel run_program(const config::MachineProfile& profile, const std::string& text) {
  Channel r;
  const std::string path = write_program(text, "opencnc-edm-turbine");
  Diagnostics d;
  r.rig = std::make_unique<SimRig>(profile, *features::machine_setup(profile, d));
  r.recorder = std::make_shared<edm::EdmRecorder>(profile.edm.config, profile.servo_period_s);
  r.per = std::make_shared<PerCondition>();
  r.rig->controller().attach(r.recorder, ObserverOptions{0, true});
  r.rig->controller().attach(r.per, ObserverOptions{0, true});
  r.rig->step();
  EXPECT_TRUE(on_and_homed(*r.rig));
  EXPECT_TRUE(r.rig->request(Request::set_mode(control::Mode::Auto)).accepted);
  const Outcome opened = r.rig->request(Request::open(path), 100000);
  EXPECT_TRUE(opened.accepted) << opened.message;
  if (!opened.accepted) return r;
  const std::uint64_t start = r.rig->status().servo.tick;
  EXPECT_TRUE(r.rig->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  r.finished = r.rig->run_until(
      [&] { return !r.rig->status().run_active && r.rig->status().servo.state == control::State::Idle; },
      400000);
  r.seconds = static_cast<double>(r.rig->status().servo.tick - start) * profile.servo_period_s;
  return r;
}

Channel run_channel(const config::MachineProfile& profile) {
  return run_program(profile, channel_without_dwell());
}

config::MachineProfile channel_machine(std::vector<std::string> sets = {}) {
  return control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml", sets));
}

/// What a run's figures are, in one line (printed: the figures docs/edm.md quotes).
void print(const char* what, const Channel& r) {
  const edm::EdmReport e = r.report();
  std::printf(
      "%s: %.2f s machining of %.2f s, in band %.4f, %llu jumps, %llu shorts (%llu uncleared, longest "
      "%.3f s), %llu arcs (%llu periods), finishing %.2f s, %llu adaptations, wear %.5f mm, depth %.5f mm, "
      "oversize %.5f mm\n%s",
      what, e.machining_s, r.seconds, e.gap_voltage_in_band_fraction,
      static_cast<unsigned long long>(e.jumps), static_cast<unsigned long long>(e.shorts),
      static_cast<unsigned long long>(e.shorts_uncleared), e.short_recovery_max_s,
      static_cast<unsigned long long>(e.arcs), static_cast<unsigned long long>(e.arc_periods), e.finishing_s,
      static_cast<unsigned long long>(e.adaptations), r.sim().electrode_wear_max_mm(), r.sim().depth_max_mm(),
      r.sim().cavity_oversize_max_mm(), r.per->text().c_str());
}

/// The frontal gap at which the simulated discharges' mean voltage is `c`'s reference: the share
/// x of the breakdown gap with (U0·t_d + Ue·t_on)/(t_d + t_on + t_off) = Ur, t_d = t_on·x/(1 − x).
double frontal_gap_mm(const machine::EdmCondition& c, const machine::SimEdmConfig& sim) {
  const double ur = c.servo_reference_v, ue = sim.discharge_voltage_v;
  const double td = (ur * (c.on_time_us + c.off_time_us) - ue * c.on_time_us) / (c.voltage_v - ur);
  return td / (c.on_time_us + td) * sim.breakdown_um_per_v * 1e-3 * c.voltage_v;
}

/// Wall k's size on a flank: the finishing square's reach in its direction (half-side r:
/// r·(|cos θ| + |sin θ|)) plus the condition's side gap.
double wall_size_mm(const machine::EdmCondition& finish, int k) {
  constexpr double kPi = 3.14159265358979323846;
  const double a = 2 * kPi * k / machine::SimEdmProcess::kSides;
  return finish.orbit_radius_mm * (std::fabs(std::cos(a)) + std::fabs(std::sin(a))) + finish.side_gap_mm;
}

/// Front f's walls against their size: the mean's error (the cavity's size, as the report's
/// cavity_oversize_mm) and the widest single direction's.
struct WallErrors {
  double mean_mm = 0, widest_mm = 0;
};

WallErrors wall_errors(const machine::SimEdmProcess& sim, const machine::EdmCondition& finish, int f) {
  WallErrors w;
  for (int k = 0; k < machine::SimEdmProcess::kSides; ++k) {
    const double err = sim.wall_mm(f, k) - wall_size_mm(finish, k);
    w.mean_mm += err / machine::SimEdmProcess::kSides;
    if (std::fabs(err) > std::fabs(w.widest_mm)) w.widest_mm = err;
  }
  return w;
}

TEST(EdmTurbine, WithoutDwellTheFinishingCycleHoldsTheGapAndBurnsTheCavityToSize) {
  const config::MachineProfile p = channel_machine();
  const Channel r = run_channel(p);
  ASSERT_TRUE(r.finished);
  print("adaptive", r);
  const edm::EdmReport e = r.report();
  EXPECT_GE(e.gap_voltage_in_band_fraction, 0.90);  // issue 28's figure
  EXPECT_EQ(e.shorts_uncleared, 0u);                // every short recovered
  EXPECT_LT(e.short_recovery_max_s, 0.1);
  EXPECT_GT(e.finishing_s, 1.0);  // the cycle held both flanks' burns
  EXPECT_GT(e.adaptations, 0u);
  // No arc left standing: the last period of every burn sparked normally or was open (the
  // recorder's arcs all ended); here: the gap's state at the end of each burn.
  EXPECT_EQ(r.per->arcs_at_burn_end, 0);
  // The cavity of each flank (B −30, B +30): the finishing square's reach in each direction plus
  // condition 3's side gap; its depth the program's 0.095 mm less the finishing electrode's wear
  // plus the frontal gap at condition 3's reference.
  const machine::EdmCondition& finish = *p.edm.config.find(3);
  const machine::SimEdmProcess& sim = r.sim();
  ASSERT_EQ(sim.fronts(), 2);
  double worst = 0;
  for (int f = 0; f < 2; ++f) {
    // Each direction: issue 28's 5 µm. The walls stand the floor's gap beyond the electrode, so
    // condition 3 may close its gap to 36 V (adaptive control's bound; docs/edm.md).
    for (int k = 0; k < machine::SimEdmProcess::kSides; ++k)
      EXPECT_NEAR(sim.wall_mm(f, k), wall_size_mm(finish, k), 0.005) << "front " << f << ", direction " << k;
    // The cavity's size (the walls' mean, as the report's cavity_oversize_mm): issue 28's 5 µm.
    const WallErrors w = wall_errors(sim, finish, f);
    EXPECT_LE(std::fabs(w.mean_mm), 0.005) << "front " << f;
    worst = std::max(worst, std::fabs(w.widest_mm));
    const double depth = 0.095 - sim.electrode_wear_mm() + frontal_gap_mm(finish, p.edm.sim);
    EXPECT_NEAR(sim.front_depth_mm(f), depth, 0.005) << "front " << f;
    std::printf("front %d: walls %.5f mm over their size on the mean, depth %.5f mm (%.5f)\n", f, w.mean_mm,
                sim.front_depth_mm(f), depth);
  }
  std::printf("the widest direction's error %.5f mm\n", worst);
}

/// One seed of the simulated gap (its noise and debris): in band at least 0.9, each flank's
/// cavity within 5 µm of its size on the mean and in every direction, the depth within 5 µm,
/// every short recovered, no arc left standing.
void check_seed(const char* seed) {
  const config::MachineProfile p = channel_machine({seed});
  const Channel r = run_channel(p);
  ASSERT_TRUE(r.finished) << seed;
  print(seed, r);
  EXPECT_GE(r.report().gap_voltage_in_band_fraction, 0.90) << seed;
  EXPECT_EQ(r.report().shorts_uncleared, 0u) << seed;
  EXPECT_EQ(r.per->arcs_at_burn_end, 0) << seed;
  const machine::EdmCondition& finish = *p.edm.config.find(3);
  ASSERT_EQ(r.sim().fronts(), 2) << seed;
  for (int f = 0; f < 2; ++f) {
    const WallErrors w = wall_errors(r.sim(), finish, f);
    EXPECT_LE(std::fabs(w.mean_mm), 0.005) << seed << ", front " << f;
    EXPECT_LE(std::fabs(w.widest_mm), 0.005) << seed << ", front " << f;
    const double depth = 0.095 - r.sim().electrode_wear_mm() + frontal_gap_mm(finish, p.edm.sim);
    EXPECT_NEAR(r.sim().front_depth_mm(f), depth, 0.005) << seed << ", front " << f;
    std::printf(
        "%s front %d: walls %.5f mm over on the mean, the widest direction %.5f mm, depth %.5f mm (%.5f)\n",
        seed, f, w.mean_mm, w.widest_mm, r.sim().front_depth_mm(f), depth);
  }
}

// Not one lucky seed: the same job on seven other realisations of the simulated gap meets issue
// 28's figures too (a third of a second a run).
TEST(EdmTurbine, TheFiguresHoldOnOtherSeedsOfTheSimulatedGap) {
  for (const char* seed :
       {"sim.seed=1", "sim.seed=2", "sim.seed=3", "sim.seed=4", "sim.seed=5", "sim.seed=6", "sim.seed=7"})
    check_seed(seed);
}

TEST(EdmTurbine, AdaptiveControlAgainstFixedParametersOnTheSameJobAndSeed) {
  config::MachineProfile fixed = channel_machine();
  for (int i = 0; i < fixed.edm.config.condition_count; ++i)
    fixed.edm.config.conditions[static_cast<std::size_t>(i)].adaptive = false;
  const Channel a = run_channel(channel_machine());
  const Channel f = run_channel(fixed);
  ASSERT_TRUE(a.finished);
  ASSERT_TRUE(f.finished);
  print("adaptive", a);
  print("fixed", f);
  EXPECT_EQ(f.report().adaptations, 0u);
  EXPECT_EQ(f.report().gain_mm_s_per_v[0], 0.01);  // condition 3's, unmoved
  EXPECT_GT(a.report().gap_voltage_in_band_fraction, f.report().gap_voltage_in_band_fraction + 0.05);
  EXPECT_LT(a.report().machining_s, f.report().machining_s);
  EXPECT_EQ(a.report().shorts_uncleared + f.report().shorts_uncleared, 0u);
  // Deterministic: the same job and seed again, the same figures to the bit.
  const Channel again = run_channel(channel_machine());
  EXPECT_EQ(again.report().gap_voltage_in_band_fraction, a.report().gap_voltage_in_band_fraction);
  EXPECT_EQ(again.sim().cavity_oversize_max_mm(), a.sim().cavity_oversize_max_mm());
  EXPECT_EQ(again.sim().electrode_wear_max_mm(), a.sim().electrode_wear_max_mm());
}

// A generated sequence on the simulated sinker (the removal walls, the profile's 20 mm² blade):
// `opencnc edm sequence`'s plan for Ra 0.8 µm and 0.08 mm of undersize, burnt 0.1 mm deep from
// its program. The conditions come in the plan's order with their orbits, and the cavity comes
// out as planned: the finishing square's reach plus E3's side gap in every direction (within
// 5 µm) and the depth within 5 µm of 0.1 mm − wear + E3's frontal gap.
TEST(EdmSequenceRun, AGeneratedSequenceBurnsTheCavityAsPlanned) {
  const config::MachineProfile p = channel_machine();
  const auto planned = edm::plan_sequence(p.edm.config, {20, 0.8, 0.08});
  ASSERT_TRUE(std::holds_alternative<edm::Sequence>(planned)) << std::get<std::string>(planned);
  const edm::Sequence& seq = std::get<edm::Sequence>(planned);
  ASSERT_EQ(seq.steps.size(), 3u);
  const std::string text = edm::sequence_program(seq, p.edm.config, 'Z', -20, 0.1, 1);
  const Channel r = run_program(p, text);
  ASSERT_TRUE(r.finished);
  print("sequence", r);
  EXPECT_EQ(r.report().shorts_uncleared, 0u);
  EXPECT_EQ(r.per->arcs_at_burn_end, 0);
  // Each step burnt under its condition (the per-condition periods of the trace).
  for (const edm::SequenceStep& st : seq.steps) EXPECT_GT(r.per->n[st.condition], 0) << "E" << st.condition;
  const machine::SimEdmProcess& sim = r.sim();
  ASSERT_EQ(sim.fronts(), 1);
  const edm::SequenceStep& last = seq.steps.back();
  const machine::EdmCondition& finish = *p.edm.config.find(last.condition);
  constexpr double kPi = 3.14159265358979323846;
  double worst = 0, sum = 0, reach = 0;
  for (int k = 0; k < machine::SimEdmProcess::kSides; ++k) {
    const double a = 2 * kPi * k / machine::SimEdmProcess::kSides;
    const double size = last.orbit_mm * (std::fabs(std::cos(a)) + std::fabs(std::sin(a))) + last.side_gap_mm;
    sum += sim.wall_mm(0, k);
    reach += size;
    worst = std::max(worst, std::fabs(sim.wall_mm(0, k) - size));
  }
  std::printf("sequence: mean wall %.5f mm (planned %.5f), widest direction's error %.5f mm\n",
              sum / machine::SimEdmProcess::kSides, reach / machine::SimEdmProcess::kSides, worst);
  EXPECT_NEAR(sum / machine::SimEdmProcess::kSides, reach / machine::SimEdmProcess::kSides, 0.005);
  // The flat sides (X and Y): the undersize the plan was made for.
  for (int k = 0; k < machine::SimEdmProcess::kSides; k += machine::SimEdmProcess::kSides / 4)
    EXPECT_NEAR(sim.wall_mm(0, k), seq.request.undersize_mm, 0.005) << "direction " << k;
  const double depth = 0.1 - sim.electrode_wear_mm() + frontal_gap_mm(finish, p.edm.sim);
  EXPECT_NEAR(sim.front_depth_mm(0), depth, 0.005);
}

}  // namespace
}  // namespace opencnc::controller::test
