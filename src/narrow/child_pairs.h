#pragma once
/// \file
/// The children of a CD-tree node taken one by one, for the visits that cannot take them four
/// lanes at a time (a taboo list given, or the distance traversal's bounds): their enumeration in
/// cd_children order, the taboo list honoured and each child counted.

#include <cstdint>

#include "bvh/model_data.h"
#include "caliber/query.h"
#include "narrow/cd_tree.h"

namespace caliber::narrow {

/// The node index of a prepared node, held or pointed to.
template <class Side>
std::uint32_t index_of(const Side& side) {
  return side.index;
}
template <class Side>
std::uint32_t index_of(Side* side) {
  return side->index;
}

/// The children of CD-tree node n (not a pair of leaves; descend_a and descend_b from cd_descend), each
/// child node of A and of B prepared once (by prepare_a / prepare_b: the node test's sides, or the
/// distance bound's) for the (up to) four pairs it takes part in: calls test(side_a, side_b,
/// child) for each in cd_children order, except those on the taboo list (skipped and marked
/// reached), each counted in stats.node_tests: the node visit's where one side descends and a
/// taboo list is given, and the distance traversal's.
template <class PrepareA, class PrepareB, class Test>
[[gnu::always_inline]] inline void for_each_child(NodePair n, const BvhNode& a, const BvhNode& b, bool descend_a, bool descend_b,
                                                  QueryStats& stats, TabooView taboo, PrepareA&& prepare_a, PrepareB&& prepare_b,
                                                  Test&& test) {
  decltype(prepare_a(std::uint32_t{})) sa[2];
  decltype(prepare_b(std::uint32_t{})) sb[2];
  const int na = descend_a ? 2 : 1, nb = descend_b ? 2 : 1;
  for (int i = 0; i < na; ++i) sa[i] = prepare_a(descend_a ? a.index + i : n.a);
  for (int j = 0; j < nb; ++j) sb[j] = prepare_b(descend_b ? b.index + j : n.b);
  for (int i = 0; i < na; ++i) {
    for (int j = 0; j < nb; ++j) {
      const NodePair child{index_of(sa[i]), index_of(sb[j])};
      if (on_taboo(taboo, child)) continue;
      ++stats.node_tests;
      test(sa[i], sb[j], child);
    }
  }
}

/// The four children of a visit where both sides descend (A's a0 and a0 + 1 against B's b0 and
/// b0 + 1, in cd_children order) that are not on the taboo list (those marked reached), each
/// counted in stats.node_tests: calls take(k, child) with k = 2i + j, the lane of the four-at-once
/// tests that computed it.
template <class Take>
[[gnu::always_inline]] inline void for_each_child_2x2(std::uint32_t a0, std::uint32_t b0, QueryStats& stats, TabooView taboo,
                                                      Take&& take) {
  for (std::uint32_t k = 0; k < 4; ++k) {
    const NodePair child{a0 + k / 2, b0 + k % 2};
    if (on_taboo(taboo, child)) continue;
    ++stats.node_tests;
    take(k, child);
  }
}

}  // namespace caliber::narrow
