// bvh_problem (bvh/validate.h): none on built models, and each kind of broken BVH it names found.

#include <functional>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "bvh/validate.h"
#include "caliber/procedural.h"

namespace caliber {
namespace {

TEST(BvhProblem, NoneOnBuiltModels) {
  Mesh one;  // a root that is a leaf: no wide node, no slot
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  EXPECT_EQ(bvh::bvh_problem(data(*build_model(one))), "");
  for (const Mesh& mesh : {make_torus(1.0, 0.3, 24, 16), make_sphere(0.5, 8, 12), make_box(1.0, 2.0, 3.0, 3)}) {
    EXPECT_EQ(bvh::bvh_problem(data(*build_model(mesh))), "");
  }
  // A mesh far from its own origin: volumes relative to ModelData::origin.
  Mesh far = make_box(0.1, 0.1, 0.1, 2);
  for (auto& v : far.vertices) v += Eigen::Vector3d(3e6, -1e6, 5e5);
  EXPECT_EQ(bvh::bvh_problem(data(*build_model(far))), "");
}

TEST(BvhProblem, EachBreakIsFound) {
  const auto model = build_model(make_torus(1.0, 0.3, 24, 16));
  ModelData& m = const_cast<ModelData&>(data(*model));
  // Each change is undone after it is checked.
  const auto broken = [&](auto&& change) {
    const std::vector<BvhNode> nodes = m.nodes;
    const std::vector<BvhNodeFilter> filters = m.filters;
    const std::vector<std::uint32_t> leaf_position = m.leaf_position;
    const std::vector<std::uint64_t> group_masks = m.group_masks;
    const std::vector<std::uint8_t> groups = m.mesh.groups;
    const std::vector<WideNode> wide = m.wide;
    change();
    const std::string problem = bvh::bvh_problem(m);
    m.nodes = nodes;
    m.filters = filters;
    m.leaf_position = leaf_position;
    m.group_masks = group_masks;
    m.mesh.groups = groups;
    m.wide = wide;
    return problem;
  };
  std::uint32_t leaf = 0, inner = 1;  // the first leaf, and the first inner node below the root
  while (!m.nodes[leaf].is_leaf()) ++leaf;
  while (m.nodes[inner].is_leaf()) ++inner;
  EXPECT_NE(broken([&] { m.nodes[leaf].radius *= 0.5f; }), "");
  EXPECT_NE(broken([&] { m.nodes[leaf].box_half[1] = 0.0f; }), "");
  EXPECT_NE(broken([&] { m.filters[leaf].slab_hi = m.filters[leaf].slab_lo - 1.0f; }), "");
  EXPECT_NE(broken([&] { m.nodes[leaf].shape = 0; }), "") << "a leaf's shape that names one corner twice";
  EXPECT_NE(broken([&] { m.nodes[leaf].shape ^= 1; }), "") << "a leaf's middle corner one step off";
  EXPECT_NE(broken([&] { m.nodes[inner].count += 1; }), "");
  EXPECT_NE(broken([&] { m.nodes[inner].index = inner; }), "") << "a child before its parent";
  EXPECT_NE(broken([&] { std::swap(m.leaf_position[0], m.leaf_position[1]); }), "") << "triangles out of leaf order";
  EXPECT_NE(broken([&] { m.group_masks.assign(m.nodes.size(), 1); }), "") << "masks for a mesh without groups";
  EXPECT_EQ(broken([&] {
              m.mesh.groups.assign(m.mesh.triangles.size(), 0);
              m.group_masks.assign(m.nodes.size(), 1);
            }),
            "")
      << "every triangle in group 0, every mask 1";
  EXPECT_NE(broken([&] {
              m.mesh.groups.assign(m.mesh.triangles.size(), 0);
              m.group_masks.assign(m.nodes.size(), 1);
              m.group_masks[inner] = 3;
            }),
            "")
      << "an inner mask that is not its children's";
  EXPECT_NE(broken([&] {
              m.mesh.groups.assign(m.mesh.triangles.size(), 0);
              m.group_masks.assign(m.nodes.size(), 1);
              m.group_masks[leaf] = 2;
            }),
            "")
      << "a leaf mask that is not its triangle's group";
  EXPECT_NE(broken([&] { m.nodes.pop_back(); }), "");
  std::uint32_t other = leaf + 1;
  while (!m.nodes[other].is_leaf()) ++other;
  EXPECT_NE(broken([&] { m.nodes[other].index = m.nodes[leaf].index; }), "") << "a triangle in two leaves";
  ASSERT_FALSE(m.wide.empty());
  std::size_t partial = 0;  // a wide node with an empty slot
  while (partial < m.wide.size() && m.wide[partial].count() == WideNode::kSlots) ++partial;
  ASSERT_LT(partial, m.wide.size());
  EXPECT_NE(broken([&] { m.wide[0].set_count(m.wide[0].count() - 1); }), "")
      << "a wide node counting one slot fewer than it uses";
  EXPECT_NE(broken([&] { m.wide[partial].set_count(m.wide[partial].count() + 1); }), "") << "a wide node counting an empty slot";
  EXPECT_NE(broken([&] { m.wide[0].set_count(0); }), "") << "a wide node of no slot";
  EXPECT_NE(broken([&] {
              m.wide[0].set_count(WideNode::kSlots + 1);
              for (std::uint32_t& node : m.wide[0].node) node = node == WideNode::kEmpty ? 0 : node;
            }),
            "")
      << "a count past the slots";
  EXPECT_NE(broken([&] { m.nodes[leaf].link = 0; }), "") << "a leaf naming a wide node";
  EXPECT_NE(broken([&] { m.nodes[0].link = static_cast<std::uint32_t>(m.wide.size()); }), "") << "a wide node past the last";
  ASSERT_NE(m.nodes[leaf].slot, BvhNode::kNoSlot);
  EXPECT_NE(broken([&] { m.nodes[leaf].slot ^= 1u; }), "") << "a slot holding another node";
  const std::uint32_t at = m.nodes[leaf].slot / WideNode::kSlots, k = m.nodes[leaf].slot % WideNode::kSlots;
  EXPECT_NE(broken([&] { m.wide[at].slab_hi[k] = std::nextafter(m.wide[at].slab_hi[k], -1e30f); }), "")
      << "a slot's slab narrowed";
  EXPECT_NE(broken([&] { m.wide[at].axis[0][k] ^= 1u; }), "") << "a slot's slab axis moved";
  EXPECT_NE(broken([&] { m.nodes[leaf].slot = static_cast<std::uint32_t>(m.wide.size() * WideNode::kSlots); }), "")
      << "a slot past the last wide node";
  std::uint32_t inner_slot = 0;  // an inner node that is a slot (and so has a wide node)
  while (inner_slot < m.nodes.size() && !(m.nodes[inner_slot].slot != BvhNode::kNoSlot && m.nodes[inner_slot].has_wide()))
    ++inner_slot;
  ASSERT_LT(inner_slot, m.nodes.size());
  const std::uint32_t own = m.nodes[inner_slot].link;  // its wide node
  // Each break found by the check meant for it (its words in the problem).
  const auto says = [&](auto&& change, const std::string& words) { return broken(change).find(words) != std::string::npos; };
  EXPECT_TRUE(says([&] { m.nodes[inner_slot].link = BvhNode::kNoWide; }, "an inner slot without a wide node"));
  // (The slots' runs are another node's: they start elsewhere or end short.)
  EXPECT_TRUE(says([&] { std::swap(m.nodes[0].link, m.nodes[inner_slot].link); }, "its slots")) << "two wide nodes swapped";
  EXPECT_TRUE(says([&] { m.nodes[inner_slot].link = m.nodes[0].link; }, "a bad wide node")) << "a wide node named twice";
  EXPECT_TRUE(says([&] { m.wide[0].node[0] = static_cast<std::uint32_t>(m.nodes.size()); }, "a slot past the last node"));
  EXPECT_TRUE(says([&] { std::swap(m.wide[own].node[0], m.wide[own].node[1]); }, "do not follow one another"))
      << "two slots swapped";
  EXPECT_TRUE(says(
      [&] {
        for (std::uint32_t& slot : m.wide[own].node) slot = WideNode::kEmpty;
        m.wide[own].node[0] = inner_slot;
        m.wide[own].set_count(1);
      },
      "slot count"))
      << "a wide node whose one slot is its own node (a visit would come back to it)";
  EXPECT_TRUE(says([&] { m.wide[0].set_leaves(m.wide[0].leaves() ^ 1u); }, "a leaf mask not its leaves"))
      << "a slot's leaf bit flipped";
  EXPECT_TRUE(
      says([&] { m.wide[partial].set_leaves(m.wide[partial].leaves() | 1u << m.wide[partial].count()); }, "past its slots"))
      << "an empty slot marked a leaf";
  EXPECT_EQ(bvh::bvh_problem(m), "") << "every change undone";
}

}  // namespace
}  // namespace caliber
