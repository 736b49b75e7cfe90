#pragma once
/// \file
/// An LSD radix sort of unsigned integers: a pass per digit, each a count and a stable scatter,
/// with no comparison of keys and so no branch that depends on them (a comparison sort of
/// scattered ids mispredicts about every other comparison).

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace caliber::util {

/// Sorts `keys` ascending, every one below 2^bits (bits <= 64): ceil(bits / 11) passes of digits
/// of equal width; `spare` is scratch (resized to keys.size()). Short inputs go to std::sort.
inline void radix_sort(std::vector<std::uint64_t>& keys, int bits, std::vector<std::uint64_t>& spare) {
  constexpr std::size_t kShort = 256;
  constexpr int kMostDigitBits = 11;
  if (keys.size() < kShort || bits <= 0) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  const int passes = (bits + kMostDigitBits - 1) / kMostDigitBits;
  const int width = (bits + passes - 1) / passes;
  const std::uint64_t mask = (std::uint64_t{1} << width) - 1;
  spare.resize(keys.size());
  std::array<std::uint32_t, std::size_t{1} << kMostDigitBits> count;
  for (int shift = 0; shift < bits; shift += width) {
    std::fill(count.begin(), count.begin() + static_cast<std::ptrdiff_t>(mask + 1), 0u);
    for (const std::uint64_t k : keys) ++count[(k >> shift) & mask];
    std::uint32_t at = 0;
    for (std::uint64_t d = 0; d <= mask; ++d) {
      const std::uint32_t c = count[d];
      count[d] = at;
      at += c;
    }
    for (const std::uint64_t k : keys) spare[count[(k >> shift) & mask]++] = k;
    keys.swap(spare);
  }
}

/// The bits an unsigned value needs (0 for 0).
inline int bits_of(std::uint64_t v) { return v == 0 ? 0 : 64 - std::countl_zero(v); }

}  // namespace caliber::util
