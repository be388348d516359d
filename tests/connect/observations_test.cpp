// SPDX-License-Identifier: GPL-3.0-or-later
// The observation buffer: sequence numbers over a bounded buffer, conditions, the state at a point.
#include <gtest/gtest.h>

#include "opencnc/connect/observations.hpp"

namespace opencnc::connect {
namespace {

Observation value(std::uint32_t item, std::string v) {
  Observation o;
  o.item = item;
  o.value = std::move(v);
  return o;
}

Observation condition(std::uint32_t item, Level level, std::string code) {
  Observation o;
  o.item = item;
  o.level = level;
  o.native_code = std::move(code);
  return o;
}

TEST(ObservationBuffer, NumbersObservationsAndForgetsTheOldestWhenFull) {
  ObservationBuffer b(2, 3);
  EXPECT_EQ(b.first_sequence(), 1u);
  EXPECT_EQ(b.next_sequence(), 1u);
  EXPECT_EQ(b.current()[0].last.value, "UNAVAILABLE");
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(b.add(value(static_cast<std::uint32_t>(i % 2), std::to_string(i))), i + 1u);
  EXPECT_EQ(b.first_sequence(), 3u);
  EXPECT_EQ(b.last_sequence(), 5u);
  EXPECT_EQ(b.next_sequence(), 6u);
  EXPECT_EQ(b.size(), 3u);
  EXPECT_EQ(b.at(3).value, "2");
  EXPECT_THROW((void)b.at(2), std::out_of_range);
  EXPECT_EQ(b.current()[0].last.value, "4");
  EXPECT_EQ(b.current()[1].last.value, "3");
}

TEST(ObservationBuffer, TheStateAtARetainedSequenceReplaysFromBeforeTheOldest) {
  ObservationBuffer b(2, 3);
  for (int i = 0; i < 6; ++i) b.add(value(static_cast<std::uint32_t>(i % 2), std::to_string(i)));
  // Retained: 4 ("3", item 1), 5 ("4", item 0), 6 ("5", item 1); before them item 0 = "2", item 1 = "1".
  auto before = b.state_at(3);
  EXPECT_EQ(before[0].last.value, "2");
  EXPECT_EQ(before[1].last.value, "1");
  auto at5 = b.state_at(5);
  EXPECT_EQ(at5[0].last.value, "4");
  EXPECT_EQ(at5[1].last.value, "3");
  EXPECT_EQ(b.state_at(6)[1].last.value, "5");
  EXPECT_THROW((void)b.state_at(2), std::out_of_range);
  EXPECT_THROW((void)b.state_at(7), std::out_of_range);
}

TEST(ObservationBuffer, ConditionsAreActiveByNativeCodeUntilANormalClearsThem) {
  ObservationBuffer b(1, 10);
  b.add(condition(0, Level::Warning, "a"));
  b.add(condition(0, Level::Fault, "b"));
  ASSERT_EQ(b.current()[0].active.size(), 2u);
  b.add(condition(0, Level::Fault, "a"));  // the same condition worsens
  ASSERT_EQ(b.current()[0].active.size(), 2u);
  EXPECT_EQ(b.current()[0].active[0].level, Level::Fault);
  b.add(condition(0, Level::Normal, "a"));
  ASSERT_EQ(b.current()[0].active.size(), 1u);
  EXPECT_EQ(b.current()[0].active[0].native_code, "b");
  b.add(condition(0, Level::Normal, ""));  // a Normal without a code clears them all
  EXPECT_TRUE(b.current()[0].active.empty());
  EXPECT_EQ(b.state_at(2)[0].active.size(), 2u);
}

}  // namespace
}  // namespace opencnc::connect
