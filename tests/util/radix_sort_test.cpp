#include "util/radix_sort.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

namespace caliber::util {
namespace {

/// Keys below 2^bits, some repeated, in a random order.
std::vector<std::uint64_t> random_keys(std::size_t n, int bits, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  const std::uint64_t top = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  std::vector<std::uint64_t> keys(n);
  for (std::uint64_t& k : keys) k = rng() & top;
  for (std::size_t i = 0; i + 7 < n; i += 7) keys[i + 3] = keys[i];  // repeats
  return keys;
}

TEST(RadixSort, SortsAsStdSortForEveryWidthAndLength) {
  for (const int bits : {0, 1, 7, 11, 12, 23, 32, 33, 34, 49, 63, 64}) {
    for (const std::size_t n : {0u, 1u, 255u, 256u, 257u, 1000u, 5003u}) {
      std::vector<std::uint64_t> keys = random_keys(n, bits, static_cast<std::uint32_t>(bits * 131 + n));
      std::vector<std::uint64_t> want = keys;
      std::sort(want.begin(), want.end());
      std::vector<std::uint64_t> spare;
      radix_sort(keys, bits, spare);
      EXPECT_EQ(keys, want) << bits << " bits, " << n << " keys";
    }
  }
}

TEST(RadixSort, SortsKeysAlreadyInOrderAndReversed) {
  std::vector<std::uint64_t> keys(3000);
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = (keys.size() - i) << 20 | i;
  std::vector<std::uint64_t> want = keys;
  std::sort(want.begin(), want.end());
  std::vector<std::uint64_t> spare;
  radix_sort(keys, bits_of(*std::max_element(keys.begin(), keys.end())), spare);
  EXPECT_EQ(keys, want);
  radix_sort(keys, 40, spare);
  EXPECT_EQ(keys, want);
}

TEST(RadixSort, SortsKeysThatShareADigit) {
  // 33 bits: three digits of 11; the middle one the same in every key (its pass moves nothing).
  std::mt19937_64 rng(7);
  std::vector<std::uint64_t> keys(4000);
  for (std::uint64_t& k : keys) k = (rng() & 0x7ffu) << 22 | std::uint64_t{0x555} << 11 | (rng() & 0x7ffu);
  std::vector<std::uint64_t> want = keys;
  std::sort(want.begin(), want.end());
  std::vector<std::uint64_t> spare;
  radix_sort(keys, 33, spare);
  EXPECT_EQ(keys, want);
}

TEST(RadixSort, BitsOf) {
  EXPECT_EQ(bits_of(0), 0);
  EXPECT_EQ(bits_of(1), 1);
  EXPECT_EQ(bits_of(255), 8);
  EXPECT_EQ(bits_of(256), 9);
  EXPECT_EQ(bits_of(~std::uint64_t{0}), 64);
}

}  // namespace
}  // namespace caliber::util
