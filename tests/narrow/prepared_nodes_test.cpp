// The distance traversal's cache of prepared nodes: each node prepared once per traversal, the
// right entry for each index whatever the table's growth, entries that stay put while others are
// added, and nothing left over after clear().

#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "narrow/traversal.h"

namespace caliber::narrow {
namespace {

struct Entry {
  std::uint32_t index;
  double value;
};

TEST(PreparedNodes, EachIndexPreparedOnceAndFoundAgain) {
  PreparedNodes<Entry> cache;
  std::vector<int> made(200000, 0);
  const auto prepare = [&](std::uint32_t i) {
    ++made[i];
    return Entry{i, 0.5 * i};
  };
  std::mt19937 rng(9);
  std::uniform_int_distribution<std::uint32_t> pick(0, 199999);
  std::vector<std::uint32_t> asked;
  std::vector<const Entry*> first;
  for (int round = 0; round < 2; ++round) {
    cache.clear();
    std::fill(made.begin(), made.end(), 0);
    asked.clear();
    first.clear();
    for (int k = 0; k < 5000; ++k) {  // the table grows from 64 slots several times
      const std::uint32_t i = pick(rng);
      const Entry& e = cache.get(i, prepare);
      ASSERT_EQ(e.index, i);
      ASSERT_EQ(e.value, 0.5 * i);
      asked.push_back(i);
      first.push_back(&e);
    }
    for (std::size_t k = 0; k < asked.size(); ++k) {
      const Entry& again = cache.get(asked[k], prepare);
      EXPECT_EQ(&again, first[k]) << "an entry stays where it was made";
      EXPECT_EQ(made[asked[k]], 1) << "index " << asked[k] << " prepared once";
    }
  }
}

TEST(PreparedNodes, ClearForgetsEveryEntry) {
  PreparedNodes<Entry> cache;
  int made = 0;
  const auto prepare = [&](std::uint32_t i) {
    ++made;
    return Entry{i, double(made)};
  };
  EXPECT_EQ(cache.get(7, prepare).value, 1.0);
  EXPECT_EQ(cache.get(7, prepare).value, 1.0);
  cache.clear();
  EXPECT_EQ(cache.get(7, prepare).value, 2.0) << "made again after clear: a prepared node belongs to one pose";
  EXPECT_EQ(made, 2);
}

}  // namespace
}  // namespace caliber::narrow
