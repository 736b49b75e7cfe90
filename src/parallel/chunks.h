#pragma once
/// \file
/// How parallel_for cuts a range: ceil(length / grain) chunks of near-equal length, each at most
/// `grain` long (and at least grain / 2 where the range allows).

#include <cstddef>

namespace caliber::parallel::detail {

/// Calls f(lo, hi) for each chunk of [begin, end) (end > begin, grain >= 1), in order.
template <class F>
void for_each_chunk(std::size_t begin, std::size_t end, std::size_t grain, F&& f) {
  // The same cuts as length * c / chunks, without overflow (length + grain - 1 and length * c can
  // both pass SIZE_MAX).
  const std::size_t length = end - begin, chunks = length / grain + (length % grain != 0);
  const auto at = [&](std::size_t c) {
    return begin + static_cast<std::size_t>(static_cast<unsigned __int128>(length) * c / chunks);
  };
  for (std::size_t c = 0; c < chunks; ++c) f(at(c), at(c + 1));
}

}  // namespace caliber::parallel::detail
