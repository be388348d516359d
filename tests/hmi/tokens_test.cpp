// SPDX-License-Identifier: GPL-3.0-or-later
// HMI tokens: written once, owner-only, read back the same; a readable or malformed file refused;
// the environment's pair; roles by token.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "opencnc/hmi/tokens.hpp"

namespace opencnc::hmi {
namespace {

std::filesystem::path fresh_dir(const char* name) {
  const auto d = std::filesystem::temp_directory_path() /
                 (std::string("opencnc-tokens-") + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

TEST(Tokens, GeneratedOnceIntoAnOwnerOnlyFile) {
  ::unsetenv("OPENCNC_OPERATOR_TOKEN");
  ::unsetenv("OPENCNC_ADMIN_TOKEN");
  const auto dir = fresh_dir("gen");
  std::string error;
  const auto a = Tokens::load(dir / "tokens", &error);
  ASSERT_TRUE(a) << error;
  struct stat st {};
  ASSERT_EQ(::stat((dir / "tokens").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(a->operator_token().size(), 48u);
  EXPECT_NE(a->operator_token(), a->admin_token());
  const auto b = Tokens::load(dir / "tokens", &error);
  ASSERT_TRUE(b) << error;
  EXPECT_EQ(b->operator_token(), a->operator_token());
  EXPECT_EQ(b->admin_token(), a->admin_token());
  EXPECT_EQ(b->role_of(a->admin_token()), Role::Admin);
  EXPECT_EQ(b->role_of(a->operator_token()), Role::Operator);
  EXPECT_FALSE(b->role_of(""));
  EXPECT_FALSE(b->role_of(a->operator_token().substr(1)));
}

TEST(Tokens, AFileOthersMayReadOrAMalformedOneIsRefused) {
  ::unsetenv("OPENCNC_OPERATOR_TOKEN");
  ::unsetenv("OPENCNC_ADMIN_TOKEN");
  const auto dir = fresh_dir("bad");
  const auto path = dir / "tokens";
  std::ofstream(path) << "operator 0123456789abcdef0123\nadmin fedcba9876543210fedc\n";
  ::chmod(path.c_str(), 0644);
  std::string error;
  EXPECT_FALSE(Tokens::load(path, &error));
  EXPECT_NE(error.find("others may read it"), std::string::npos) << error;
  ::chmod(path.c_str(), 0600);
  EXPECT_TRUE(Tokens::load(path, &error)) << error;
  std::ofstream(path) << "operator short\n";
  EXPECT_FALSE(Tokens::load(path, &error));
  EXPECT_NE(error.find(":1:1: expected"), std::string::npos) << error;
}

TEST(Tokens, TheEnvironmentWinsWhenBothAreSet) {
  const auto dir = fresh_dir("env");
  ::setenv("OPENCNC_OPERATOR_TOKEN", "operator-token-0123456789", 1);
  std::string error;
  EXPECT_FALSE(Tokens::load(dir / "tokens", &error));  // only one of the two
  ::setenv("OPENCNC_ADMIN_TOKEN", "admin-token-0123456789abc", 1);
  const auto t = Tokens::load(dir / "tokens", &error);
  ::unsetenv("OPENCNC_OPERATOR_TOKEN");
  ::unsetenv("OPENCNC_ADMIN_TOKEN");
  ASSERT_TRUE(t) << error;
  EXPECT_EQ(t->origin(), "environment");
  EXPECT_EQ(t->role_of("admin-token-0123456789abc"), Role::Admin);
  EXPECT_FALSE(std::filesystem::exists(dir / "tokens"));
}

}  // namespace
}  // namespace opencnc::hmi
