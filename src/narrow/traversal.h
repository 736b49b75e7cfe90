#pragma once
/// \file
/// The one traversal of the CD tree (the product of two BVHs). Every method of the parallel engine
/// cuts this tree into tasks differently; all of them run this routine on their pieces.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "caliber/query.h"
#include "narrow/cd_tree.h"
#include "narrow/child_pairs.h"
#include "narrow/pair_context.h"
#include "narrow/traversal_scratch.h"
#include "narrow/visit.h"
#include "narrow/visit_order.h"
#include "util/assert.h"
#include "util/gap_buckets.h"

namespace caliber::narrow {

/// What the traversals of one object pair share, whatever threads they run on: how many triangle
/// pairs they have kept, against QueryRequest::max_pairs (they stop once it is reached; which
/// pairs were kept by then depends on the schedule; finalize keeps max_pairs of them), and for a
/// distance query the nearest distance any of them has found (each prunes by it: see Nearest).
struct PairShared {
  std::atomic<std::size_t> kept{0};
  std::size_t max = 0;  ///< 0: no limit
  std::atomic<double> nearest{std::numeric_limits<double>::infinity()};

  /// Counts one more kept pair; true when the limit is now reached.
  bool add() { return kept.fetch_add(1, std::memory_order_relaxed) + 1 >= max && max != 0; }
  /// Whether the traversals have kept max pairs or more between them (never without a limit).
  [[nodiscard]] bool reached() const { return kept.load(std::memory_order_relaxed) >= max && max != 0; }
};

/// Depth-first traversal of the CD subtree at `root`: tests root as `root_test` says, then visits every
/// node that passes (narrow::visit), the kept pairs appended to `out`, every node and leaf test
/// counted in `stats`. With a taboo list, a child on it is neither tested nor entered, only marked.
/// Given `piece`, the pair's wide lanes (made once for its pieces), the traversal is one piece of a
/// split pair: without a limit, its last leaf pairs stay waiting in `scratch` for the next piece
/// of the pair on this thread (PieceCarry), and the caller has them finished
/// (TraversalScratch::flush_pieces) before it reads `out`.
inline void traverse_depth_first(const PairContext& ctx, NodePair root, TraversalScratch& scratch, std::vector<Candidate>& out,
                                 QueryStats& stats, RootTest root_test = RootTest::as_root, TabooView taboo = {},
                                 PairShared* limit = nullptr, const detail::WideLanes* piece = nullptr) {
  // Each visit pops one node and pushes at most eight, one level deeper in one of the trees: the
  // depth-first stack never holds more than 7 * (height A + height B) + 1 nodes (the loop without
  // a limit, whose visits wait a little, grows it where it must).
  std::vector<NodePair>& stack = scratch.stack;
  const auto bound = static_cast<std::size_t>(7 * (ctx.a().height + ctx.b().height) + 8);
  if (stack.size() < bound) stack.resize(bound);
  NodePair* base = stack.data();
  NodePair* top = base;
  QueryStats counted;
  if (root_test == RootTest::done || test_root(ctx, root, counted, root_test)) *top++ = root;
  NodePair passed[kMaxChildren];
  // The lanes, made only where the root passes: a pair refused at its root pays nothing.
  detail::WideLanes wide;
  detail::NodeLanes binary;
  VisitLanes lanes;
  // A piece without a limit carries its staying nodes and waiting leaf pairs to the next piece of
  // its pair on this thread (PieceCarry).
  const bool carried = piece != nullptr && limit == nullptr && top != base && wide_cd_tree(ctx);
  LeafBuffer own;
  LeafBuffer& buffer = carried ? scratch.piece_leaves(ctx, out) : own;
  if (top != base && wide_cd_tree(ctx)) {
    if (piece == nullptr) wide_lanes(ctx, wide);
    lanes.wide = piece != nullptr ? piece : &wide;
    lanes.staying = &scratch.staying_for(carried ? piece : nullptr);
  } else if (top != base) {
    binary = ctx.node_lanes();
    lanes.binary = &binary;
  }
  std::size_t seen = out.size();
  // Without a limit, the leaf pairs wait in a buffer for the batch kernels, and the children that
  // pass are written straight onto the stack, the first one on top (the order of cd_children), but
  // the pairs of leaves a wide visit tests itself (visit_until_empty).
  // With one, each leaf test's pair is counted as it is kept.
  if (limit == nullptr) {
    const auto size = static_cast<std::size_t>(top - base);
    if (lanes.wide != nullptr && kWideLoop != nullptr) {
      kWideLoop(ctx, stack, size, out, counted, taboo, buffer, lanes);
    } else {
      visit_until_empty(ctx, stack, size, out, counted, taboo, buffer, lanes);
    }
    top = base = stack.data();
  }
  // With a limit, the children's order keys (push_nearest_first).
  float order[kMaxChildren] = {};
  if (limit != nullptr && lanes.wide != nullptr) lanes.order = order;
  while (limit != nullptr && top != base) {
    const int count = visit(ctx, *--top, out, counted, passed, taboo, nullptr, lanes);
    // With a limit, after each leaf test: count what it kept, stop once the pair has enough.
    if (count < 0) {
      if (out.size() != seen) {
        seen = out.size();
        if (limit->add()) break;
      } else if (limit->reached()) {
        break;
      }
    }
    // Nearest boxes first (a pair-collecting query walks the wide tree).
    CALIBER_ASSERT(lanes.order != nullptr, "a traversal with a limit walks the wide tree");
    top = push_nearest_first(passed, order, count, top);
    CALIBER_ASSERT(static_cast<std::size_t>(top - base) <= bound, "the depth-first stack stays within its bound");
  }
  if (!carried) ctx.flush_leaves(buffer, out);
  stats.node_tests += counted.node_tests;
  stats.leaf_tests += counted.leaf_tests;
}

/// The closest triangle pair a distance traversal has found so far.
struct Nearest {
  bool found = false;
  Candidate best{};
  /// The nearest distance found by every traversal of the pair (the pieces of a split pair), or
  /// null for a traversal alone. Pruning by it gives the same answer: a node is dropped only when
  /// farther than some pair found (by more than the safety margin), and a pair exactly as close
  /// is still kept, so the closest pair with the lowest ids is in some piece's answer.
  std::atomic<double>* shared = nullptr;

