// SPDX-License-Identifier: GPL-3.0-or-later
// Axis exchange maps: reading "X=Y,Y=X", completing half-named exchanges, refusing bad maps.
#include <gtest/gtest.h>

#include "opencnc/core/axis_map.hpp"

using namespace opencnc;

TEST(AxisMap, ReadsExchangesAndWritesThemBack) {
  AxisMap m = identity_axis_map();
  EXPECT_EQ(parse_axis_map("X=Y,Y=X", m), "");
  EXPECT_EQ(m[0], Axis::Y);
  EXPECT_EQ(m[1], Axis::X);
  EXPECT_EQ(m[2], Axis::Z);
  EXPECT_EQ(format_axis_map(m), "X=Y,Y=X");
  EXPECT_EQ(parse_axis_map(" z = x , x=z ", m), "");
  EXPECT_EQ(format_axis_map(m), "X=Z,Z=X");
  EXPECT_EQ(parse_axis_map("", m), "");
  EXPECT_EQ(m, identity_axis_map());
}

TEST(AxisMap, AHalfNamedExchangeIsCompleted) {
  AxisMap m{};
  EXPECT_EQ(parse_axis_map("X=U", m), "");
  EXPECT_EQ(m[index(Axis::X)], Axis::U);
  EXPECT_EQ(m[index(Axis::U)], Axis::X);
  EXPECT_EQ(parse_axis_map("X=Y,Y=Z", m), "");   // a rotation of three letters
  EXPECT_EQ(m[index(Axis::Z)], Axis::X);
  EXPECT_EQ(parse_axis_map("A=C", m), "");
  EXPECT_EQ(m[index(Axis::C)], Axis::A);
}

TEST(AxisMap, RefusesWhatIsNotAnExchange) {
  AxisMap m = identity_axis_map();
  EXPECT_NE(parse_axis_map("X=Q", m), "");
  EXPECT_NE(parse_axis_map("X", m), "");
  EXPECT_NE(parse_axis_map("X=Y,X=Z", m), "");
  EXPECT_NE(parse_axis_map("X=Z,Y=Z", m), "");
  EXPECT_NE(parse_axis_map("X=A", m), "");
  EXPECT_EQ(m, identity_axis_map());   // unchanged after an error
}
