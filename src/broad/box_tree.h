#pragma once
/// \file
/// The broad phase's structure: the objects' world boxes sorted along a Morton curve of their
/// centres, a binary tree of boxes over that order partitioned where the curve's codes differ (as a linear
/// BVH's), and the pairs whose boxes overlap found by querying each leaf's boxes together against
/// the part of the tree that lies after them in that order (so each pair is met once), in parallel
/// on the executor the caller runs in. The order only steers the pruning:
/// the pairs are those whose boxes overlap (closed intervals on the three axes), whatever it is.
/// Kept from frame to frame: the order is re-sorted only when refitting the tree over the old one
/// has let its boxes grow (temporal coherence), and the buffers are reused.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "broad/world_box.h"
#include "caliber/engine.h"

namespace caliber::broad {

/// Which pairs the caller does not want: two fixed objects, or an ignored pair.
struct PairFilter {
  const std::vector<bool>* fixed = nullptr;             ///< null or one flag per object
  const std::vector<std::uint64_t>* ignored = nullptr;  ///< sorted (a << 32 | b), or null
};

/// A box as the tree stores it (the WorldBox's corners, without Eigen's alignment rules).
struct FlatBox {
  double lo[3];
  double hi[3];
};

class BoxTree {
 public:
  /// Sets `out` to the sorted pairs (a < b) whose boxes overlap and that `filter` keeps. Reuses
  /// the previous call's order when there were as many boxes.
  void pairs(std::span<const WorldBox> boxes, const PairFilter& filter, std::vector<ObjectPair>& out);

 private:
  /// A node: its box and its run of positions; its first child follows it, `right` is its second
  /// (0 for a leaf).
  struct Node {
    FlatBox box;
    std::uint32_t first, count, right;
  };

  void sort_order(std::span<const WorldBox> boxes);
  void build_nodes(std::uint32_t first, std::uint32_t count);
  void refit();
  [[nodiscard]] double node_area() const;
  void collect(const PairFilter& filter, std::size_t objects, std::vector<ObjectPair>& out);

  std::vector<std::uint32_t> mOrder;               ///< object at each position
  std::vector<std::uint32_t> mScratch;             ///< the radix sort's other buffer
  std::vector<std::uint32_t> mCodes;               ///< Morton code per object
  std::vector<FlatBox> mSorted;                    ///< box per position
  std::vector<Node> mNodes;                        ///< the tree in preorder (the root first)
  std::vector<std::uint32_t> mLeaves;              ///< the leaves (node indices), in position order
  double mSortedArea = 0.0;                        ///< the tree's node area right after the last sort
  std::vector<std::vector<std::uint64_t>> mFound;  ///< per chunk of positions: pairs (a << 32 | b)
  std::vector<std::uint32_t> mStart;               ///< counting sort by a
};

}  // namespace caliber::broad
