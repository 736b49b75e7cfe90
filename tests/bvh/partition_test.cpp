// The BVH build's cut (bvh/partition.h): a partition of the range, the cheaper side of a clear gap,
// the balance rule, and the same cut whatever the order the triangles come in.

#include <algorithm>
#include <numeric>
#include <random>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/partition.h"

namespace caliber::bvh {
namespace {

/// A small triangle (side 0.1) with its first corner at (x, y, 0).
void add_triangle(Mesh& mesh, double x, double y, double size = 0.1) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.emplace_back(x, y, 0.0);
  mesh.vertices.emplace_back(x + size, y, 0.0);
  mesh.vertices.emplace_back(x, y + size, 0.0);
  mesh.triangles.push_back({base, base + 1, base + 2});
}

struct Cut {
  std::vector<std::uint32_t> order;
  std::uint32_t first = 0;
};

Cut cut(const Mesh& mesh, std::vector<std::uint32_t> order) {
  const std::vector<PartitionItem> all = partition_items(mesh);
  std::vector<PartitionItem> items;  // in the places of `order`, as the build keeps them
  for (const std::uint32_t t : order) items.push_back(all[t]);
  const CentroidBounds bounds = centroid_bounds(items);
  CentroidBounds a, b;
  Cut c;
  c.first = partition_binned(std::span<std::uint32_t>(order), std::span<PartitionItem>(items), bounds, a, b);
  c.order = std::move(order);
  for (std::size_t i = 0; i < c.order.size(); ++i) {  // the items moved with their ids
    for (int k = 0; k < 3; ++k) EXPECT_EQ(items[i].centroid[k], all[c.order[i]].centroid[k]);
  }
  // The boxes returned are those of each part's centroids.
  const CentroidBounds want_a = centroid_bounds(std::span<const PartitionItem>(items).first(c.first));
  const CentroidBounds want_b = centroid_bounds(std::span<const PartitionItem>(items).subspan(c.first));
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.lo[k], want_a.lo[k]);
    EXPECT_EQ(a.hi[k], want_a.hi[k]);
    EXPECT_EQ(b.lo[k], want_b.lo[k]);
    EXPECT_EQ(b.hi[k], want_b.hi[k]);
  }
  return c;
}

std::vector<std::uint32_t> identity(std::size_t n) {
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  return order;
}

TEST(Partition, TwoClustersAreCutApart) {
  Mesh mesh;
  for (int i = 0; i < 40; ++i) add_triangle(mesh, 0.01 * i, 0.0);         // ids 0..39 near x = 0
  for (int i = 0; i < 24; ++i) add_triangle(mesh, 10.0 + 0.01 * i, 0.0);  // ids 40..63 near x = 10
  const Cut c = cut(mesh, identity(64));
  ASSERT_TRUE(c.first == 40 || c.first == 24) << c.first;
  const bool near_first = c.first == 40;
  for (std::uint32_t p = 0; p < 64; ++p) EXPECT_EQ(c.order[p] < 40, (p < c.first) == near_first) << p;
  std::vector<std::uint32_t> sorted = c.order;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, identity(64));  // a permutation of the range
}

TEST(Partition, ALoneOutlierIsNotCutOffAlone) {
  // 100 small triangles in [0, 1] and one far away: every plane between the bins leaves the
  // outlier alone, under the 1/kPartitionBalance share, so the range is cut at its median.
  Mesh mesh;
  for (int i = 0; i < 100; ++i) add_triangle(mesh, 0.01 * i, 0.0);
  add_triangle(mesh, 100.0, 0.0);
  const Cut c = cut(mesh, identity(101));
  const std::uint32_t least = 101 / kPartitionBalance;
  EXPECT_GE(c.first, least);
  EXPECT_LE(c.first, 101 - least);
  EXPECT_EQ(c.first, 50u);  // the median
}

TEST(Partition, TheCutDoesNotDependOnTheOrderGiven) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mesh mesh;
  for (int i = 0; i < 300; ++i) add_triangle(mesh, u(rng) * 3.0, u(rng), 0.05 + 0.1 * (u(rng) + 1.0));
  const Cut in_order = cut(mesh, identity(300));
  std::vector<std::uint32_t> shuffled = identity(300);
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const Cut reordered = cut(mesh, shuffled);
  ASSERT_EQ(in_order.first, reordered.first);
  std::vector<std::uint32_t> a(in_order.order.begin(), in_order.order.begin() + in_order.first);
  std::vector<std::uint32_t> b(reordered.order.begin(), reordered.order.begin() + reordered.first);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);  // the same triangles first
}

}  // namespace
}  // namespace caliber::bvh
