#pragma once
/// \file
/// Where the BVH build cuts a node's triangles in two: a binned surface-area heuristic over the
/// triangles' centroids. A heuristic only: whatever the cut, the build bounds each child around
/// its own vertices, so the choice changes how much the node tests prune, never what a query
/// reports. Deterministic: the cut depends only on the triangles and their order in the range.

#include <cstdint>
#include <span>
#include <vector>

#include "caliber/mesh.h"

namespace caliber::bvh {

/// What the partition reads of a triangle: its centroid and its box, in floats (the cost is a
/// heuristic), each padded to four lanes for vector minima and maxima.
struct PartitionItem {
  alignas(16) float centroid[4];
  alignas(16) float lo[4];
  alignas(16) float hi[4];
};

/// The box of a range's centroids (lane 3 unused).
struct CentroidBounds {
  alignas(16) float lo[4];
  alignas(16) float hi[4];
};

/// Bins per axis: the planes tried are the 7 between 8 equal bins of the centroids' range, on each
/// axis. Against 16 and 32 (node tests of bench_fcl_compare's and bench_fcl_distance's cases):
/// more bins saved a little on the interference node tests but made the turbine and blade's
/// distance query at gap 1e-6 test far more nodes (bench/results/intel-xeon-2c/kernels/README.md).
inline constexpr int kPartitionBins = 8;
/// A cut leaves each side at least 1/kPartitionBalance of the triangles, so the tree's height stays
/// within log base 16/15 of the count (where no plane does, the range is cut at its median).
inline constexpr std::uint32_t kPartitionBalance = 16;

/// The partition items of every triangle of `mesh`, item t for triangle t (in parallel, on the
/// caller's executor).
[[nodiscard]] std::vector<PartitionItem> partition_items(const Mesh& mesh);

/// The box of the centroids of `items` (not empty).
[[nodiscard]] CentroidBounds centroid_bounds(std::span<const PartitionItem> items);

/// Reorders `order` (triangle ids, at least two) and `items` (their partition items, in the same
/// places: the two move together, so every pass reads the items in memory order) so that the
/// first part comes first, and returns its size (1 to order.size() - 1), with the boxes of each
/// part's centroids; `bounds` is the box of all of them. The cut: the plane among kPartitionBins - 1
/// per axis that minimizes the surface-area cost (each side's box area times its count), of those
/// that leave each side at least 1/kPartitionBalance; where none does, the median along the
/// centroids' longest axis (ties by id).
[[nodiscard]] std::uint32_t partition_binned(std::span<std::uint32_t> order, std::span<PartitionItem> items,
                                             const CentroidBounds& bounds, CentroidBounds& first, CentroidBounds& second);

}  // namespace caliber::bvh
