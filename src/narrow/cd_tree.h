#pragma once
/// \file
/// The CD tree of a pair of objects (the product of their BVHs): its nodes, which of them descend
/// and into which children (the same for every method, schedule and pose), and the taboo lists
/// with which the a posteriori method hands parts of it to sub-tasks.
///
/// Two shapes, by the query's kind. The pair-collecting kinds (interference, proximity, contact)
/// walk the wide tree (WideNode): a node descends on one side, into the slots of that side's wide
/// node (up to eight children). The distance query walks the binary BVH: a node descends on one
/// or both sides (up to four children).

#include <algorithm>
#include <compare>
#include <cstdint>
#include <vector>

#include "bvh/model_data.h"
#include "narrow/pair_context.h"
#include "narrow/wide_test.h"
#include "util/assert.h"

namespace caliber::narrow {

/// The most children a CD-tree node has (the wide tree's slots).
inline constexpr int kMaxChildren = WideNode::kSlots;

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

/// In the binary CD tree (the distance query's), which sides of node n descend: both (up to 4 children) unless one is a leaf or its
/// sphere is more than `ratio` times the other's (PairContext::descend_alone_ratio), in which
/// case only the larger one descends. Depends only on object-space radii and the query's kind, so
/// the CD tree's shape does not depend on the poses. n must not be a pair of leaves.
inline void cd_descend(const BvhNode& a, const BvhNode& b, double ratio, bool& descend_a, bool& descend_b) {
  descend_a = !a.is_leaf() && (b.is_leaf() || double(a.radius) * ratio >= double(b.radius));
  descend_b = !b.is_leaf() && (a.is_leaf() || double(b.radius) * ratio >= double(a.radius));
}

/// Whether the queries of ctx walk the wide CD tree (the pair-collecting kinds) rather than the
/// binary one (distance).
inline bool wide_cd_tree(const PairContext& ctx) { return ctx.request().kind != QueryKind::distance; }

/// In the wide CD tree, whether node (a, b), not a pair of leaves, descends on A's side: A's node
/// is not a leaf, and B's is one or its box is no larger than A's (BvhNode::size). Depends only
/// on object-space boxes, so the CD tree's shape does not depend on the poses.
inline bool wide_descends_a(const BvhNode& a, const BvhNode& b) { return !a.is_leaf() && (b.is_leaf() || a.size() >= b.size()); }

/// A visit of the wide CD tree's node n (not a pair of leaves): the side that descends
/// (wide_descends_a), its wide node and the node that stays (its id and BvhNode); child k is
/// slot k with that node.
struct WideVisit {
  const WideNode* node;
  std::uint32_t stay;
  bool a_descends;
  const BvhNode* staying;
  const BvhNode* descending_nodes;  ///< the BVH nodes of the side that descends (its slots')

