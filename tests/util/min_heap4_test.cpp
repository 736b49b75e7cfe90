// The distance traversal's 4-ary heap: every pop gives the smallest key waiting, against a sorted
// multiset of the same entries, through interleaved pushes and pops and through clear().

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>
#include <utility>

#include "util/min_heap4.h"

namespace {

TEST(MinHeap4, PopsInKeyOrderThroughInterleavedPushesAndPops) {
  std::mt19937_64 rng(7);
  for (int round = 0; round < 20; ++round) {
    caliber::util::MinHeap4<std::uint32_t> heap;
    std::multiset<std::pair<double, std::uint32_t>> ref;
    // Few distinct keys in some rounds, so that ties are common.
    std::uniform_int_distribution<int> key(0, round % 2 == 0 ? 5 : 1000000);
    std::uint32_t next_value = 0;
    for (int op = 0; op < 5000; ++op) {
      if (ref.empty() || rng() % 3 != 0) {
        const double k = key(rng) * 0.5;
        heap.push(k, next_value);
        ref.emplace(k, next_value++);
      } else {
        ASSERT_EQ(heap.top().key, ref.begin()->first);
        const auto e = heap.pop();
        ASSERT_EQ(e.key, ref.begin()->first);
        // The entry popped is one of those with the smallest key, popped once.
        const auto it = ref.find({e.key, e.value});
        ASSERT_NE(it, ref.end());
        ref.erase(it);
      }
      ASSERT_EQ(heap.size(), ref.size());
    }
    while (!ref.empty()) {
      const auto e = heap.pop();
      ASSERT_EQ(e.key, ref.begin()->first);
      const auto it = ref.find({e.key, e.value});
      ASSERT_NE(it, ref.end());
      ref.erase(it);
    }
    EXPECT_TRUE(heap.empty());
  }
}

TEST(MinHeap4, ClearForgetsEverything) {
  caliber::util::MinHeap4<int> heap;
  for (int i = 100; i > 0; --i) heap.push(i, i);
  heap.clear();
  EXPECT_TRUE(heap.empty());
  heap.push(3.0, 3);
  heap.push(1.0, 1);
  heap.push(2.0, 2);
  EXPECT_EQ(heap.pop().value, 1);
  EXPECT_EQ(heap.pop().value, 2);
  EXPECT_EQ(heap.pop().value, 3);
  EXPECT_TRUE(heap.empty());
}

}  // namespace
