// The one-pass check of a built BVH's invariants (validate.h).

#include "bvh/validate.h"

#include <bit>
#include <utility>
#include <vector>

#include "bvh/leaf_shape.h"
#include "bvh/wide_tree.h"

namespace caliber::bvh {
namespace {

/// Why leaf `i`'s volumes do not hold the vertices of its triangle (empty when they do).
std::string leaf_problem(const ModelData& m, std::uint32_t i) {
  const BvhNode& n = m.nodes[i];
  const BvhNodeFilter& f = m.filters[i];
  const Eigen::Vector3d c(n.center[0], n.center[1], n.center[2]);
  const Eigen::Vector3d bc(n.box_center[0], n.box_center[1], n.box_center[2]);
  const Eigen::Vector3d bh(n.box_half[0], n.box_half[1], n.box_half[2]);
  const Eigen::Vector3d axis(f.cone_axis[0], f.cone_axis[1], f.cone_axis[2]);
  Eigen::Vector3d corners[3];
  for (int k = 0; k < 3; ++k) corners[k] = m.mesh.vertices[m.mesh.triangles[n.index][k]] - m.origin;
  if (n.shape != bvh::leaf_shape(n, corners)) return "leaf " + std::to_string(i) + ": its shape is not its triangle's";
  for (const std::uint32_t v : m.mesh.triangles[n.index]) {
    const Eigen::Vector3d p = m.mesh.vertices[v] - m.origin;
    if (!((p - c).norm() <= n.radius)) return "leaf " + std::to_string(i) + ": its sphere misses a vertex";
    if (!((p - bc).cwiseAbs().array() <= bh.array()).all()) return "leaf " + std::to_string(i) + ": its box misses a vertex";
    const double along = axis.dot(p);
    if (!(f.slab_lo <= along && along <= f.slab_hi)) return "leaf " + std::to_string(i) + ": its slab misses a vertex";
  }
  const std::uint64_t group = std::uint64_t{1} << (m.mesh.groups.empty() ? 0 : m.mesh.groups[n.index]);
  if (m.group_mask(i) != group) return "leaf " + std::to_string(i) + ": its group mask is not its triangle's group";
  return {};
}

/// Why inner node `i`'s children do not fit it (empty when they do).
std::string children_problem(const ModelData& m, std::uint32_t i) {
  const BvhNode& n = m.nodes[i];
  const std::size_t size = m.nodes.size();
  if (n.index <= i || n.index + 1 >= size) return "node " + std::to_string(i) + ": children out of range or before it";
  const BvhNode &a = m.nodes[n.index], &b = m.nodes[n.index + 1];
  if (a.count + b.count != n.count) return "node " + std::to_string(i) + ": its children's counts do not add up";
  if ((m.group_mask(n.index) | m.group_mask(n.index + 1)) != m.group_mask(i)) {
    return "node " + std::to_string(i) + ": its group mask is not its children's";
  }
  return {};
}

/// Whether slot `slot` (BvhNode::slot) of m's wide tree holds node i, with the slab bvh::slot_slab
/// makes of i's, bit for bit.
bool slot_holds(const ModelData& m, std::uint32_t slot, std::size_t i) {
  if (slot / WideNode::kSlots >= m.wide.size()) return false;
  const WideNode& w = m.wide[slot / WideNode::kSlots];
  const std::uint32_t k = slot % WideNode::kSlots;
  const SlotSlab slab = slot_slab(m.nodes[i], m.filters[i]);
  const auto bits = [](float x) { return std::bit_cast<std::uint32_t>(x); };
  bool same = w.node[k] == i && bits(w.slab_lo[k]) == bits(slab.lo) && bits(w.slab_hi[k]) == bits(slab.hi);
  for (int a = 0; a < 3; ++a) same = same && w.axis[a][k] == slab.axis[a];
  return same;
}

/// Wide node w's slots: the count of those in use (2 or more; they come first, the rest empty),
/// each a node of m, an inner one with a wide node of its own; their runs of leaves follow one
/// another and cover node i's, whose wide node w is (`firsts`: where each node's run starts). So
/// each slot lies strictly below node i, and no visit comes back to a node it left.
std::string wide_slots_problem(const ModelData& m, const std::vector<std::uint32_t>& firsts, std::size_t i, std::size_t w) {
  const WideNode& node = m.wide[w];
  const int used = node.count();
  bool counted = used >= 2 && used <= WideNode::kSlots;
  for (int k = 0; k < WideNode::kSlots && counted; ++k) counted = (node.node[k] != WideNode::kEmpty) == (k < used);
  if (!counted) return "wide node " + std::to_string(w) + ": its slot count is not its slots in use";
  if ((node.leaves() >> used) != 0) return "wide node " + std::to_string(w) + ": a leaf mask past its slots";
  std::uint64_t next = firsts[i];
  for (int k = 0; k < used; ++k) {
    if (node.node[k] >= m.nodes.size()) return "wide node " + std::to_string(w) + ": a slot past the last node";
    const BvhNode& slot = m.nodes[node.node[k]];
    if (!slot.is_leaf() && !slot.has_wide()) return "wide node " + std::to_string(w) + ": an inner slot without a wide node";
    if (firsts[node.node[k]] != next) return "wide node " + std::to_string(w) + ": its slots' leaves do not follow one another";
    if (((node.leaves() >> k & 1u) != 0) != slot.is_leaf())
      return "wide node " + std::to_string(w) + ": a leaf mask not its leaves";
    next += slot.count;
  }
  if (next != std::uint64_t{firsts[i]} + m.nodes[i].count)
    return "wide node " + std::to_string(w) + ": its slots are not its node's triangles";
  return {};
}

/// What a wide visit reads of each node (where the wide tree is built): its wide node, named by one
/// node alone, an inner one; its slot, which holds it and stores the slab bvh::slot_slab makes of its filter's.
std::string wide_problem(const ModelData& m, const std::vector<std::uint32_t>& firsts) {
  std::vector<std::uint8_t> named(m.wide.size(), 0);
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const BvhNode& n = m.nodes[i];
    if (n.has_wide()) {
      if (n.is_leaf() || n.link >= m.wide.size() || named[n.link]++ != 0)
        return "node " + std::to_string(i) + ": a bad wide node";
      if (std::string p = wide_slots_problem(m, firsts, i, n.link); !p.empty()) return p;
    }
    if (n.slot != BvhNode::kNoSlot && !slot_holds(m, n.slot, i))
      return "node " + std::to_string(i) + ": its slot does not hold it";
  }
  for (std::size_t w = 0; w < m.wide.size(); ++w) {
    if (named[w] == 0) return "wide node " + std::to_string(w) + " is no node's";
  }
  return {};
}

}  // namespace

