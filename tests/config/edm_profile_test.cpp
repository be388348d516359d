// SPDX-License-Identifier: GPL-3.0-or-later
// [edm] in profiles: the shipped EDM loads with its conditions; bad conditions are named at
// their file:line:col with a stable code.
#include <gtest/gtest.h>

#include <string>

#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {
namespace {

const std::string kEdm = std::string(OPENCNC_SOURCE_DIR) + "/configs/edm-5axis.toml";

std::string all_messages(const Diagnostics& d) {
  std::string s;
  for (const auto& i : d.items()) s += i.format() + "\n";
  return s;
}

const Diagnostic* first_error(const ProfileLoad& load) {
  for (const auto& d : load.diagnostics.items())
    if (d.severity == Severity::Error) return &d;
  return nullptr;
}

constexpr const char* kMachine = R"(name = "edm"
[axis.x]
max_velocity = 20
max_acceleration = 500
min_limit = -10
max_limit = 10
[axis.y]
max_velocity = 20
max_acceleration = 500
min_limit = -10
max_limit = 10
[axis.z]
max_velocity = 50
max_acceleration = 2000
min_limit = -50
max_limit = 10
[process]
generator = true
[edm]
tool_axis = "Z"
)";

std::string condition(const std::string& extra) {
  return "[[edm.condition]]\nnumber = 1\non_time_us = 100\noff_time_us = 50\npeak_current_a = 10\n"
         "voltage_v = 100\nservo_reference_v = 45\ngain_mm_s_per_v = 0.02\nmax_forward_mm_s = 1\n"
         "max_retract_mm_s = 3\n" +
         extra;
}

TEST(EdmProfile, TheFiveAxisEdmLoadsWithItsConditions) {
  const ProfileLoad load = load_profile(kEdm);
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const MachineProfile& p = *load.profile;
  ASSERT_TRUE(p.edm.present);
  EXPECT_EQ(p.edm.config.condition_count, 4);
  const machine::EdmCondition* c = p.edm.config.find(3);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->orbit, machine::OrbitKind::Square);
  EXPECT_EQ(c->jump_mode, machine::JumpMode::Path);
  EXPECT_EQ(c->orbit_radius_mm, 0.08);
  EXPECT_EQ(p.edm.config.find(9)->jump_period_s, 0.0);
  EXPECT_TRUE(p.edm.sim.present);
  EXPECT_EQ(p.edm.sim.surface_mm, -20.0);
  EXPECT_EQ(p.edm.sim.orientation_joints[0], 3);  // B
  EXPECT_EQ(p.edm.sim.work_direction, -1.0);
  // The table's side gap and wear reach the simulated gap, and X, Y are its lateral joints.
  EXPECT_EQ(c->side_gap_mm, 0.012);
  EXPECT_EQ(c->electrode_wear_ratio, 0.08);
  ASSERT_EQ(p.edm.sim.condition_count, 4);
  EXPECT_EQ(p.edm.sim.conditions[2].number, 3);
  EXPECT_EQ(p.edm.sim.conditions[2].side_gap_mm, 0.012);
  EXPECT_EQ(p.edm.sim.conditions[2].electrode_wear_ratio, 0.08);
  EXPECT_EQ(p.edm.sim.lateral_joints[0], 0);
  EXPECT_EQ(p.edm.sim.lateral_joints[1], 1);
  // Issue 28: condition 3 finishes with the cycle and the lateral servo under adaptive control;
  // a bound the profile leaves out is the condition's own value (that setting stays); the
  // simulated gap burns its walls by their rate and knows each condition's reference.
  EXPECT_TRUE(c->orbit_finish);
  EXPECT_TRUE(c->lateral_servo);
  EXPECT_TRUE(c->adaptive);
  EXPECT_EQ(c->gain_min_mm_s_per_v, c->gain_mm_s_per_v);
  EXPECT_EQ(c->gain_max_mm_s_per_v, 0.05);
  EXPECT_EQ(c->jump_height_min_mm, c->jump_height_mm);
  EXPECT_EQ(c->jump_height_max_mm, c->jump_height_mm);
  EXPECT_FALSE(p.edm.config.find(9)->adaptive);
  EXPECT_EQ(p.edm.sim.side_walls, machine::SideWalls::Removal);
  EXPECT_EQ(p.edm.sim.electrode_perimeter_mm, 24.0);
  EXPECT_EQ(p.edm.sim.conditions[2].servo_reference_v, 40.0);
}

