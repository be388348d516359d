// SPDX-License-Identifier: GPL-3.0-or-later
// [alarms.<name>]: process-input alarms read into plain data (and the simulated inputs' values),
// bad ones rejected at file:line:col.
#include <gtest/gtest.h>

#include <string>

#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {
namespace {

/// One axis and four analog inputs (lines 1–8); tests append from line 9.
const std::string kBase = R"(name = "t"
[axis.x]
max_velocity = 50
max_acceleration = 300
min_limit = -300
max_limit = 300
[io]
analog_inputs = 4
)";

std::string first_error(const ProfileLoad& load) {
  for (const auto& d : load.diagnostics.items()) {
    if (d.severity == Severity::Error) return d.format() + " [" + d.code + "]";
  }
  return "";
}

TEST(Alarms, AreReadInProfileOrderWithTheirSimulatedValues) {
  const ProfileLoad load =
      parse_profile(kBase +
                        "[alarms.level]\ninput = 3\nlow = 40\nhysteresis = 2\nreaction = \"stop\"\n"
                        "sim = 80\n[alarms.oil]\ninput = 1\nhigh = 40\nreaction = \"feed-hold\"\n",
                    "p.toml");
  ASSERT_TRUE(load.ok()) << first_error(load);
  const AlarmProfile& a = load.profile->alarms;
  ASSERT_EQ(a.alarms.count, 2);
  EXPECT_EQ(a.names, (std::vector<std::string>{"level", "oil"}));
  const machine::ProcessAlarm& level = a.alarms.alarms[0];
  EXPECT_EQ(level.channel, 3);
  EXPECT_TRUE(level.has_low);
  EXPECT_FALSE(level.has_high);
  EXPECT_EQ(level.reaction, machine::AlarmReaction::Stop);
  EXPECT_EQ(a.alarms.alarms[1].reaction, machine::AlarmReaction::FeedHold);
  EXPECT_EQ(sim_machine_config(*load.profile).analog_in[3], 80.0);
}

struct Bad {
  const char* name;
  std::string extra;
  std::string error;  ///< the start of the first error
};

class BadAlarm : public ::testing::TestWithParam<Bad> {};

TEST_P(BadAlarm, IsRejectedAtItsPlace) {
  const ProfileLoad load = parse_profile(kBase + GetParam().extra, "p.toml");
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load).rfind(GetParam().error, 0), 0u) << first_error(load);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadAlarm,
    ::testing::Values(
        Bad{"NotAnInput", "[alarms.a]\ninput = 4\nlow = 1\nreaction = \"stop\"\n",
            "p.toml:10:9: error: alarms.a.input (4) is not an analog input"},
        Bad{"NoBound", "[alarms.a]\ninput = 0\nreaction = \"stop\"\n",
            "p.toml:10:9: error: alarms.a needs low"},
        Bad{"UnknownReaction", "[alarms.a]\ninput = 0\nlow = 1\nreaction = \"halt\"\n",
            "p.toml:12:12: error: alarms.a.reaction must be one of message, feed-hold, stop"},
        Bad{"NoReaction", "[alarms.a]\ninput = 0\nlow = 1\n", "p.toml:9:1: error:"},
        Bad{"RangeNarrowerThanHysteresis",
            "[alarms.a]\ninput = 0\nlow = 10\nhigh = 12\nhysteresis = 1.5\nreaction = \"stop\"\n",
            "p.toml:12:8: error: alarms.a: high (12) must be more than low (10) plus twice"},
        Bad{"UnknownKey", "[alarms.a]\ninput = 0\nlow = 1\nreaction = \"stop\"\nlimit = 3\n",
            "p.toml:13:1: error: unknown key 'limit'"},
        Bad{"NotATable", "[alarms]\nlevel = 3\n", "p.toml:9:1: error: alarms.level must be a table"}),
    [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace opencnc::config
