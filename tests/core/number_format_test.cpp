// SPDX-License-Identifier: GPL-3.0-or-later
// format_fixed must be byte-identical to printf("%.Nf") — checked on random and tricky values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include "opencnc/core/number_format.hpp"

namespace {

std::string reference(double v, int d) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%.*f", d, v);
  return buf;
}

std::string ours(double v, int d) {
  char buf[opencnc::kFixedBufferSize];
  std::size_t n = opencnc::format_fixed(buf, v, d);
  return std::string(buf, n);
}

TEST(NumberFormat, MatchesPrintfOnExactValues) {
  for (double v : {0.0, -0.0, 1.0, -1.0, 0.5, 1.5, 2.5, 0.00005, 0.00015, 0.00025, -0.00005, 1e-9, -1e-9,
                   123.45675, 0.12345, 9.99995, 99999.99995, 1e15, -1e15, 1e300, 25.4, 1.0 / 3.0}) {
    for (int d : {0, 1, 4, 6, 9}) EXPECT_EQ(ours(v, d), reference(v, d)) << v << " d=" << d;
  }
}

TEST(NumberFormat, MatchesPrintfOnNonFinite) {
  for (double v : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_EQ(ours(v, 4), reference(v, 4));
  }
}

TEST(NumberFormat, MatchesPrintfOnRandomValues) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> mag(-8.0, 8.0);
  std::uniform_int_distribution<int> dec(0, 9);
  for (int i = 0; i < 400000; ++i) {
    double v = std::pow(10.0, mag(rng)) * (rng() & 1 ? 1 : -1);
    int d = (i & 1) ? 4 : dec(rng);
    ASSERT_EQ(ours(v, d), reference(v, d)) << v << " d=" << d;
  }
}

TEST(NumberFormat, MatchesPrintfOnDecimalTies) {
  // Values typed as decimals that sit on a rounding boundary at 4 places (x.xxxx5).
  std::mt19937_64 rng(99);
  for (int i = 0; i < 200000; ++i) {
    long k = static_cast<long>(rng() % 20000000) - 10000000;
    double v = (static_cast<double>(k) * 10 + 5) / 100000.0;
    ASSERT_EQ(ours(v, 4), reference(v, 4)) << v;
  }
}

}  // namespace
