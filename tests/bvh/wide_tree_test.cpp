// The wide tree (bvh/wide_tree.h): every wide node's slots are BVH nodes below it whose runs of
// leaves split its own, in order; every leaf and every wide node is one slot (the root's is the
// root); each slot's box is the tightest on its node's grid around the tightest float box around
// its BVH box, its bounds floats; the nodes are well filled.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "bvh/validate.h"
#include "bvh/wide_tree.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

/// The first broken property of slot k of wide node w, BVH node s, in words: its slab axis is its
/// filter's cut toward zero to a half float, and its bounds hold every vertex below s along that
/// axis, no wider than the filter's by more than the axis's change can move them over s's box.
std::string slot_slab_problem(const ModelData& m, const std::vector<std::uint32_t>& by_place, std::uint32_t s, const WideNode& w,
                              int k) {
  const BvhNodeFilter& f = m.filters[s];
  const BvhNode& n = m.nodes[s];
  double axis[3], moved = 0.0;
  for (int a = 0; a < 3; ++a) {
    axis[a] = w.slab_axis(a, k);
    const double cut = double(f.cone_axis[a]) - axis[a];
    // A half float has 11 significant bits; the least normal one is 2^-14.
    if (std::abs(axis[a]) > std::abs(double(f.cone_axis[a])) || std::abs(cut) >= std::max(std::abs(axis[a]) * 0x1p-10, 0x1p-14))
      return "a slot's slab axis is not its node's cut to a half float";
    moved += std::abs(cut) * n.box_half[a];
  }
  const std::uint32_t first = m.first_leaf(s);
  for (std::uint32_t p = first; p < first + n.count; ++p) {
    for (const std::uint32_t v : m.mesh.triangles[by_place[p]]) {
      const Eigen::Vector3d x = m.mesh.vertices[v] - m.origin;
      const double along = axis[0] * x[0] + axis[1] * x[1] + axis[2] * x[2];
      const double hair = 1e-13 * (std::abs(axis[0] * x[0]) + std::abs(axis[1] * x[1]) + std::abs(axis[2] * x[2]));
      if (along + hair < w.slab_lo[k] || along - hair > w.slab_hi[k]) return "a vertex below a slot lies outside its slab";
    }
  }
  const double slack = 1e-6 * (std::abs(double(f.slab_lo)) + std::abs(double(f.slab_hi)) + moved) + 1e-30;
  if (double(w.slab_hi[k]) - w.slab_lo[k] > double(f.slab_hi) - f.slab_lo + 2.0 * moved + slack)
    return "a slot's slab is wider than its axis's cut makes it";
  return {};
}

