// The cart's merge: light items sorted by weight (a radix sort) and packed into tasks of the
// caliber, heaviest with lightest (plans/calibration.h).

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include "parallel/executor.h"
#include "plans/calibration.h"

namespace caliber::plans {

namespace {

/// A cart item as a sort key (the roots are twice its size).
struct CartKey {
  double weight;
  std::uint32_t pair, a, b, item;
};

/// Carts from this size on are radix-sorted (below, its 2,048-entry counts cost more than comparing).
constexpr std::size_t kRadixFrom = 1024;

bool cart_before(const CartKey& x, const CartKey& y) {
  if (x.weight != y.weight) return x.weight < y.weight;
  if (x.pair != y.pair) return x.pair < y.pair;
  if (x.a != y.a) return x.a < y.a;
  return x.b < y.b;
}

/// Sorts the keys by (weight, pair, a, b) as cart_before does, with a least-significant-digit radix
/// sort: stable passes of 11 bits, the node and pair fields first (unless the keys come in that
/// order already, as a cart of whole pairs does), the weight's bits last; a pass is skipped where
/// every key has the same digit. The weights must be positive and finite: their bits then order as
/// their values do.
void radix_sort(std::vector<CartKey>& keys) {
  constexpr int kBits = 11;
  constexpr std::uint64_t kMask = (1u << kBits) - 1;
  // Digit d of a key: 0-2 b, 3-5 a, 6-8 pair (11, 11 and 10 bits), 9-14 the weight's bits.
  const auto field = [](const CartKey& k, int d) -> std::uint64_t {
    return d >= 9 ? std::bit_cast<std::uint64_t>(k.weight) : d >= 6 ? k.pair : d >= 3 ? k.a : k.b;
  };
  const auto shift = [](int d) { return kBits * (d >= 9 ? d - 9 : d % 3); };
  const bool nodes_in_order = std::is_sorted(keys.begin(), keys.end(), [](const CartKey& x, const CartKey& y) {
    return std::tie(x.pair, x.a, x.b) < std::tie(y.pair, y.a, y.b);
  });
  // The bits that differ between keys, per field.
  std::uint64_t any[4] = {0, 0, 0, 0}, all[4] = {~0ull, ~0ull, ~0ull, ~0ull};
  for (const CartKey& k : keys) {
    for (int f = 0; f < 4; ++f) {
      const std::uint64_t v = field(k, 3 * f);
      any[f] |= v;
      all[f] &= v;
    }
  }
  std::vector<CartKey> other(keys.size());
  std::vector<std::size_t> at(std::size_t{1} << kBits);
  for (int d = nodes_in_order ? 9 : 0; d < 15; ++d) {
    const int f = std::min(d / 3, 3);
    if (((any[f] ^ all[f]) >> shift(d) & kMask) == 0) continue;  // one digit for all
    std::fill(at.begin(), at.end(), 0);
    for (const CartKey& k : keys) ++at[field(k, d) >> shift(d) & kMask];
    std::size_t sum = 0;
    for (std::size_t& bucket : at) sum += std::exchange(bucket, sum);
    for (const CartKey& k : keys) other[at[field(k, d) >> shift(d) & kMask]++] = k;
    keys.swap(other);
  }
}

}  // namespace

std::vector<RunTask> merge_cart(std::vector<Root> cart, double omega) {
  // Sorted as keys by a total order (no two items share pair and node): the same on any number of
  // threads.
  std::vector<CartKey> keys(cart.size());
  bool positive = true;
  for (std::size_t k = 0; k < cart.size(); ++k) {
    keys[k] = CartKey{cart[k].weight, cart[k].pair, cart[k].node.a, cart[k].node.b, static_cast<std::uint32_t>(k)};
    positive = positive && cart[k].weight > 0.0 && cart[k].weight <= std::numeric_limits<double>::max();
  }
  if (positive && keys.size() >= kRadixFrom) {
    radix_sort(keys);
  } else {
    parallel::parallel_sort(keys.begin(), keys.end(), cart_before);
  }
  // Which task each item joins: the heaviest left takes the lightest left until omega.
  std::vector<std::uint32_t> task_of(cart.size());
  std::vector<double> weight;
  std::vector<std::uint32_t> size;
  std::size_t light = 0, heavy = keys.size();
  while (light < heavy) {
    const auto t = static_cast<std::uint32_t>(weight.size());
    task_of[keys[--heavy].item] = t;
    double w = keys[heavy].weight;
    std::uint32_t n = 1;
    while (w < omega && light < heavy) {
      task_of[keys[light].item] = t;
      w += keys[light++].weight;
      ++n;
    }
    weight.push_back(w);
    size.push_back(n);
  }
  // Each task's roots in the cart's order (pair order for whole pairs): a task then walks the
  // pairs' contexts in memory order. The order of a task's roots changes no result.
  std::vector<RunTask> tasks(weight.size());
  for (std::size_t t = 0; t < tasks.size(); ++t) {
    tasks[t].weight = weight[t];
    tasks[t].roots.reserve(size[t]);
  }
  for (std::size_t k = 0; k < cart.size(); ++k) tasks[task_of[k]].roots.push_back(cart[k]);
  return tasks;
}

}  // namespace caliber::plans