  /// Keeps c if it is closer than the best by narrow::closer (ties: lower triangle ids), the order
  /// every method agrees on, so the answer does not depend on which pairs a traversal met first.
  void offer(const Candidate& c) {
    if (!found || closer(c, best)) {
      best = c;
      found = true;
      if (shared != nullptr) {
        double now = shared->load(std::memory_order_relaxed);
        while (c.distance < now && !shared->compare_exchange_weak(now, c.distance, std::memory_order_relaxed)) {}
      }
    }
  }
  /// The distance beyond which nothing can win: the best so far (this traversal's, or another's
  /// of the same pair), or the query's tolerance.
  [[nodiscard]] double bound(const PairContext& ctx) const {
    const double own = found ? best.distance : ctx.request().tolerance;
    return shared != nullptr ? std::min(own, shared->load(std::memory_order_relaxed)) : own;
  }
};

/// At most this many triangle pairs, a distance traversal tests them all (nearest_of_all_pairs):
/// on two tetrahedra (16 pairs, two batches of the kernels) 0.62 of the traversal's instructions
/// (callgrind, the AVX2 path).
inline constexpr std::size_t kFewPairs = 16;
/// Whether the models of ctx have at most kFewPairs triangle pairs.
inline bool few_pairs(const PairContext& ctx) {
  return ctx.a().mesh.triangles.size() * ctx.b().mesh.triangles.size() <= kFewPairs;
}

/// Where the meshes intersect, the pair the interference traversal from the root meets first
/// (PairContext::first_hit: the wide tree's first hit, far cheaper than the distance traversal's
/// bounds), offered at distance 0: true. Else false (its tests counted in `stats` all the same).
inline bool first_hit(const PairContext& ctx, TraversalScratch& scratch, Nearest& nearest, QueryStats& stats) {
  const PairContext hit = ctx.first_hit();
  PairShared limit;
  limit.max = 1;
  scratch.within.clear();
  traverse_depth_first(hit, NodePair{0, 0}, scratch, scratch.within, stats, RootTest::as_root, {}, &limit);
  if (scratch.within.empty()) return false;
  Candidate c;
  const bool kept = ctx.leaf_distance(scratch.within.front().tri_a, scratch.within.front().tri_b, nearest.bound(ctx), c);
  CALIBER_ASSERT(kept && c.distance == 0.0, "an intersecting pair is at distance 0");
  if (!kept || c.distance != 0.0) return false;  // (never: the best-first traversal would then answer)
  nearest.offer(c);
  return true;
}

/// The distance traversal of a pair of models with few triangles (few_pairs), from its root once
/// the root's bound is within reach: every triangle pair through the batch kernels
/// (as the proximity query's leaf tests, ta then tb in order), each kept pair offered to `nearest`.
/// So the nearest pair, ties (at distance 0 too) to the lowest ids: the brute force's answer.
/// Counts a leaf test per pair.
inline void nearest_of_all_pairs(const PairContext& ctx, TraversalScratch& scratch, Nearest& nearest, QueryStats& stats) {
  std::vector<Candidate>& within = scratch.within;
  within.clear();
  LeafBuffer buffer;
  const auto na = static_cast<std::uint32_t>(ctx.a().mesh.triangles.size());
  const auto nb = static_cast<std::uint32_t>(ctx.b().mesh.triangles.size());
  for (std::uint32_t ta = 0; ta < na; ++ta) {
    for (std::uint32_t tb = 0; tb < nb; ++tb) ctx.leaf_test(ta, tb, within, buffer);
  }
  ctx.flush_leaves(buffer, within);
  stats.leaf_tests += std::size_t{na} * nb;
  for (const Candidate& c : within) nearest.offer(c);
}

/// The distance bounds of the children of CD-tree node r (prepared nodes of A and B; a and b its
/// BVH nodes, not both leaves): calls wait(gap, child) for each in cd_children order, except those
/// on the taboo list (skipped and marked reached), each counted in stats.node_tests. The
/// children's prepared nodes are made by the first visit that descends into a node, found by its link
/// after that; a side that does not descend brings its own node.
template <class Wait>
[[gnu::always_inline]] inline void near_children(const PairContext& ctx, TraversalScratch& scratch, TraversalScratch::Reached r,
                                                 const BvhNode& a, const BvhNode& b, double reach, QueryStats& stats,
                                                 TabooView taboo, Wait&& wait) {
  using Reached = TraversalScratch::Reached;
  const auto prepare = [&](std::uint32_t i, auto& out) { ctx.near(i, out); };
  bool descend_a, descend_b;
  cd_descend(a, b, ctx.descend_alone_ratio(), descend_a, descend_b);
  TraversalScratch::NearA* const ka = descend_a ? scratch.near_a.kids(*r.a, a.index, prepare) : nullptr;
  TraversalScratch::NearB* const kb = descend_b ? scratch.near_b.kids(*r.b, b.index, prepare) : nullptr;
  if (descend_a && descend_b) {
    // Both sides descend: the four child pairs' bounds at once, then taken in cd_children order
    // as for_each_child takes them (a child on the taboo list marked reached, not counted).
    double gaps[4];
    ctx.gaps_2x2(ka[0], ka[1], kb[0], kb[1], reach, gaps);
    for_each_child_2x2(a.index, b.index, stats, taboo, [&](std::uint32_t k, NodePair) {
      wait(gaps[k], Reached{&ka[k / 2], &kb[k % 2]});
    });
    return;
  }
  // One side descends: its two children against the other node twice in the four lanes (lanes
  // 0 and 2, or 0 and 1); the enumeration below takes these prepared nodes.
  TraversalScratch::NearA* const a0 = descend_a ? &ka[0] : r.a;
  TraversalScratch::NearA* const a1 = descend_a ? &ka[1] : r.a;
  TraversalScratch::NearB* const b0 = descend_b ? &kb[0] : r.b;
  TraversalScratch::NearB* const b1 = descend_b ? &kb[1] : r.b;
  double gaps[4];
  ctx.gaps_2x2(*a0, *a1, *b0, *b1, reach, gaps);
  const auto prepared_a = [&](std::uint32_t i) { return i == a0->index ? a0 : a1; };
  const auto prepared_b = [&](std::uint32_t j) { return j == b0->index ? b0 : b1; };
  for_each_child(NodePair{r.a->index, r.b->index}, a, b, descend_a, descend_b, stats, taboo, prepared_a, prepared_b,
                 [&](TraversalScratch::NearA* sa, TraversalScratch::NearB* sb, NodePair) {
                   wait(gaps[(sa == a0 ? 0 : 2) + (sb == b0 ? 0 : 1)], Reached{sa, sb});
                 });
}

/// The leaf pairs of a distance traversal waiting in scratch.leaves (PairContext::wait_leaf),
/// tested within the bound at once (the batch kernels), each kept pair offered to `nearest`: true
/// where one is at distance 0 and the traversal stops at contact.
inline bool nearest_of_leaves(const PairContext& ctx, TraversalScratch& scratch, Nearest& nearest, bool stop_at_contact) {
  scratch.within.clear();
  ctx.flush_leaves(scratch.leaves, scratch.within, nearest.bound(ctx));
  bool contact = false;
  for (const Candidate& c : scratch.within) {
    nearest.offer(c);
    contact = contact || c.distance == 0.0;
  }
  return stop_at_contact && contact;
}

/// A distance traversal's leaf pair (ta, tb): tested at once until one is kept (its bound prunes
/// from then on), then waiting for the batch kernels, tested eight at a time when the batch is
/// full or the traversal runs out of nodes (nearest_of_leaves), within the bound as it is then.
/// True where the traversal stops (a pair at distance 0, stop_at_contact).
inline bool leaf_pair(const PairContext& ctx, std::uint32_t ta, std::uint32_t tb, TraversalScratch& scratch, Nearest& nearest,
                      bool stop_at_contact) {
  if (nearest.found) return ctx.wait_leaf(ta, tb, scratch.leaves) && nearest_of_leaves(ctx, scratch, nearest, stop_at_contact);
  Candidate c;
  if (!ctx.leaf_distance(ta, tb, nearest.bound(ctx), c)) return false;
  nearest.offer(c);
  return stop_at_contact && c.distance == 0.0;
}

/// The distance traversal (branch and bound, best first) of the CD subtree rooted at `root`: the
/// nodes that pass their test wait by their gap (PairContext::gap, a lower bound on the distance
/// below them) in buckets of gaps within 1/256 of each other (util::GapBuckets); a node of the
/// nearest bucket is visited next, each child tested within the best distance found so far, a
/// node popped beyond that distance is dropped, and the traversal ends when every waiting node is
/// farther than that distance by more than the safety margin. Each node's fate depends only on its
/// gap and the best distance, so any order within a bucket gives the same answer; a visited node's
/// nearest child is visited next directly when no waiting node is in a nearer bucket. A node or
/// pair exactly as close as the best is still examined, so ties go to the lowest ids; but at
/// distance 0 (the meshes intersect) the traversal stops at the first batch of leaf pairs that
/// holds one (leaf_pair), unless the request asks for the lowest ids (QueryRequest::lowest_ids);
/// so that it finds one sooner, among children at gap 0 the most overlapping spheres go first
/// (touching_first). Counts node and leaf tests like
/// traverse_depth_first; honours a taboo list the same way. (A binary heap's
/// sift took a large part of the bunny's time; the buckets are faster than a 4-ary heap too.)
/// A whole traversal (from the root, no taboo list; its root passed, or tested here) of models
/// with few triangle pairs tests every pair (nearest_of_all_pairs), ties at distance 0 too to the
/// lowest ids; of other models, unless it asks for the lowest ids, it first asks for the first hit
/// (first_hit), which where the meshes intersect is its answer. Either way its answer is the
/// pair's (as found: ContactPair::as_found); a piece of a split traversal meets a contact of its
/// own, which the pair's finalization replaces (ContactPair::from_root).
inline void traverse_nearest(const PairContext& ctx, NodePair root, TraversalScratch& scratch, Nearest& nearest,
                             QueryStats& stats, RootTest root_test = RootTest::as_root, TabooView taboo = {}) {
  using Reached = TraversalScratch::Reached;
  using Waiting = util::GapBuckets<Reached>::Entry;
  const bool stop_at_contact = !ctx.request().lowest_ids;
  util::GapBuckets<Reached>& queue = scratch.waiting;
  queue.clear();
  scratch.near_a.clear();
  scratch.near_b.clear();
  // Nearest bucket first (within a bucket, last in first out: an order that depends only on the
  // order they came in, the same on every run).
  Waiting next;  // the node to visit next
  bool have_next = false;
  {
    const double reach = ctx.reach_for(nearest.bound(ctx));
    const auto prepare = [&](std::uint32_t i, auto& out) { ctx.near(i, out); };
    const Reached r{scratch.near_a.root(root.a, prepare), scratch.near_b.root(root.b, prepare)};
    const double root_gap = ctx.gap(*r.a, *r.b, reach);
    if (root_test == RootTest::done || (++stats.node_tests, root_gap <= reach)) {
      next = Waiting{root_gap, r};
      have_next = true;
    }
  }
  const bool whole = have_next && root == NodePair{0, 0} && taboo.taboo == nullptr;
  if (whole && few_pairs(ctx)) {
    nearest_of_all_pairs(ctx, scratch, nearest, stats);
    return;
  }
  if (whole && stop_at_contact && ctx.request().first_hit && first_hit(ctx, scratch, nearest, stats)) return;
  scratch.leaves.refusal.batch.size = scratch.leaves.closest.batch.size = 0;
  for (;;) {
    const double reach = ctx.reach_for(nearest.bound(ctx));
    if (!have_next) {
      // Done when every node still waiting is farther than the reach, and no leaf pair waits.
      if (queue.empty() || queue.floor_of(queue.min_bucket()) > reach) {
        if (scratch.leaves.refusal.batch.size == 0 || nearest_of_leaves(ctx, scratch, nearest, stop_at_contact)) break;
        continue;
      }
      next = queue.pop();
    }
    have_next = false;
    const auto [gap, r] = next;
    if (gap > reach) continue;
    const NodePair n{r.a->index, r.b->index};
    const BvhNode& a = ctx.a().nodes[n.a];
    const BvhNode& b = ctx.b().nodes[n.b];
    if (a.is_leaf() && b.is_leaf()) {
      ++stats.leaf_tests;
      if (leaf_pair(ctx, a.index, b.index, scratch, nearest, stop_at_contact)) break;
      continue;
    }
    Waiting kids[4];
    int count = 0, nearest_kid = -1, touching = 0;
    const auto wait = [&](double child_gap, Reached child) {
      if (child_gap > reach) return;
      if (nearest_kid < 0 || child_gap < kids[nearest_kid].key) nearest_kid = count;
      touching += child_gap == 0.0 ? 1 : 0;
      kids[count++] = Waiting{child_gap, child};
    };
    near_children(ctx, scratch, r, a, b, reach, stats, taboo, wait);
    // Children at gap 0 (touching, as far as the bounds tell), when the traversal stops at contact
    // and there are several: the one whose spheres overlap the most (PairContext::sphere_apart)
    // counts as the nearest, and the others wait so that the next most overlapping is popped first
    // (a bucket is last in, first out): the traversal meets a contact sooner.
    int order[4] = {0, 1, 2, 3};
    if (stop_at_contact && touching > 1) touching_first(ctx, kids, count, order, nearest_kid);
    // The nearest child is visited next without going through the queue when no waiting node is
    // in a nearer bucket (popping could give it next); the others wait.
    if (nearest_kid >= 0 && (queue.empty() || queue.bucket_of(kids[nearest_kid].key) <= queue.min_bucket())) {
      next = kids[nearest_kid];
      have_next = true;
    }
    for (int i = 0; i < count; ++i) {
      const int k = order[i];
      if (have_next && k == nearest_kid) continue;
      queue.push(kids[k].key, kids[k].value);
    }
  }
}

/// The traversal every schedule runs on its pieces: for a distance query, traverse_nearest (the
/// piece's closest pair, if any, appended to `out`; pruning by the pair's nearest distance so far,
/// if `shared` is given), otherwise traverse_depth_first (stopping early at the pair's limit, if
/// `shared` is given; a piece that carries its leaf pairs to the next where `piece` is given).
inline void traverse(const PairContext& ctx, NodePair root, TraversalScratch& scratch, std::vector<Candidate>& out,
                     QueryStats& stats, RootTest root_test = RootTest::as_root, TabooView taboo = {},
                     PairShared* shared = nullptr, const detail::WideLanes* piece = nullptr) {
  if (ctx.request().kind == QueryKind::distance) {
    Nearest nearest;
    nearest.shared = shared != nullptr ? &shared->nearest : nullptr;
    traverse_nearest(ctx, root, scratch, nearest, stats, root_test, taboo);
    if (nearest.found) out.push_back(nearest.best);
    return;
  }
  traverse_depth_first(ctx, root, scratch, out, stats, root_test, taboo, shared, piece);
}

}  // namespace caliber::narrow
