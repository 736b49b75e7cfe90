#pragma once
/// \file
/// The CD tree of a pair of objects (the product of their BVHs): its nodes, which of them descend
/// and into which children (the same for every method, schedule and pose), and the taboo lists
/// with which the a posteriori method hands parts of it to sub-tasks.

#include <algorithm>
#include <compare>
#include <cstdint>
#include <vector>

#include "bvh/model_data.h"
#include "narrow/pair_context.h"

namespace caliber::narrow {

/// A node of the CD tree: a node of A's BVH paired with a node of B's.
struct NodePair {
  std::uint32_t a;  ///< node index in A's BVH
  std::uint32_t b;  ///< node index in B's BVH
  friend bool operator==(const NodePair&, const NodePair&) = default;
  friend auto operator<=>(const NodePair&, const NodePair&) = default;
};

/// The a posteriori method's taboo list: CD-tree nodes that sub-tasks own. A traversal that meets
/// one skips it without testing it (its sub-task tests it) and says so in its "reached" output.
struct Taboo {
  std::vector<NodePair> nodes;  ///< sorted, distinct

  /// Index of n in the list, or -1.
  [[nodiscard]] int find(NodePair n) const {
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), n);
    return (it != nodes.end() && *it == n) ? static_cast<int>(it - nodes.begin()) : -1;
  }
};

/// What a traversal skips, and where it records that it met them: `reached[i]` is set when the
/// traversal meets taboo->nodes[i] (the caller sizes it; one thread writes it). Empty: skip nothing.
struct TabooView {
  const Taboo* taboo = nullptr;
  char* reached = nullptr;
};

/// Whether `child` is on the taboo list; if so it is marked reached (the traversal neither tests
/// nor enters it).
inline bool on_taboo(TabooView taboo, NodePair child) {
  if (taboo.taboo == nullptr) return false;
  const int t = taboo.taboo->find(child);
  if (t < 0) return false;
  taboo.reached[t] = 1;
  return true;
}

/// Which sides of CD-tree node n descend: both (up to 4 children) unless one is a leaf or its
/// sphere is more than `ratio` times the other's (PairContext::descend_alone_ratio), in which
/// case only the larger one descends. Depends only on object-space radii and the query's kind, so
/// the CD tree's shape does not depend on the poses. n must not be a pair of leaves.
inline void cd_descend(const BvhNode& a, const BvhNode& b, double ratio, bool& descend_a, bool& descend_b) {
  descend_a = !a.is_leaf() && (b.is_leaf() || double(a.radius) * ratio >= double(b.radius));
  descend_b = !b.is_leaf() && (a.is_leaf() || double(b.radius) * ratio >= double(a.radius));
}

/// The children of CD-tree node n of pair context ctx (not a pair of leaves), written to out;
/// returns how many.
inline int cd_children(const PairContext& ctx, NodePair n, NodePair out[4]) {
  const BvhNode& a = ctx.a().nodes[n.a];
  const BvhNode& b = ctx.b().nodes[n.b];
  bool descend_a, descend_b;
  cd_descend(a, b, ctx.descend_alone_ratio(), descend_a, descend_b);
  int count = 0;
  for (std::uint32_t i = 0; i < (descend_a ? 2u : 1u); ++i) {
    for (std::uint32_t j = 0; j < (descend_b ? 2u : 1u); ++j) {
      out[count++] = NodePair{descend_a ? a.index + i : n.a, descend_b ? b.index + j : n.b};
    }
  }
  return count;
}

/// The node test that a visit of `parent` makes on `child` (one of its cd_children): with the
/// disks where both sides descend (PairContext::node_test_2x2_lane), node_test where one does. For
/// code that walks the CD tree its own way and must make the decisions narrow::visit makes (tests,
/// benches).
inline bool child_test(const PairContext& ctx, NodePair parent, NodePair child) {
  return child.a != parent.a && child.b != parent.b ? ctx.node_test_2x2_lane(child.a, child.b) : ctx.node_test(child.a, child.b);
}

}  // namespace caliber::narrow
