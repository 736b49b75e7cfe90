#pragma once
/// \file
/// The one traversal of the CD tree (the product of two BVHs). Every method of the parallel engine
/// cuts this tree into tasks differently; all of them run this routine on their pieces.

#include <algorithm>
#include <compare>
#include <cstdint>
#include <vector>

#include "caliber/query.h"
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
/// one skips it without testing it (its sub-task tests it) and records that it met it.
struct Taboo {
  std::vector<NodePair> nodes;         ///< sorted, distinct
  mutable std::vector<char> reached;   ///< reached[i]: the traversal met nodes[i] (one thread writes it)

  /// Index of n in the list, or -1.
  [[nodiscard]] int find(NodePair n) const {
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), n);
    return (it != nodes.end() && *it == n) ? static_cast<int>(it - nodes.begin()) : -1;
  }
};

/// A node whose sphere is more than this many times larger than its partner's descends alone.
inline constexpr double kDescendAloneRatio = 2.0;

/// Which sides of CD-tree node n split: both (up to 4 children) unless one is a leaf or much larger
/// than the other, in which case only the larger one splits. Depends only on object-space radii,
/// so the CD tree's shape does not depend on the poses. n must not be a pair of leaves.
inline void cd_split(const BvhNode& a, const BvhNode& b, bool& split_a, bool& split_b) {
  split_a = !a.is_leaf() && (b.is_leaf() || double(a.radius) * kDescendAloneRatio >= double(b.radius));
  split_b = !b.is_leaf() && (a.is_leaf() || double(b.radius) * kDescendAloneRatio >= double(a.radius));
}

/// The children of CD-tree node n (not a pair of leaves), written to out; returns how many.
inline int cd_children(const Model& ma, const Model& mb, NodePair n, NodePair out[4]) {
  const BvhNode& a = ma.nodes[n.a];
  const BvhNode& b = mb.nodes[n.b];
  bool split_a, split_b;
  cd_split(a, b, split_a, split_b);
  int count = 0;
  for (std::uint32_t i = 0; i < (split_a ? 2u : 1u); ++i) {
    for (std::uint32_t j = 0; j < (split_b ? 2u : 1u); ++j) {
      out[count++] = NodePair{split_a ? a.index + i : n.a, split_b ? b.index + j : n.b};
    }
  }
  return count;
}

/// Per-thread scratch for traversals, reused across calls to avoid allocation.
struct TraversalScratch {
  std::vector<NodePair> stack;  ///< explicit depth-first stack
};

/// Depth-first traversal of the CD subtree rooted at `root`: tests root (unless `root_tested`: it
/// was tested, and passed, earlier) and every node below it whose parent passed; runs the leaf
/// test on passing leaf pairs; appends the kept pairs to `out` and counts the work in `stats`
/// (every node test, every leaf test). With a taboo list, a child on the list is neither tested nor
/// entered, only marked as reached.
/// Children are tested when their parent is expanded, so each child node of A and of B is
/// prepared once for the (up to) four pairs it takes part in; only passing children are pushed.
inline void traverse_depth_first(const PairContext& ctx, NodePair root, TraversalScratch& scratch,
                                 std::vector<Candidate>& out, QueryStats& stats, bool root_tested = false,
                                 const Taboo* taboo = nullptr) {
  const Model& ma = ctx.a();
  const Model& mb = ctx.b();
  // Each expansion pops one node and pushes at most four, one level deeper: the stack never holds
  // more than 3 * (height A + height B) + 1 nodes.
  std::vector<NodePair>& stack = scratch.stack;
  const auto bound = static_cast<std::size_t>(3 * (ma.height + mb.height) + 4);
  if (stack.size() < bound) stack.resize(bound);
  NodePair* const base = stack.data();
  NodePair* top = base;
  std::uint64_t node_tests = root_tested ? 0 : 1, leaf_tests = 0;
  if (root_tested || ctx.node_test(root.a, root.b)) *top++ = root;
  while (top != base) {
    const NodePair n = *--top;
    const BvhNode& a = ma.nodes[n.a];
    const BvhNode& b = mb.nodes[n.b];
    if (a.is_leaf() && b.is_leaf()) {
      ++leaf_tests;
      ctx.leaf_test(a.index, b.index, out);
      continue;
    }
    bool split_a, split_b;
    cd_split(a, b, split_a, split_b);
    PairContext::SideA sa[2];
    PairContext::SideB sb[2];
    const int na = split_a ? 2 : 1, nb = split_b ? 2 : 1;
    for (int i = 0; i < na; ++i) sa[i] = ctx.prepare_a(split_a ? a.index + i : n.a);
    for (int j = 0; j < nb; ++j) sb[j] = ctx.prepare_b(split_b ? b.index + j : n.b);
    // Pushed in reverse so that the first child is popped first (the same order as cd_children).
    for (int i = na - 1; i >= 0; --i) {
      for (int j = nb - 1; j >= 0; --j) {
        if (taboo != nullptr) {
          const int t = taboo->find(NodePair{sa[i].index, sb[j].index});
          if (t >= 0) {
            taboo->reached[static_cast<std::size_t>(t)] = 1;
            continue;
          }
        }
        ++node_tests;
        if (ctx.node_test(sa[i], sb[j])) *top++ = NodePair{sa[i].index, sb[j].index};
      }
    }
  }
  stats.node_tests += node_tests;
  stats.leaf_tests += leaf_tests;
}

/// Sorts the candidates of one object pair canonically, applies the contact reduction (local
/// minima) for contact queries, and converts them to world coordinates. With `parallel`, a large
/// candidate list is processed by several tasks of the current oneTBB arena (same result).
QueryResult finalize(const PairContext& ctx, std::vector<Candidate>& candidates, const QueryStats& stats,
                     bool parallel = false);

}  // namespace caliber::narrow
