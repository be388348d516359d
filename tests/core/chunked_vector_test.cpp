// SPDX-License-Identifier: GPL-3.0-or-later
// ChunkedVector keeps order and element addresses across chunk boundaries.
#include <gtest/gtest.h>

#include "opencnc/core/chunked_vector.hpp"

TEST(ChunkedVector, StoresAcrossChunks) {
  opencnc::ChunkedVector<int, 4> v;  // 16 elements per chunk
  const int* first = &v.push_back(7);
  for (int i = 1; i < 1000; ++i) v.push_back(i * 3);
  EXPECT_EQ(v.size(), 1000u);
  EXPECT_EQ(&v[0], first);
  EXPECT_EQ(v[0], 7);
  EXPECT_EQ(v[999], 2997);
  EXPECT_EQ(v.back(), 2997);
  EXPECT_EQ(v.capacity_bytes(), 63u * 16 * sizeof(int));
  v.clear();
  EXPECT_TRUE(v.empty());
}

TEST(ChunkedVector, AppendsRunsAndSlotsAcrossChunks) {
  opencnc::ChunkedVector<int, 3> v;  // 8 elements per chunk: runs of 3 straddle chunk ends
  int next = 0;
  for (int run = 0; run < 20; ++run) {
    v.append_slot() = next++;
    v.append_with(3, [&](std::size_t i) { return next + static_cast<int>(i); });
    next += 3;
  }
  ASSERT_EQ(v.size(), 80u);
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], static_cast<int>(i));
}

TEST(ChunkedVector, ReleasesWholeChunksBeforeAnIndexAndKeepsIndices) {
  opencnc::ChunkedVector<int, 3> v;  // 8 elements per chunk
  for (int i = 0; i < 40; ++i) v.push_back(i);
  EXPECT_EQ(v.capacity_bytes(), 5u * 8 * sizeof(int));
  EXPECT_EQ(v.release_before(19), 16u);  // chunks 0 and 1 freed; 16..19 share a chunk with what stays
  EXPECT_EQ(v.first_held(), 16u);
  EXPECT_EQ(v.capacity_bytes(), 3u * 8 * sizeof(int));
  EXPECT_EQ(v[16], 16);
  EXPECT_EQ(v[39], 39);
  EXPECT_EQ(v.size(), 40u);
  EXPECT_EQ(v.release_before(100), 32u);  // never the chunk being filled
  for (int i = 40; i < 48; ++i) v.push_back(i);  // the freed chunk is used again
  EXPECT_EQ(v[47], 47);
  EXPECT_EQ(v[33], 33);
}