/// The line (1-based) of the first line of `text` that starts with `start`, from line `from` on.
std::uint32_t line_of(const std::string& text, const std::string& start, std::uint32_t from = 1) {
  std::uint32_t line = 1;
  for (std::size_t i = 0; i < text.size(); i = text.find('\n', i) + 1, ++line) {
    if (line >= from && text.compare(i, start.size(), start) == 0) return line;
    if (text.find('\n', i) == std::string::npos) break;
  }
  return 0;
}

struct Bad {
  std::string text, key, message;
  std::uint32_t after = 1;  // the key's line is the first at or after this one
};

TEST(EdmProfile, BadConditionsAreNamedWhereTheyAre) {
  const std::string base = kMachine;
  const std::uint32_t second = line_of(base + condition("") + condition(""), "[[edm.condition]]", 22);
  const Bad cases[] = {
      {base + condition("orbit = \"circle\"\norbit_radius_mm = 10\norbit_period_s = 0.1\n"), "orbit_period_s",
       "above the orbit axes' max_velocity"},
      {base + condition("jump_period_s = 0.2\njump_height_mm = 0.5\n"), "jump_period_s",
       "jump_speed_mm_s > 0"},
      {base + condition("") + condition(""), "number", "defined twice", second},
      {base + "[[edm.condition]]\nnumber = 100\n", "number", "number"},
      {base + condition("jump_mode = \"sideways\"\n"), "jump_mode", "must be one of axis, path"},
      {base + condition("short_timeout_s = 0\n"), "short_timeout_s", "must be greater than 0"},
      {std::string(kMachine).replace(base.find("tool_axis"), 0, "short_timeout_s = -1\n") + condition(""),
       "short_timeout_s", "edm.short_timeout_s must be greater than 0"},
      {base + condition("electrode_wear_ratio = 1.5\n"), "electrode_wear_ratio", "must be below 1"},
      {base + condition("side_gap_mm = -0.01\n"), "side_gap_mm", "side_gap_mm"},
      // Issue 28: the finishing cycle needs an orbit; adaptive control's bounds enclose the
      // condition's own value, the reference's stays below the open voltage.
      {base + condition("orbit_finish = true\n"), "orbit_finish", "needs an orbit"},
      // A circle of 2 mm turning in 1 s moves at 12.6 mm/s, within X's and Y's 20; its last turn
      // in the finishing cycle at twice that is not.
      {base + condition("orbit = \"circle\"\norbit_radius_mm = 2\norbit_period_s = 1\norbit_finish = true\n"
                        "lateral_servo = true\n"),
       "lateral_servo", "the finishing cycle's last turn runs the orbit at twice its period's speed, 25.13"},
      {base + condition("adaptive = true\ngain_min_mm_s_per_v = 0.05\n"), "gain_min_mm_s_per_v",
       "must enclose the condition's own value (0.02)"},
      {base + condition("adaptive = true\njump_period_s = 0.2\njump_height_mm = 0.5\njump_speed_mm_s = 20\n"
                        "jump_period_max_s = 0.1\n"),
       "jump_period_max_s", "must enclose"},
      {base + condition("adaptive = true\nservo_reference_max_v = 100\n"), "servo_reference_max_v",
       "must be below voltage_v"},
  };
  for (const Bad& b : cases) {
    const ProfileLoad load = parse_profile(b.text, "edm.toml");
    const Diagnostic* e = first_error(load);
    ASSERT_NE(e, nullptr) << b.text;
    EXPECT_EQ(e->file, "edm.toml");
    EXPECT_EQ(e->code, "config.range") << all_messages(load.diagnostics);
    EXPECT_NE(e->message.find(b.message), std::string::npos) << all_messages(load.diagnostics);
    EXPECT_EQ(e->line, line_of(b.text, b.key, b.after)) << all_messages(load.diagnostics);
    EXPECT_GT(e->col, 0u);
  }
}

