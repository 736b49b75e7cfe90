#pragma once
/// \file
/// The one traversal of the CD tree (the product of two BVHs). Every method of the parallel engine
/// cuts this tree into tasks differently; all of them run this routine on their pieces.

#include <cstdint>
#include <vector>

#include "caliber/query.h"
#include "narrow/pair_context.h"

namespace caliber::narrow {

/// A node of the CD tree: a node of A's BVH paired with a node of B's.
struct NodePair {
  std::uint32_t a;  ///< node index in A's BVH
  std::uint32_t b;  ///< node index in B's BVH
};

/// A node whose sphere is more than this many times larger than its partner's descends alone.
inline constexpr double kDescendAloneRatio = 2.0;

/// The children of CD-tree node n (which must not be a leaf pair): both nodes split (up to 4
/// children) unless one is a leaf or much larger than the other, in which case only the larger
/// one splits. Depends only on object-space radii, so the CD tree's shape is pose-independent.
/// Writes them to out and returns how many.
inline int cd_children(const Model& ma, const Model& mb, NodePair n, NodePair out[4]) {
  const BvhNode& a = ma.nodes[n.a];
  const BvhNode& b = mb.nodes[n.b];
  const bool split_a = !a.is_leaf() && (b.is_leaf() || a.radius * kDescendAloneRatio >= b.radius);
  const bool split_b = !b.is_leaf() && (a.is_leaf() || b.radius * kDescendAloneRatio >= a.radius);
  const std::uint32_t as[2] = {n.a + 1, a.index};
  const std::uint32_t bs[2] = {n.b + 1, b.index};
  int count = 0;
  if (split_a && split_b) {
    for (const std::uint32_t ca : as) {
      for (const std::uint32_t cb : bs) out[count++] = NodePair{ca, cb};
    }
  } else if (split_a) {
    for (const std::uint32_t ca : as) out[count++] = NodePair{ca, n.b};
  } else {
    for (const std::uint32_t cb : bs) out[count++] = NodePair{n.a, cb};
  }
  return count;
}

/// Per-thread scratch for traversals, reused across calls to avoid allocation.
struct TraversalScratch {
  std::vector<NodePair> stack;  ///< explicit depth-first stack
};

/// Depth-first traversal of the CD subtree rooted at `root`: tests root and every node below it
/// that survives its parent's test; runs the leaf test on surviving leaf pairs; appends the kept
/// pairs to `out` and counts the work in `stats`.
inline void traverse_depth_first(const PairContext& ctx, NodePair root, TraversalScratch& scratch,
                                 std::vector<Candidate>& out, QueryStats& stats) {
  const Model& ma = ctx.a();
  const Model& mb = ctx.b();
  std::vector<NodePair>& stack = scratch.stack;
  stack.clear();
  stack.push_back(root);
  std::uint64_t node_tests = 0, leaf_tests = 0;
  NodePair kids[4];
  while (!stack.empty()) {
    const NodePair n = stack.back();
    stack.pop_back();
    const BvhNode& a = ma.nodes[n.a];
    const BvhNode& b = mb.nodes[n.b];
    ++node_tests;
    if (!ctx.node_test(n.a, n.b)) continue;
    if (a.is_leaf() && b.is_leaf()) {
      ++leaf_tests;
      ctx.leaf_test(a.index, b.index, out);
      continue;
    }
    const int count = cd_children(ma, mb, n, kids);
    for (int i = count - 1; i >= 0; --i) stack.push_back(kids[i]);
  }
  stats.node_tests += node_tests;
  stats.leaf_tests += leaf_tests;
}

/// Sorts the candidates of one object pair canonically, applies the contact reduction (local
/// minima) for contact queries, and converts them to world coordinates.
QueryResult finalize(const PairContext& ctx, std::vector<Candidate>& candidates, const QueryStats& stats);

}  // namespace caliber::narrow
