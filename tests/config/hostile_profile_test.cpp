// SPDX-License-Identifier: GPL-3.0-or-later
// Hostile profiles and overrides (issue 7): physically absurd limits, a folder or an unreadable
// file as the profile, numbers an override cannot hold, fractions where a whole number belongs.
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {
namespace {

const std::string kMill = std::string(OPENCNC_SOURCE_DIR) + "/configs/mill-3axis.toml";

const Diagnostic* first_error(const ProfileLoad& load) {
  for (const auto& d : load.diagnostics.items()) {
    if (d.severity == Severity::Error) return &d;
  }
  return nullptr;
}

ProfileLoad with(std::vector<std::string> sets) {
  return load_profile(kMill, sets);
}

TEST(HostileProfile, AbsurdDynamicLimitsAreRefusedAtTheirKey) {
  const struct {
    std::string set;
    std::uint32_t col;
  } cases[] = {
      {"axis.x.max_velocity=1e-300", 21},     {"axis.x.max_velocity=1e300", 21},
      {"axis.y.max_acceleration=1e-300", 25}, {"axis.y.max_acceleration=1e300", 25},
      {"axis.z.max_jerk=1e-300", 17},         {"axis.z.max_jerk=1e300", 17},
      {"axis.x.min_limit=-1e12", 18},         {"axis.x.max_limit=1e300", 18},
  };
  for (const auto& c : cases) {
    const ProfileLoad load = with({c.set});
    EXPECT_FALSE(load.ok()) << c.set;
    const Diagnostic* e = first_error(load);
    ASSERT_NE(e, nullptr) << c.set;
    EXPECT_EQ(e->code, "config.implausible") << c.set << ": " << e->format();
    EXPECT_EQ(e->format().rfind("--set:1:" + std::to_string(c.col) + ": error: ", 0), 0u) << e->format();
  }
}

TEST(HostileProfile, PlausibleLimitsPass) {
  for (const std::string set :
       {"axis.x.max_velocity=0.01", "axis.x.max_velocity=50000", "axis.x.max_acceleration=200000",
        "axis.x.max_jerk=0", "axis.x.max_jerk=1e9"}) {
    const ProfileLoad load = with({set});
    EXPECT_TRUE(load.ok()) << set << ": " << (first_error(load) ? first_error(load)->format() : "");
  }
}

TEST(HostileProfile, NotANumberAndInfinityAreRefused) {
  for (const std::string set :
       {"axis.x.max_velocity=nan", "axis.x.max_acceleration=inf", "axis.x.min_limit=-inf"}) {
    const ProfileLoad load = with({set});
    ASSERT_NE(first_error(load), nullptr) << set;
    EXPECT_EQ(first_error(load)->code, "config.range") << set;
  }
}

TEST(HostileProfile, ANumberTooLargeForADoubleIsATomlErrorNotAString) {
  const ProfileLoad load = with({"axis.x.max_velocity=1e999"});
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_EQ(first_error(load)->code, "config.override");
  EXPECT_NE(first_error(load)->message.find("1e999"), std::string::npos);
  EXPECT_EQ(first_error(load)->message.find("string"), std::string::npos) << first_error(load)->message;
  // A bare word is still a string.
  EXPECT_TRUE(with({"interpreter.dialect=fanuc"}).ok());
}

TEST(HostileProfile, AFractionWhereAWholeNumberBelongsSaysItsValue) {
  const ProfileLoad load = with({"planner.lookahead=2.5"});
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_EQ(first_error(load)->message, "planner.lookahead must be a whole number (it is 2.5)");
}

TEST(HostileProfile, ADriveTooWeakForTheVelocityIsAWarning) {
  const ProfileLoad load = with({"axis.x.max_velocity=90000"});
  ASSERT_TRUE(load.ok());
  bool warned = false;
  for (const auto& d : load.diagnostics.items()) warned = warned || d.code == "config.drive-too-weak";
  EXPECT_TRUE(warned);
}

TEST(HostileProfile, AFolderIsNotAProfileWithoutAName) {
  const std::string dir = std::filesystem::temp_directory_path().string();
  const ProfileLoad load = load_profile(dir);
  ASSERT_NE(first_error(load), nullptr);
  EXPECT_EQ(first_error(load)->code, "config.file");
  EXPECT_EQ(first_error(load)->format(),
            dir + ": error: cannot read the profile: it is a folder, not a file");
}

TEST(HostileProfile, AnUnreadableProfileSaysWhy) {
  const ProfileLoad missing = load_profile("/no/such/profile.toml");
  ASSERT_NE(first_error(missing), nullptr);
  EXPECT_EQ(first_error(missing)->message, "cannot read the profile: No such file or directory");
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files whatever their mode";
  const std::string p =
      std::filesystem::temp_directory_path() / ("locked-" + std::to_string(::getpid()) + ".toml");
  std::ofstream(p) << "name = \"x\"\n";
  ::chmod(p.c_str(), 0);
  const ProfileLoad locked = load_profile(p);
  std::filesystem::remove(p);
  ASSERT_NE(first_error(locked), nullptr);
  EXPECT_EQ(first_error(locked)->message, "cannot read the profile: Permission denied");
}

}  // namespace
}  // namespace opencnc::config
