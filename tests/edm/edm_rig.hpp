// SPDX-License-Identifier: GPL-3.0-or-later
// What the EDM's controller tests share: the profile with a small electrode, homing on the
// switches, a trace recorder and a program file of the test's own.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../control/test_profiles.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/sim_rig.hpp"

namespace opencnc::controller::test {

/// edm-5axis with a smaller electrode (5 mm²: four times the depth per discharge) so that a burn
/// of a few hundredths takes seconds of virtual time; `sets` after it. The mechanisms these tests
/// measure (the jump's period and height, the orbit's growth, the walls at the side gap) with
/// each condition's own values: issue 28's keys off (adaptive control, the lateral servo, the
/// finishing cycle, the walls by a removal rate), as before them; the profile as shipped, with
/// them on, is measured by EdmTurbine.* (edm_turbine_test.cpp).
inline config::MachineProfile without_issue_28(config::MachineProfile p) {
  for (int i = 0; i < p.edm.config.condition_count; ++i) {
    machine::EdmCondition& c = p.edm.config.conditions[static_cast<std::size_t>(i)];
    c.adaptive = c.lateral_servo = c.orbit_finish = false;
  }
  p.edm.sim.side_walls = machine::SideWalls::Envelope;
  return p;
}

inline config::MachineProfile edm_profile(std::vector<std::string> sets = {}) {
  sets.insert(sets.begin(), "edm.sim.electrode_area_mm2=5");
  return without_issue_28(
      control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml", sets)));
}

/// Machine on and every axis homed on its switches (the EDM's steppers know nothing at power-up).
inline bool on_and_homed(SimRig& rig) {
  if (!rig.request(Request::simple(control::CommandKind::MachineOn)).accepted) return false;
  if (!rig.request(Request::set_mode(control::Mode::Manual)).accepted ||
      !rig.request(Request::home()).accepted)
    return false;
  return rig.run_until(
      [&] { return rig.status().servo.state == control::State::Idle && rig.status().servo.all_homed; },
      60000);
}

/// Every trace sample of the run.
class Samples final : public ControllerObserver {
 public:
  void on_trace(const control::TraceSample& s, const TraceContext&) override { all.push_back(s); }
  std::vector<control::TraceSample> all;
};

/// `text` written to `<tmp>/<prefix>-<the running test's name>/p.ngc`; its path.
inline std::string write_program(const std::string& text, const std::string& prefix) {
  const auto dir = std::filesystem::temp_directory_path() /
                   (prefix + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "p.ngc").string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace opencnc::controller::test