std::string bvh_problem(const ModelData& m) {
  const std::size_t triangles = m.mesh.triangles.size(), size = m.nodes.size();
  if (triangles == 0) return "no triangle";
  if (size != 2 * triangles - 1 || m.filters.size() != size || m.laterals.size() != size || m.leaf_position.size() != triangles) {
    return "the node arrays do not have 2n - 1 entries for n triangles";
  }
  if (m.group_masks.size() != (m.mesh.groups.empty() ? 0 : size)) {
    return "the group masks are not one a node (a mesh with groups) or none (a mesh without)";
  }
  if (m.nodes[0].count != triangles) return "the root does not hold every triangle";
  std::vector<std::uint8_t> reached(size, 0), placed(triangles, 0);
  std::vector<std::uint32_t> firsts(size, 0);
  // Each node with where its run of leaves starts (ModelData::first_leaf).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [i, first] = stack.back();
    stack.pop_back();
    if (reached[i]++ != 0) return "node " + std::to_string(i) + " is reached twice";
    firsts[i] = first;
    const BvhNode& n = m.nodes[i];
    if (n.is_leaf()) {
      if (n.index >= triangles || placed[n.index]++ != 0) return "leaf " + std::to_string(i) + ": a bad or repeated triangle";
      if (m.leaf_position[n.index] != first) return "leaf " + std::to_string(i) + ": not at its triangle's place";
      if (std::string p = leaf_problem(m, i); !p.empty()) return p;
      continue;
    }
    if (n.count < 2) return "node " + std::to_string(i) + ": an inner node of fewer than two triangles";
    if (std::string p = children_problem(m, i); !p.empty()) return p;
    stack.emplace_back(n.index, first);
    stack.emplace_back(n.index + 1, first + m.nodes[n.index].count);
  }
  for (std::size_t i = 0; i < size; ++i) {
    if (reached[i] == 0) return "node " + std::to_string(i) + " is not reached from the root";
  }
  return wide_problem(m, firsts);
}

}  // namespace caliber::bvh
