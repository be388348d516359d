// SPDX-License-Identifier: GPL-3.0-or-later
// The one three-vector and the one minimiser every layer uses.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <span>

#include "opencnc/core/minimise.hpp"
#include "opencnc/core/vec3.hpp"

namespace opencnc {
namespace {

TEST(Vec3, ArithmeticIsTheTextbooks) {
  const Vec3 a{1, 2, 3}, b{-4, 5, 0.5};
  EXPECT_EQ(a + b, (Vec3{-3, 7, 3.5}));
  EXPECT_EQ(a - b, (Vec3{5, -3, 2.5}));
  EXPECT_EQ(2.0 * a, (Vec3{2, 4, 6}));
  EXPECT_DOUBLE_EQ(dot(a, b), -4 + 10 + 1.5);
  EXPECT_EQ(cross(Vec3{1, 0, 0}, Vec3{0, 1, 0}), (Vec3{0, 0, 1}));  // right-handed
  EXPECT_EQ(cross(a, a), (Vec3{0, 0, 0}));
  EXPECT_DOUBLE_EQ(norm(Vec3{3, 4, 12}), 13);
}

TEST(Vec3, TakesAndPutsThreeAxesOfAPose) {
  Pose p;
  for (int i = 0; i < kAxisCount; ++i) p[i] = i;
  EXPECT_EQ(take3(p), (Vec3{0, 1, 2}));
  EXPECT_EQ(take3(p, 6), (Vec3{6, 7, 8}));
  put3(p, 6, Vec3{-1, -2, -3});
  EXPECT_EQ(p[6], -1);
  EXPECT_EQ(p[8], -3);
  EXPECT_EQ(p[5], 5);  // the others untouched
}

TEST(Vec3, IsARangeOfThreeDoubles) {
  Vec3 v{1, 2, 3};
  double sum = 0;
  for (double x : v) sum += x;
  EXPECT_EQ(sum, 6);
  const std::span<const double> s(v);
  EXPECT_EQ(s.size(), 3u);
  EXPECT_EQ(s[2], 3);
}

TEST(GoldenSection, FindsTheMinimumOfAUnimodalFunction) {
  int calls = 0;
  const auto f = [&](double x) {
    ++calls;
    return (x - 0.3) * (x - 0.3) + 2;
  };
  const Minimum m = golden_section(f, -1, 2, 200, 1e-12);
  EXPECT_NEAR(m.x, 0.3, 1e-6);
  EXPECT_NEAR(m.f, 2, 1e-12);
  EXPECT_LT(calls, 80);  // one evaluation a step: the interval shrinks by 0.618 each
}

TEST(GoldenSection, StopsAfterTheStepsAllowed) {
  int calls = 0;
  const auto f = [&](double x) {
    ++calls;
    return std::cos(x);
  };
  golden_section(f, 0, 2 * std::numbers::pi, 5, 0);
  EXPECT_EQ(calls, 2 + 5);
}

}  // namespace
}  // namespace opencnc
