#pragma once
/// \file
/// The one node visit of every traversal (narrow::visit): a pair of leaves gets its leaf test, any
/// other CD-tree node its children's node tests, in the wide CD tree (visit_wide) or the binary
/// one (visit_binary; cd_tree.h).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "caliber/query.h"
#include "narrow/candidate.h"
#include "narrow/cd_tree.h"
#include "narrow/child_pairs.h"
#include "narrow/leaf_buffer.h"
#include "narrow/pair_context.h"
#include "util/assert.h"

namespace caliber::narrow {

/// The lanes of a traversal's node tests, made once by it: those of the binary CD tree's
/// (PairContext::node_lanes) or of the wide one's (wide_lanes); null: made by each visit. In the
/// wide tree, `staying`: the staying nodes its visits moved (detail::StayingCache), renewed by the
/// traversal, which alone uses it, on one thread (null: each visit moves its own).
struct VisitLanes {
  const detail::NodeLanes* binary = nullptr;
  const detail::WideLanes* wide = nullptr;
  detail::StayingCache* staying = nullptr;
  /// Where given (with `staying`), a wide visit that writes two children or more to `passed`
  /// writes there the order key of each, in the same places (detail::SlotOrderKeys): what a
  /// traversal with a limit orders them by (push_nearest_first).
  float* order = nullptr;
};

/// Counts and makes the node test of CD-tree node n: the test of a node no parent tested (a root),
/// as `how` says (not RootTest::done).
inline bool test_root(const PairContext& ctx, NodePair n, QueryStats& stats, RootTest how = RootTest::as_root) {
  ++stats.node_tests;
  return root_test(ctx, n, how);
}

/// The order keys of the slots of visit v (detail::SlotOrderKeys) against its staying node, which
/// `staying` holds (its visit's test has just moved it there, or found it there).
inline void slot_order_keys(const WideVisit& v, detail::StayingCache& staying, float keys[WideNode::kSlots]) {
  bool held = false;
  const detail::StayingCache::Entry& kept = staying.find(v.stay, v.a_descends, held);
  CALIBER_ASSERT(held, "the visit kept its staying node");
  // (Null also before the library's constants are made: a query from another constant's constructor.)
  (kSlotOrderKeys != nullptr ? kSlotOrderKeys : detail::slot_order_keys_portable)(kept, *v.node, keys);
}

/// The visit of a node of the wide CD tree (not a pair of leaves; narrow::visit): its children's
/// tests at once (wide_pass), those that pass written to `passed` in cd_children order (kReversed:
/// reversed), every child counted but those on the taboo list (skipped and marked reached). Given
/// `leaf_pair` (a callable, not null), the children that pass and are pairs of leaves (the staying
/// node a leaf, the slot one: WideNode::leaves) get their leaf test here, leaf_pair(ta, tb), in
/// slot order, and are not written: they would be visited next only to be found leaves. Given
/// `order` (and `staying`), each child written gets its order key there (VisitLanes::order).
template <bool kReversed, class Test = ChosenWideTest, class LeafPair = std::nullptr_t>
[[gnu::always_inline]] inline int visit_wide(const PairContext& ctx, NodePair n, const BvhNode& a, const BvhNode& b,
                                             QueryStats& stats, NodePair passed[], TabooView taboo,
                                             const detail::WideLanes& lanes, detail::StayingCache* staying, Test test = {},
                                             LeafPair leaf_pair = nullptr, float* order = nullptr) {
  const WideVisit v = wide_visit(ctx, n, a, b);
  unsigned pass = wide_pass(ctx, n, v, lanes, staying, test);
  const int count = v.node->count();
  if (taboo.taboo != nullptr) {
    for (int k = 0; k < count; ++k) {
      if (on_taboo(taboo, v.child(k, n))) {
        pass &= ~(1u << k);
      } else {
        ++stats.node_tests;
      }
    }
  } else {
    stats.node_tests += static_cast<std::uint64_t>(count);
  }
  if constexpr (!std::is_same_v<LeafPair, std::nullptr_t>) {
    const unsigned leaves = pass & v.node->leaves() & (0u - static_cast<unsigned>(v.staying->is_leaf()));
    pass &= ~leaves;
    const std::uint32_t held = v.staying->triangle();
    for (unsigned bits = leaves; bits != 0; bits &= bits - 1) {
      const std::uint32_t t = v.descending_nodes[v.node->node[__builtin_ctz(bits)]].triangle();
      if (v.a_descends) {
        leaf_pair(t, held);
      } else {
        leaf_pair(held, t);
      }
    }
  }
  if constexpr (requires { test.template write_passed<kReversed>(v, pass, passed); }) {
    if (order == nullptr) return test.template write_passed<kReversed>(v, pass, passed);
  }
  // The keys where two children or more pass (one needs no order).
  const bool ordered = order != nullptr && (pass & (pass - 1)) != 0;
  CALIBER_ASSERT(!ordered || staying != nullptr, "the keys read the staying node the test kept");
  float keys[WideNode::kSlots];
  if (ordered) slot_order_keys(v, *staying, keys);
  int passing = 0;
  while (pass != 0) {
    const unsigned k = kReversed ? 31u - static_cast<unsigned>(__builtin_clz(pass)) : static_cast<unsigned>(__builtin_ctz(pass));
    pass ^= 1u << k;
    if (ordered) order[passing] = keys[k];
    passed[passing++] = v.child(static_cast<int>(k), n);
  }
  return passing;
}

/// visit_wide for a visit without the traversal's lanes: made here.
template <bool kReversed>
[[gnu::noinline]] int visit_wide_alone(const PairContext& ctx, NodePair n, const BvhNode& a, const BvhNode& b, QueryStats& stats,
                                       NodePair passed[], TabooView taboo) {
  const detail::WideLanes made = wide_lanes(ctx);
  return visit_wide<kReversed>(ctx, n, a, b, stats, passed, taboo, made, nullptr);
}

/// The visit of a node of the binary CD tree (not a pair of leaves; narrow::visit): its children's
/// tests four or two at a time where no taboo list is given, else one pair at a time.
template <bool kReversed>
[[gnu::always_inline]] inline int visit_binary(const PairContext& ctx, NodePair n, const BvhNode& a, const BvhNode& b,
                                               QueryStats& stats, NodePair passed[], TabooView taboo,
                                               const detail::NodeLanes* lanes) {
  int count = 0;
  bool descend_a, descend_b;
  cd_descend(a, b, ctx.descend_alone_ratio(), descend_a, descend_b);
  const bool both = descend_a && descend_b;
  if (taboo.taboo == nullptr) {
    // No taboo list: the children tested and counted at once, taken by their bits in lane order:
    // four where both sides descend (lane 2i + j: A's child i, B's child j), else the two of the
    // side that descends against the other node (node_tests_one_side: lanes 0 and 3).
    const std::uint32_t a0 = descend_a ? a.index : n.a, a1 = descend_a ? a.index + 1 : n.a;
    const std::uint32_t b0 = descend_b ? b.index : n.b, b1 = descend_b ? b.index + 1 : n.b;
    const int pass = both ? ctx.node_tests_2x2(a0, a1, b0, b1, lanes) : ctx.node_tests_one_side(a0, a1, b0, b1, lanes);
    stats.node_tests += both ? 4 : 2;
    for (unsigned bits = static_cast<unsigned>(pass) & 0xFu; bits != 0;) {
      const unsigned k =
          kReversed ? 31u - static_cast<unsigned>(__builtin_clz(bits)) : static_cast<unsigned>(__builtin_ctz(bits));
      bits ^= 1u << k;
      passed[count++] = NodePair{k / 2 != 0 ? a1 : a0, k % 2 != 0 ? b1 : b0};
    }
    return count;
  }
  if (both) {
    // With a taboo list: the four at once, taken in cd_children order (one on the list is marked
    // reached, neither counted nor entered); where one side descends, pair by pair below.
    const int pass = ctx.node_tests_2x2(a.index, a.index + 1, b.index, b.index + 1, lanes);
    for_each_child_2x2(a.index, b.index, stats, taboo, [&](std::uint32_t k, NodePair child) {
      if ((pass >> k) & 1) passed[count++] = child;
    });
    if constexpr (kReversed) std::reverse(passed, passed + count);
    return count;
  }
  for_each_child(
      n, a, b, descend_a, descend_b, stats, taboo, [&](std::uint32_t i) { return ctx.prepare_a(i); },
      [&](std::uint32_t j) { return ctx.prepare_b(j); },
      [&](const PairContext::SideA& sa, const PairContext::SideB& sb, NodePair child) {
        if (ctx.node_test(sa, sb)) passed[count++] = child;
      });
  if constexpr (kReversed) std::reverse(passed, passed + count);
  return count;
}

/// The one node visit of every traversal (depth first, stealing, the weight-driven stage), at a
/// CD-tree node n that passed its node test. A pair of leaves gets its leaf test (a kept pair is
/// appended to `out`) and the visit returns -1. Any other node's children are tested, each counted
/// in stats.node_tests, except those on the taboo list (skipped and marked reached); the children
/// that pass are written to `passed` in cd_children order and the visit returns how many (0..8).
/// So every CD node below a root is tested exactly once, by its parent's visit. With a buffer, a
/// leaf pair may wait there (PairContext::leaf_test with a buffer): the caller flushes it before
/// reading `out`; and a wide visit tests its children that are pairs of leaves itself (counted as
/// leaf tests, not returned: visit_wide). `passed` has room for kMaxChildren children, however
/// many pass (a form may write all its places). `lanes`: the lanes of the node tests, made once
/// by the traversal (null: made here): wide_lanes(ctx) in the wide CD tree (visit_wide),
/// ctx.node_lanes() in the binary one.
/// kReversed: the children written in reverse cd_children order (a depth-first stack takes them
/// so, the first child on top). Test: the form of the wide node test (ChosenWideTest: the one the
/// library chose; a loop built for AVX2 names its own, inlined: the same decisions).
template <bool kReversed = false, class Test = ChosenWideTest>
[[gnu::always_inline]] inline int visit(const PairContext& ctx, NodePair n, std::vector<Candidate>& out, QueryStats& stats,
                                        NodePair passed[kMaxChildren], TabooView taboo = {}, LeafBuffer* buffer = nullptr,
                                        VisitLanes lanes = {}, Test test = {}) {
  const auto leaf_pair = [&](std::uint32_t ta, std::uint32_t tb) {
    ++stats.leaf_tests;
    if (buffer != nullptr) {
      ctx.leaf_test(ta, tb, out, *buffer);
    } else {
      ctx.leaf_test(ta, tb, out);
    }
    return -1;
  };
  if (wide_cd_tree(ctx)) {
    // One line of each side (BvhNode): the leaves' triangles, the sizes, the wide node, the
    // staying box and slot.
    const BvhNode& a = ctx.a().nodes[n.a];
    const BvhNode& b = ctx.b().nodes[n.b];
    if (a.is_leaf() && b.is_leaf()) return leaf_pair(a.triangle(), b.triangle());
    if (lanes.wide == nullptr) return visit_wide_alone<kReversed>(ctx, n, a, b, stats, passed, taboo);
    if (buffer != nullptr)
      return visit_wide<kReversed>(ctx, n, a, b, stats, passed, taboo, *lanes.wide, lanes.staying, test, leaf_pair, lanes.order);
    return visit_wide<kReversed>(ctx, n, a, b, stats, passed, taboo, *lanes.wide, lanes.staying, test, nullptr, lanes.order);
  }
  const BvhNode& a = ctx.a().nodes[n.a];
  const BvhNode& b = ctx.b().nodes[n.b];
  if (a.is_leaf() && b.is_leaf()) return leaf_pair(a.index, b.index);
  return visit_binary<kReversed>(ctx, n, a, b, stats, passed, taboo, lanes.binary);
}

/// Asks memory for the BVH nodes of CD-tree node n (a visit reads them first).
inline void prefetch_nodes(const PairContext& ctx, NodePair n) {
  __builtin_prefetch(ctx.a().nodes.data() + n.a);
  __builtin_prefetch(ctx.b().nodes.data() + n.b);
}

/// Asks memory for what the wide visit of node n reads after its BVH nodes: the descending side's
/// wide node (four lines). Reads the BVH nodes (asked for a visit before).
inline void prefetch_wide(const PairContext& ctx, NodePair n) {
  const BvhNode& a = ctx.a().nodes[n.a];
  const BvhNode& b = ctx.b().nodes[n.b];
  if (a.is_leaf() && b.is_leaf()) return;
  const char* const w = reinterpret_cast<const char*>(wide_visit(ctx, n, a, b).node);
  for (std::size_t line = 0; line < sizeof(WideNode); line += 64) __builtin_prefetch(w + line);
}

/// A depth-first traversal's loop without a limit, from the first `size` nodes of `stack` until
/// none is left: each node visited (visit<true>, the leaf pairs waiting in `buffer`), the children
/// that pass pushed (the stack grows where it must). Except in a contact query, two nodes wait
/// between the stack and their visit, so that memory is asked for what a visit reads a visit
/// before it reads it: the BVH nodes of the node taken from the stack, then, once it is next, its
/// wide node. So the order of the visits is the depth-first one but that a visit's children come
/// after the two nodes waiting; every node is visited once, as in any order. (A contact query's
/// reduction finds neighbours next to each other in the depth-first order of its candidates, and
/// lost more than the waiting saved.) Test: the wide test's form, as visit's.
template <class Test = ChosenWideTest>
[[gnu::always_inline]] inline void visit_until_empty(const PairContext& ctx, std::vector<NodePair>& stack, std::size_t size,
                                                     std::vector<Candidate>& out, QueryStats& stats, TabooView taboo,
                                                     LeafBuffer& buffer, VisitLanes lanes, Test test = {}) {
  CALIBER_ASSERT(size <= stack.size(), "the nodes to visit are on the stack");
  if (stack.size() < size + kMaxChildren) stack.resize(size + kMaxChildren);
  NodePair* base = stack.data();
  NodePair* top = base + size;
  // Where the stack must grow before a visit writes its children (kept here: the vector's own
  // bounds would be read again after every store through `top`).
  NodePair* limit = base + (stack.size() - kMaxChildren);
  constexpr int kWaiting = 2;
  const int most = ctx.request().kind == QueryKind::contact ? 0 : kWaiting;
  NodePair ahead[kWaiting] = {};
  int waiting = 0;
  while (waiting != 0 || top != base) {
    if (waiting == 0) ahead[waiting++] = *--top;
    const NodePair n = ahead[0];
    for (int i = 0; i + 1 < kWaiting; ++i) ahead[i] = ahead[i + 1];
    if (--waiting != 0 && lanes.wide != nullptr) prefetch_wide(ctx, ahead[0]);
    while (waiting < most && top != base) {
      ahead[waiting] = *--top;
      prefetch_nodes(ctx, ahead[waiting++]);
    }
    if (top > limit) {
      const auto at = top - base;
      stack.resize(2 * stack.size() + kMaxChildren);
      base = stack.data();
      top = base + at;
      limit = base + (stack.size() - kMaxChildren);
    }
    const int count = visit<true>(ctx, n, out, stats, top, taboo, &buffer, lanes, test);
    top += count > 0 ? count : 0;
  }
}

/// visit_until_empty on the wide CD tree with its wide test inlined, built for AVX2 or for
/// AVX-512VL (wide_test_avx2.cpp; the same visits and decisions).
using WideLoop = void (*)(const PairContext& ctx, std::vector<NodePair>& stack, std::size_t size, std::vector<Candidate>& out,
                          QueryStats& stats, TabooView taboo, LeafBuffer& buffer, VisitLanes lanes);
namespace detail {
/// The loop built for AVX2, FMA and F16C, or (wide_registers) the same loop built for AVX-512VL
/// too (32 vector registers); null where this CPU lacks what the form needs.
WideLoop wide_loop_form(bool wide_registers);
}  // namespace detail
/// The AVX-512VL loop where this CPU has it, else the AVX2 one, else null (with kWideTest),
/// chosen when the library loads.
extern const WideLoop kWideLoop;

}  // namespace caliber::narrow