/// The first broken property of m's wide tree, in words (empty when none).
std::string wide_problem(const ModelData& m) {
  std::vector<int> seen(m.nodes.size(), 0);
  seen[0] = 1;
  std::vector<std::uint32_t> by_place(m.leaf_position.size());  // the triangle at each place of the leaf order
  for (std::uint32_t t = 0; t < by_place.size(); ++t) by_place[m.leaf_position[t]] = t;
  for (std::uint32_t i = 0; i < m.nodes.size(); ++i) {
    // A visit reads the node's own box, its triangle or wide node, and its slot.
    const BvhNode& n = m.nodes[i];
    if (n.is_leaf() && n.has_wide()) return "a leaf names a wide node";
    if (n.is_leaf() || !n.has_wide()) continue;
    const std::uint32_t w = n.link;
    if (w >= m.wide.size()) return "a node's wide node is out of range";
    const WideNode& node = m.wide[w];
    const int count = node.count();
    int exponent = 0;
    if (std::frexp(node.step(), &exponent) != 0.5f) return "the grid's step is not a power of two";
    for (int a = 0; a < 3; ++a) {
      if (std::fmod(double(node.origin[a]), double(node.step())) != 0.0) return "the grid's origin is not on it";
    }
    double box_lo[3] = {INFINITY, INFINITY, INFINITY}, box_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    // The slots' runs of leaves follow one another and cover the node's.
    std::uint32_t next = m.first_leaf(i);
    for (int k = 0; k < WideNode::kSlots; ++k) {
      if (k >= count) {
        if (node.node[k] != WideNode::kEmpty || node.low(0, k) <= node.high(0, k)) return "a slot past the last is not empty";
        continue;
      }
      const std::uint32_t s = node.node[k];
      if (s >= m.nodes.size() || seen[s]++ != 0) return "slot " + std::to_string(s) + " is bad or seen twice";
      if (m.first_leaf(s) != next) return "the slots' runs of leaves do not follow one another";
      next += m.nodes[s].count;
      if (!m.nodes[s].is_leaf() && !m.nodes[s].has_wide()) return "an inner slot without a wide node";
      if (m.nodes[s].slot != w * WideNode::kSlots + static_cast<std::uint32_t>(k)) return "a slot's node does not name it";
      const BvhNode& b = m.nodes[s];
      for (int a = 0; a < 3; ++a) {
        const double lo = double(b.box_center[a]) - b.box_half[a], hi = double(b.box_center[a]) + b.box_half[a];
        // The bounds as the test reads them, exact (origin + q step in double equals it in float).
        const double low = node.origin[a] + double(node.lo[a][k]) * node.step();
        const double high = node.origin[a] + double(node.hi[a][k]) * node.step();
        if (low != node.low(a, k) || high != node.high(a, k)) return "a slot's bound is not a float";
        if (!(low <= lo && high >= hi)) return "a slot's box does not hold its node's";
        // The grid's tightest outside the tightest float box.
        const float below = float(lo) > lo ? std::nextafter(float(lo), -INFINITY) : float(lo);
        const float above = float(hi) < hi ? std::nextafter(float(hi), INFINITY) : float(hi);
        if (low + node.step() <= below || high - node.step() >= above) return "a slot's box is not the grid's tightest";
        box_lo[a] = std::min(box_lo[a], double(below));
        box_hi[a] = std::max(box_hi[a], double(above));
      }
      if (std::string p = slot_slab_problem(m, by_place, s, node, k); !p.empty()) return p;
    }
    if (next != m.first_leaf(i) + m.nodes[i].count) return "the slots do not cover their node's leaves";
    // The least step the grid's rules allow (wide_tree.cpp's set_grid).
    double reach = 0.0, far = 0.0;
    for (int a = 0; a < 3; ++a) {
      reach = std::max(reach, 0.5 * (box_hi[a] - box_lo[a]));
      far = std::max({far, std::abs(box_lo[a]), std::abs(box_hi[a])});
    }
    const double least = std::max({reach / 32000.0, far * 0x1p-23, 0x1p-126});
    if (!(node.step() >= least && node.step() < 2.0 * least)) return "the grid's step is not the least its rules allow";
  }
  // Every leaf is one slot; a node between a wide node and its slots is neither root nor slot.
  for (std::uint32_t i = 0; i < m.nodes.size(); ++i) {
    if (m.nodes[i].is_leaf() && seen[i] != 1) return "leaf " + std::to_string(i) + " is not one slot";
    if (m.nodes[i].has_wide() && seen[i] != 1) return "wide node " + std::to_string(i) + " is not the root or one slot";
    if ((seen[i] == 0 || i == 0) && m.nodes[i].slot != BvhNode::kNoSlot)
      return "node " + std::to_string(i) + " is no slot but names one";
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
  // A plate turned by 3e-5 about x: its faces' normals have a component below the least normal
  // half (2^-14), which the slab axes drop (the slabs must still hold every vertex).
  Mesh tilted = make_plate(2.0, 0.01, 16);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(3e-5, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (Eigen::Vector3d& v : tilted.vertices) v = turn * v;
  // A box so small that the grids' least step (2^-126) sets the steps of its upper nodes.
  Mesh tiny = make_box(1.0, 0.5, 0.25, 4);
  for (Eigen::Vector3d& v : tiny.vertices) v *= std::ldexp(1.0, -112);
  for (const Mesh& mesh : {make_torus(1.0, 0.35, 48, 24), make_sphere(0.5, 9, 11), make_box(1.0, 0.5, 0.25, 4),
                           make_plate(2.0, 0.01, 16), far, slivers, tiny, tilted}) {
    const auto model = build_model(mesh);
    EXPECT_EQ(wide_problem(data(*model)), "") << mesh.source;
    EXPECT_FALSE(data(*model).wide.empty());
  }
  EXPECT_EQ(data(*build_model(tiny)).wide[0].step(), 0x1p-126f) << "the least step sets the root's grid";
  const auto turned = build_model(tilted);
  std::size_t dropped = 0;  // axis components the halves drop
  for (const BvhNodeFilter& f : data(*turned).filters) {
    for (const float x : f.cone_axis) dropped += x != 0.0f && std::abs(x) < 0x1p-14f ? 1 : 0;
  }
  EXPECT_GT(dropped, 0u) << "the turned plate's slab axes have components below the least normal half";
}

// A wide node and a BVH node start a cache line and a node's filter lies in one: a visit reads four
// lines of the first, one of the second and one of the third, not five, two and two.
TEST(WideTree, NodesLieOnCacheLines) {
  for (const Mesh& mesh : {make_torus(1.0, 0.35, 48, 24), make_sphere(0.5, 9, 11)}) {
    const auto model = build_model(mesh);
    const ModelData& m = data(*model);
    ASSERT_FALSE(m.wide.empty());
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(m.wide.data()) % 64, 0u);
    EXPECT_EQ(sizeof(WideNode) % 64, 0u);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(m.nodes.data()) % 64, 0u);
    EXPECT_EQ(sizeof(BvhNode), 64u);
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
  ASSERT_EQ(data(*model).nodes.size(), 1u);
  const BvhNode& n = data(*model).nodes[0];
  EXPECT_TRUE(n.is_leaf());
  EXPECT_EQ(n.triangle(), 0u);
  EXPECT_EQ(n.slot, BvhNode::kNoSlot);
  EXPECT_FALSE(n.has_wide());
}

// A node whose wide node lies past BvhNode::kSlotWideNodes names no slot (kNoSlot): single_slot
// finds its wide node from the root, and a visit reads its slab in its filter. With every slot
// cleared, the same single slots and the same contacts.
TEST(WideTree, NodesThatNameNoSlotGiveTheSameSingleSlotsAndContacts) {
  const auto a = build_model(make_torus(1.0, 0.35, 48, 24)), b = build_model(make_sphere(0.5, 9, 11));
  ModelData& ma = const_cast<ModelData&>(data(*a));
  ModelData& mb = const_cast<ModelData&>(data(*b));
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = 0.05;
  Pose pose_b;
  pose_b.translation = Eigen::Vector3d(1.1, 0.2, 0.1);
  pose_b.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  const QueryResult before = query(*a, Pose{}, *b, pose_b, request);
  ASSERT_FALSE(before.contacts.empty());
  std::vector<std::uint32_t> slotted;
  std::vector<WideNode> singles;
  for (std::uint32_t i = 0; i < ma.nodes.size(); ++i) {
    if (ma.nodes[i].slot == BvhNode::kNoSlot) continue;
    slotted.push_back(i);
    singles.push_back(bvh::single_slot(ma, i));
  }
  ASSERT_GT(slotted.size(), ma.wide.size()) << "the slots of every wide node";
  for (BvhNode& n : ma.nodes) n.slot = BvhNode::kNoSlot;
  for (BvhNode& n : mb.nodes) n.slot = BvhNode::kNoSlot;
  EXPECT_EQ(bvh::bvh_problem(ma), "");
  for (std::size_t s = 0; s < slotted.size(); ++s) {
    const WideNode found = bvh::single_slot(ma, slotted[s]), &want = singles[s];
    ASSERT_EQ(found.count(), 1);
    bool same = found.node[0] == want.node[0] && found.step() == want.step() && found.slab_lo[0] == want.slab_lo[0] &&
                found.slab_hi[0] == want.slab_hi[0];
    for (int i = 0; i < 3; ++i) {
      same = same && found.origin[i] == want.origin[i] && found.lo[i][0] == want.lo[i][0] && found.hi[i][0] == want.hi[i][0] &&
             found.axis[i][0] == want.axis[i][0];
    }
    EXPECT_TRUE(same) << "node " << slotted[s];
  }
  test::expect_identical(query(*a, Pose{}, *b, pose_b, request), before, "every slot cleared");
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

// Every slot, at every depth, alone as the wide node that holds it has it: its grid and bounds.
TEST(WideTree, OneSlotAsItsParentHasIt) {
  Mesh far = make_torus(1.0, 0.35, 20, 12);
  for (Eigen::Vector3d& v : far.vertices) v += Eigen::Vector3d(3e6, -2e6, 1e6);
  for (const Mesh& mesh : {make_torus(1.0, 0.35, 20, 12), far}) {
    const auto model = build_model(mesh);
    const ModelData& m = data(*model);
    std::size_t checked = 0;
    for (const WideNode& w : m.wide) {
      for (int k = 0; k < w.count(); ++k) {
        const WideNode one = bvh::single_slot(m, w.node[k]);
        ++checked;
        EXPECT_EQ(one.count(), 1);
        EXPECT_EQ(one.node[0], w.node[k]);
        EXPECT_EQ(one.step(), w.step());
        for (int a = 0; a < 3; ++a) {
          EXPECT_EQ(one.origin[a], w.origin[a]);
          EXPECT_EQ(one.low(a, 0), w.low(a, k));
          EXPECT_EQ(one.high(a, 0), w.high(a, k));
          EXPECT_EQ(one.axis[a][0], w.axis[a][k]);
          for (int j = 1; j < WideNode::kSlots; ++j) EXPECT_GT(one.low(a, j), one.high(a, j)) << "the other slots are empty";
        }
        EXPECT_EQ(one.slab_lo[0], w.slab_lo[k]);
        EXPECT_EQ(one.slab_hi[0], w.slab_hi[k]);
      }
    }
    EXPECT_EQ(checked, m.mesh.triangles.size() + m.wide.size() - 1) << "every slot of every wide node";
  }
}

}  // namespace
}  // namespace caliber