  [[nodiscard]] NodePair child(int k, NodePair n) const {
    return a_descends ? NodePair{node->node[k], n.b} : NodePair{n.a, node->node[k]};
  }
};

/// The wide visit of node n, whose BVH nodes are a (of A) and b (of B).
inline WideVisit wide_visit(const PairContext& ctx, NodePair n, const BvhNode& a, const BvhNode& b) {
  CALIBER_ASSERT(!(a.is_leaf() && b.is_leaf()), "a pair of leaves has no children");
  // (Written as branches: chosen by index from arrays, the wide node's address waits for both BVH
  // nodes to come from memory, where a predicted branch asks for it at once; queries were slower.)
  const bool down_a = wide_descends_a(a, b);
  const BvhNode& descending = down_a ? a : b;
  const ModelData& m = down_a ? ctx.a() : ctx.b();
  CALIBER_ASSERT(descending.has_wide(), "a node of the wide CD tree that descends has a wide node");
  return WideVisit{&m.wide[descending.link], down_a ? n.b : n.a, down_a, down_a ? &b : &a, m.nodes.data()};
}

/// The children of CD-tree node n of pair context ctx (not a pair of leaves), written to out;
/// returns how many. The wide tree's: the slots of the descending side's wide node, in order,
/// each with the node that stays (WideVisit). The binary tree's: A's child i (or n.a) with B's
/// child j (or n.b), i major.
inline int cd_children(const PairContext& ctx, NodePair n, NodePair out[kMaxChildren]) {
  if (wide_cd_tree(ctx)) {
    const WideVisit v = wide_visit(ctx, n, ctx.a().nodes[n.a], ctx.b().nodes[n.b]);
    const int count = v.node->count();
    for (int k = 0; k < count; ++k) out[k] = v.child(k, n);
    return count;
  }
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

/// The lanes of the wide node test for ctx's pose (detail::make_wide_lanes, with the scale of
/// PairContext::node_lanes): made once by a traversal, in place (`out`) or returned.
void wide_lanes(const PairContext& ctx, detail::WideLanes& out);
detail::WideLanes wide_lanes(const PairContext& ctx);

/// The vector form of the wide node test where this CPU has one (built for AVX-512VL, else for
/// AVX2), else null (wide_pass then runs the scalar form: the same decisions), chosen when the
/// library loads.
extern const detail::WideTest kWideTest;

/// The AVX2 form of detail::SlotOrderKeys where this CPU has it, else null (the portable form,
/// detail::slot_order_keys_portable, then: the same keys), chosen when the library loads.
extern const detail::SlotOrderKeys kSlotOrderKeys;

/// The wide node test as the library chose it when it loaded (kWideTest, else the scalar form),
/// called through a pointer: what a visit runs unless its caller names the form (Test below).
struct ChosenWideTest {
  unsigned operator()(const detail::NodeTestFrame& f, const detail::WideLanes& l, bool a_descends, std::uint32_t stay,
                      const BvhNode& sn, const WideNode& w, detail::StayingCache* cache) const {
    // (Null also before the library's constants are made: a query from another constant's constructor.)
    return (kWideTest != nullptr ? kWideTest : detail::wide_test_scalar)(f, l, a_descends, stay, sn, w, cache);
  }
};

/// The node tests of the wide visit v of node n on its children: bit k set where child k
/// (cd_children order) passes the wide test (`test`, a form of detail::WideTest; its staying node
/// read from or kept in `cache`, if given), then the groups and normal cones
/// (PairContext::groups_and_cones_allow) of each that is not a pair of leaves.
template <class Test = ChosenWideTest>
[[gnu::always_inline]] inline unsigned wide_pass(const PairContext& ctx, NodePair n, const WideVisit& v,
                                                 const detail::WideLanes& lanes, detail::StayingCache* cache = nullptr,
                                                 Test test = {}) {
  CALIBER_ASSERT(v.staying == &(v.a_descends ? ctx.b() : ctx.a()).nodes[v.stay], "the staying node is node stay");
  unsigned pass = test(ctx.node_test_frame(), lanes, v.a_descends, v.stay, *v.staying, *v.node, cache);
  if (!ctx.refuses_by_groups_or_cones() || pass == 0) return pass;
  // A pair of leaves skips them: its leaf test tests the triangles' groups and normals exactly
  // (PairContext::groups_allow, normals_allow), refusing all that the nodes' groups and cones would
  // (two thirds of the cone tests of a contact query, each reading two nodes' filters). Which
  // slots are leaves, the wide node says.
  const unsigned leaves = v.staying->is_leaf() ? v.node->leaves() : 0u;
  for (unsigned bits = pass & ~leaves; bits != 0; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    const NodePair child = v.child(k, n);
    if (!ctx.groups_and_cones_allow(child.a, child.b)) pass &= ~(1u << k);
  }
  return pass;
}

/// How a CD-tree node is tested where no visit of its parent tests it (a traversal's root): not at
/// all (tested and passed earlier), as a pair's root (PairContext::node_test), as a child of a
/// binary visit where both sides descend (PairContext::node_test_2x2_lane), or as its wide
/// parent's visit tests it, the parent having descended on A's side or on B's (wide_pass).
enum class RootTest : std::uint8_t { done, as_root, with_disks, child_of_a, child_of_b };

/// How the visit of `parent` tests `child` (one of its cd_children), as a RootTest; a node given
/// as its own parent is tested as a root.
inline RootTest child_root_test(const PairContext& ctx, NodePair parent, NodePair child) {
  if (child == parent) return RootTest::as_root;
  if (wide_cd_tree(ctx)) return child.a != parent.a ? RootTest::child_of_a : RootTest::child_of_b;
  return child.a != parent.a && child.b != parent.b ? RootTest::with_disks : RootTest::as_root;
}

/// The node test of CD-tree node n made as `how` says (not RootTest::done).
bool root_test(const PairContext& ctx, NodePair n, RootTest how);

/// The node test that a visit of `parent` makes on `child` (one of its cd_children). For code that
/// walks the CD tree its own way and must make the decisions narrow::visit makes (tests, benches).
inline bool child_test(const PairContext& ctx, NodePair parent, NodePair child) {
  return root_test(ctx, child, child_root_test(ctx, parent, child));
}

}  // namespace caliber::narrow
