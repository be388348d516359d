// SPDX-License-Identifier: GPL-3.0-or-later
// Machine profiles for the controller tests: the shipped mill, and a mill that homes on
// switches (switch, switch + index, deceleration dog) with limit switches, a UPS and a probe.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "opencnc/config/profile_loader.hpp"

namespace opencnc::control::test {

inline config::MachineProfile loaded(const config::ProfileLoad& load) {
  std::string messages;
  for (const auto& d : load.diagnostics.items()) messages += d.format() + "\n";
  EXPECT_TRUE(load.ok()) << messages;
  return load.ok() ? *load.profile : config::MachineProfile{};
}

/// configs/mill-3axis.toml with `--set` overrides.
inline config::MachineProfile mill(std::vector<std::string> sets = {}) {
  return loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml", sets));
}

/// configs/drill-retrofit.toml with `--set` overrides.
inline config::MachineProfile drill(std::vector<std::string> sets = {}) {
  return loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.toml", sets));
}

/// Z homes first on a deceleration dog and a home switch; then X on a switch (latching the
/// rising edge after backing off) and Y on a switch and the next index mark (latching away from
/// the switch). Noisy switches with hysteresis, limit switches beyond the soft limits, a UPS,
/// a probe under Z, a tool changer.
inline const char* kHomingMillToml = R"(name = "homing-mill"
servo_period_s = 0.001
[sim]
substep_s = 0.0001
seed = 7

[axis.x]
max_velocity = 100.0
max_acceleration = 1000.0
min_limit = 0.0
max_limit = 300.0
max_following_error = 0.5
encoder_counts_per_unit = 13107.2
[axis.x.homing]
method = "switch"
position = 290.0
switch_position = 300.0
search_velocity = 20.0
latch_velocity = 0.5
sequence = 1
[axis.x.switches]
home = [100.0, inf]
limit_max = 160.0
limit_min = -150.0
hysteresis = 0.02
noise = 0.0004

[axis.y]
max_velocity = 100.0
max_acceleration = 1000.0
min_limit = -10.0
max_limit = 200.0
max_following_error = 0.5
encoder_counts_per_unit = 13107.2
[axis.y.homing]
method = "switch_index"
position = 5.0
switch_position = 0.0
search_velocity = -20.0
latch_velocity = 2.0
sequence = 1
[axis.y.switches]
home = [-inf, -50.0]
limit_min = -120.0
hysteresis = 0.02
noise = 0.003
[axis.y.sim]
index_spacing = 5.0
index_offset = 0.3

[axis.z]
max_velocity = 100.0
max_acceleration = 1000.0
min_limit = -200.0
max_limit = 0.0
max_following_error = 0.5
encoder_counts_per_unit = 13107.2
[axis.z.homing]
method = "decel_home"
position = -5.0
switch_position = 0.0
search_velocity = 30.0
latch_velocity = 0.5
sequence = 0
[axis.z.switches]
decel = [40.0, inf]
home = [45.0, inf]
limit_max = 80.0
hysteresis = 0.02
noise = 0.0004

[spindle]
max_rpm = 8000.0
encoder_counts_per_rev = 4096

[power]
ups = true

[probe.sim]
axis = "z"
trip = [-inf, -100.0]

[tool_changer]
[tool_changer.sim]
prepare_time_s = 0.2
change_time_s = 0.5
)";

inline config::MachineProfile homing_mill(std::vector<std::string> sets = {}) {
  return loaded(config::parse_profile(kHomingMillToml, "homing-mill.toml", sets));
}

}  // namespace opencnc::control::test
