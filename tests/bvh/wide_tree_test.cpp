// The wide tree (bvh/wide_tree.h): every wide node's slots are BVH nodes below it whose runs of
// leaves split its own, in order; every leaf and every wide node is one slot (the root's is the
// root); each slot's float box is the tightest float box around its BVH box; the nodes are well
// filled.

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "bvh/wide_tree.h"
#include "caliber/model.h"
#include "caliber/procedural.h"

namespace caliber {
namespace {

/// The first broken property of m's wide tree, in words (empty when none).
std::string wide_problem(const ModelData& m) {
  if (m.wide_of.size() != m.nodes.size()) return "wide_of is not one a node";
  std::vector<int> seen(m.nodes.size(), 0);
  seen[0] = 1;
  for (std::uint32_t i = 0; i < m.nodes.size(); ++i) {
    const std::uint32_t w = m.wide_of[i];
    if (m.nodes[i].is_leaf() && w != WideNode::kEmpty) return "a leaf has a wide node";
    if (w == WideNode::kEmpty) continue;
    const WideNode& node = m.wide[w];
    const int count = node.count();
    // The slots' runs of leaves follow one another and cover the node's.
    std::uint32_t next = m.first_leaf(i);
    for (int k = 0; k < WideNode::kSlots; ++k) {
      if (k >= count) {
        if (node.node[k] != WideNode::kEmpty || node.lo[0][k] <= node.hi[0][k]) return "a slot past the last is not empty";
        continue;
      }
      const std::uint32_t s = node.node[k];
      if (s >= m.nodes.size() || seen[s]++ != 0) return "slot " + std::to_string(s) + " is bad or seen twice";
      if (m.first_leaf(s) != next) return "the slots' runs of leaves do not follow one another";
      next += m.nodes[s].count;
      if (m.nodes[s].is_leaf() != (m.wide_of[s] == WideNode::kEmpty)) return "an inner slot without a wide node";
      const BvhNode& b = m.nodes[s];
      for (int a = 0; a < 3; ++a) {
        const double lo = double(b.box_center[a]) - b.box_half[a], hi = double(b.box_center[a]) + b.box_half[a];
        if (!(node.lo[a][k] <= lo && node.hi[a][k] >= hi)) return "a slot's box does not hold its node's";
        if (std::nextafter(node.lo[a][k], INFINITY) <= lo || std::nextafter(node.hi[a][k], -INFINITY) >= hi) {
          return "a slot's box is not the tightest float box";
        }
        if (node.axis[a][k] != m.filters[s].cone_axis[a]) return "a slot's slab axis is not its node's";
      }
      if (node.slab_lo[k] != m.filters[s].slab_lo || node.slab_hi[k] != m.filters[s].slab_hi) return "a slot's slab";
    }
    if (next != m.first_leaf(i) + m.nodes[i].count) return "the slots do not cover their node's leaves";
  }
  // Every leaf is one slot; a node between a wide node and its slots is neither root nor slot.
  for (std::uint32_t i = 0; i < m.nodes.size(); ++i) {
    if (m.nodes[i].is_leaf() && seen[i] != 1) return "leaf " + std::to_string(i) + " is not one slot";
    if (m.wide_of[i] != WideNode::kEmpty && seen[i] != 1)
      return "wide node " + std::to_string(i) + " is not the root or one slot";
  }
  return {};
}

TEST(WideTree, SlotsSplitTheirNodesLeavesInOrder) {
  Mesh far = make_torus(1.0, 0.35, 30, 16);
  for (Eigen::Vector3d& v : far.vertices) v += Eigen::Vector3d(3e6, -2e6, 1e6);
  Mesh slivers = make_sphere(1.0, 12, 16);
  for (std::size_t i = 0; i < 40; ++i) {
    const auto t = slivers.triangles[i * 3];
    slivers.triangles.push_back({t[0], t[1], t[0]});
  }
  for (const Mesh& mesh : {make_torus(1.0, 0.35, 48, 24), make_sphere(0.5, 9, 11), make_box(1.0, 0.5, 0.25, 4),
                           make_plate(2.0, 0.01, 16), far, slivers}) {
    const auto model = build_model(mesh);
    EXPECT_EQ(wide_problem(data(*model)), "") << mesh.source;
    EXPECT_FALSE(data(*model).wide.empty());
  }
}

// A wide node starts a cache line and a node's filter lies in one: a visit reads six lines of the
// one and one of the other, not seven and two.
TEST(WideTree, NodesLieOnCacheLines) {
  for (const Mesh& mesh : {make_torus(1.0, 0.35, 48, 24), make_sphere(0.5, 9, 11)}) {
    const auto model = build_model(mesh);
    const ModelData& m = data(*model);
    ASSERT_FALSE(m.wide.empty());
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(m.wide.data()) % 64, 0u);
    EXPECT_EQ(sizeof(WideNode) % 64, 0u);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(m.filters.data()) % 32, 0u);
    EXPECT_EQ(64 % sizeof(BvhNodeFilter), 0u);
  }
}

TEST(WideTree, ARootLeafHasNoWideNode) {
  Mesh one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  const auto model = build_model(one);
  EXPECT_TRUE(data(*model).wide.empty());
  EXPECT_EQ(data(*model).wide_of, std::vector<std::uint32_t>{WideNode::kEmpty});
}

// Subtrees that fit are opened to their leaves: the nodes hold more than half their slots on
// average (the largest-box rule alone left the 8-wide bunny at 4.2 of 8).
TEST(WideTree, NodesAreWellFilled) {
  for (const Mesh& mesh : {make_torus(1.0, 0.35, 64, 32), make_sphere(1.0, 40, 50)}) {
    const auto model = build_model(mesh);
    const ModelData& m = data(*model);
    std::size_t slots = 0;
    for (const WideNode& w : m.wide) slots += static_cast<std::size_t>(w.count());
    EXPECT_EQ(slots, m.mesh.triangles.size() + m.wide.size() - 1) << "every leaf and every wide node but the root's is a slot";
    EXPECT_GT(static_cast<double>(slots) / static_cast<double>(m.wide.size()), 5.0) << mesh.source;
  }
}

TEST(WideTree, OneSlotAsItsParentHasIt) {
  const auto model = build_model(make_torus(1.0, 0.35, 20, 12));
  const ModelData& m = data(*model);
  const WideNode& root = m.wide[0];
  for (int k = 0; k < root.count(); ++k) {
    const WideNode one = bvh::single_slot(m, root.node[k]);
    EXPECT_EQ(one.count(), 1);
    EXPECT_EQ(one.node[0], root.node[k]);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(one.lo[a][0], root.lo[a][k]);
      EXPECT_EQ(one.hi[a][0], root.hi[a][k]);
      EXPECT_EQ(one.axis[a][0], root.axis[a][k]);
      for (int j = 1; j < WideNode::kSlots; ++j) EXPECT_GT(one.lo[a][j], one.hi[a][j]) << "the other slots are empty";
    }
    EXPECT_EQ(one.slab_lo[0], root.slab_lo[k]);
    EXPECT_EQ(one.slab_hi[0], root.slab_hi[k]);
  }
}

}  // namespace
}  // namespace caliber
