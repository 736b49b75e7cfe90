// The distance traversal's queue: every entry pushed comes out once, lowest bucket first, through
// interleaved pushes and pops and through clear(); a bucket holds the keys between its floor and
// the next bucket's.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <utility>

#include "util/gap_buckets.h"

namespace {

using Buckets = caliber::util::GapBuckets<std::uint32_t>;

TEST(GapBuckets, PopsLowestBucketFirstAndEveryEntryOnce) {
  std::mt19937_64 rng(7);
  Buckets queue;
  for (int round = 0; round < 10; ++round) {
    std::multiset<std::pair<double, std::uint32_t>> ref;
    // Keys over many orders of magnitude, zero and infinity, and runs of equal keys.
    std::uniform_real_distribution<double> exponent(-30.0, 30.0);
    std::uint32_t next_value = 0;
    for (int op = 0; op < 5000; ++op) {
      if (ref.empty() || rng() % 3 != 0) {
        const int kind = static_cast<int>(rng() % 10);
        const double k = kind == 0   ? 0.0
                         : kind == 1 ? std::numeric_limits<double>::infinity()
                         : kind == 2 ? 1.0
                                     : std::pow(10.0, exponent(rng));
        queue.push(k, next_value);
        ref.emplace(k, next_value++);
      } else {
        const std::uint32_t lowest = Buckets::bucket_of(ref.begin()->first);
        ASSERT_EQ(queue.min_bucket(), lowest);
        const auto e = queue.pop();
        ASSERT_EQ(Buckets::bucket_of(e.key), lowest);
        const auto it = ref.find({e.key, e.value});
        ASSERT_NE(it, ref.end()) << "popped an entry not waiting";
        ref.erase(it);
      }
      ASSERT_EQ(queue.empty(), ref.empty());
    }
    if (round % 2 == 0) {
      queue.clear();  // with entries waiting
      EXPECT_TRUE(queue.empty());
      continue;
    }
    while (!ref.empty()) {
      const auto e = queue.pop();
      ASSERT_EQ(Buckets::bucket_of(e.key), Buckets::bucket_of(ref.begin()->first));
      ref.erase(ref.find({e.key, e.value}));
    }
    EXPECT_TRUE(queue.empty());
  }
}

TEST(GapBuckets, ABucketHoldsTheKeysFromItsFloorToTheNext) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> exponent(-300.0, 300.0);
  for (int i = 0; i < 100000; ++i) {
    const double k = std::pow(10.0, exponent(rng));
    const std::uint32_t b = Buckets::bucket_of(k);
    ASSERT_LE(Buckets::floor_of(b), k);
    ASSERT_GT(Buckets::floor_of(b + 1), k);
    // Within a factor 1 + 1/256 of its floor.
    ASSERT_LT(k, Buckets::floor_of(b) * (1.0 + 1.0 / 256.0) * (1.0 + 1e-15));
  }
  EXPECT_EQ(Buckets::bucket_of(0.0), 0u);
  // Keys with the sign bit set come out first, not last.
  EXPECT_EQ(Buckets::bucket_of(-0.0), 0u);
  EXPECT_EQ(Buckets::bucket_of(-1.0), 0u);
  Buckets queue;
  queue.push(1.0, 1);
  queue.push(-0.0, 2);
  EXPECT_EQ(queue.pop().value, 2u);
  EXPECT_LT(Buckets::bucket_of(1.0), Buckets::bucket_of(std::numeric_limits<double>::infinity()));
}

}  // namespace
