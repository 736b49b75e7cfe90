#pragma once
/// \file
/// How parallel_for cuts a range: ceil(length / grain) chunks of near-equal length, each at most
/// `grain` long (and at least grain / 2 where the range allows).

#include <cstddef>

namespace caliber::parallel::detail {

/// Calls f(lo, hi) for each chunk of [begin, end) (end > begin, grain >= 1), in order.
template <class F>
void for_each_chunk(std::size_t begin, std::size_t end, std::size_t grain, F&& f) {
  const std::size_t length = end - begin, chunks = (length + grain - 1) / grain;
  for (std::size_t c = 0; c < chunks; ++c) f(begin + length * c / chunks, begin + length * (c + 1) / chunks);
}

}  // namespace caliber::parallel::detail