// A short's time limit: 5 s unless [edm] says otherwise, and a condition may have its own.
TEST(EdmProfile, TheShortTimeoutComesFromTheConditionOrEdm) {
  ProfileLoad load = parse_profile(std::string(kMachine) + condition(""), "edm.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_EQ(load.profile->edm.config.find(1)->short_timeout_s, 5.0);
  std::string text = kMachine;
  text.replace(text.find("tool_axis"), 0, "short_timeout_s = 2.5\n");
  std::string second = condition("short_timeout_s = 0.8\n");
  second.replace(second.find("number = 1"), 10, "number = 2");
  load = parse_profile(text + condition("") + second, "edm.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_EQ(load.profile->edm.config.find(1)->short_timeout_s, 2.5);
  EXPECT_EQ(load.profile->edm.config.find(2)->short_timeout_s, 0.8);
}

// The EDM's switches: every axis homes on one, X Y Z and B can seek their limit switches; C's
// home mark comes round every turn. A seek that cannot stop within the overtravel, or that has
// no limit switch, or seek keys without seek_velocity, is refused at its key.
TEST(EdmProfile, TheSeekOfALimitStopsWithinItsOvertravel) {
  ProfileLoad load = load_profile(kEdm);
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  for (const AxisProfile& a : load.profile->axes) {
    EXPECT_NE(a.homing.method, HomingMethod::Immediate) << letter(a.axis);
    EXPECT_EQ(a.seek.velocity > 0, a.axis != Axis::C) << letter(a.axis);
  }
  const AxisProfile& x = load.profile->axes[0];
  EXPECT_EQ(x.seek.overtravel, 4.0);
  EXPECT_EQ(x.seek.latch_velocity, 0.5);
  EXPECT_EQ(x.switches.limit_pos.from, 151.0);
  EXPECT_EQ(load.profile->axes[4].switches.home.period, 360.0);
  EXPECT_EQ(x.switches.home.period, 0.0);

  std::string text = std::string(kMachine) + condition("");
  text.replace(text.find("[axis.y]"), 0,
               "[axis.x.switches]\nlimit_max = 11\novertravel = 0.3\nseek_velocity = 20\n");
  load = parse_profile(text, "edm.toml");
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_NE(first_error(load)->message.find(
                "needs 0.44 to stop once the switch trips, more than the overtravel (0.3)"),
            std::string::npos)
      << first_error(load)->message;
  EXPECT_EQ(first_error(load)->line, line_of(text, "seek_velocity"));

  load = load_profile(kEdm, std::vector<std::string>{"axis.c.switches.seek_velocity=10"});
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_NE(first_error(load)->message.find("needs a limit switch"), std::string::npos);
  load = load_profile(kEdm, std::vector<std::string>{"axis.x.switches.seek_latch_velocity=30"});
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_NE(first_error(load)->message.find("exceeds the axis' max_velocity"), std::string::npos)
      << first_error(load)->message;
}

TEST(EdmProfile, TheReferenceMustBeBelowTheOpenVoltageAndTheGeneratorPresent) {
  std::string text = kMachine;
  text +=
      "[[edm.condition]]\nnumber = 1\non_time_us = 100\noff_time_us = 50\npeak_current_a = 10\n"
      "voltage_v = 40\nservo_reference_v = 45\ngain_mm_s_per_v = 0.02\nmax_forward_mm_s = 1\n"
      "max_retract_mm_s = 3\n";
  ProfileLoad load = parse_profile(text, "edm.toml");
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_NE(first_error(load)->message.find("below voltage_v"), std::string::npos);
  EXPECT_EQ(first_error(load)->line, line_of(text, "servo_reference_v"));
  std::string no_generator = kMachine;
  no_generator.replace(no_generator.find("generator = true"), 16, "generator = false");
  load = parse_profile(no_generator + condition(""), "edm.toml");
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_NE(first_error(load)->message.find("generator = true"), std::string::npos);
}

}  // namespace
}  // namespace opencnc::config
