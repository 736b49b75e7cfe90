#pragma once
/// \file
/// A plain sort and prune along x over world boxes: the reference the broad phase's tree is
/// checked against (tests/world/broad_phase_test.cpp) and measured against (bench/broad_phase.cpp).
/// Not part of the library.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "broad/world_box.h"
#include "caliber/engine.h"

namespace caliber::test {

/// Whether two boxes overlap (closed intervals on the three axes).
inline bool boxes_overlap(const broad::WorldBox& x, const broad::WorldBox& y) {
  return (x.lo.array() <= y.hi.array()).all() && (y.lo.array() <= x.hi.array()).all();
}

/// The pairs (a < b, sorted) whose boxes overlap: sorted by low x, each box against those that
/// start before it ends along x.
inline std::vector<ObjectPair> pairs_by_x_sort(const std::vector<broad::WorldBox>& boxes) {
  std::vector<std::uint32_t> order(boxes.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return boxes[a].lo.x() < boxes[b].lo.x() || (boxes[a].lo.x() == boxes[b].lo.x() && a < b);
  });
  std::vector<ObjectPair> pairs;
  for (std::size_t i = 0; i < order.size(); ++i) {
    for (std::size_t j = i + 1; j < order.size() && boxes[order[j]].lo.x() <= boxes[order[i]].hi.x(); ++j) {
      if (boxes_overlap(boxes[order[i]], boxes[order[j]])) {
        pairs.push_back({std::min(order[i], order[j]), std::max(order[i], order[j])});
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace caliber::test
