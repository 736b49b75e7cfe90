// The order in which a traversal that stops early takes a visit's children: the depth-first one
// with max_pairs (push_nearest_first, by the boxes' order keys), the distance one at contact
// (touching_first, by PairContext::sphere_apart); ties in cd_children order. (Which pair such a
// traversal meets first is its own choice; the answers' tests are elsewhere.)

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/model.h"
#include "caliber/query.h"
#include "narrow/cd_tree.h"
#include "narrow/traversal.h"
#include "narrow/visit.h"
#include "narrow/visit_order.h"
#include "support/random_poses.h"
#include "support/torus_sphere.h"

namespace caliber {
namespace {

const test::TorusSphere& shapes() { return test::torus_sphere(); }

bool leaf_pair(const narrow::PairContext& ctx, narrow::NodePair n) {
  return ctx.a().nodes[n.a].is_leaf() && ctx.b().nodes[n.b].is_leaf();
}

/// Every CD node of the first `levels` levels of the pair's tree, breadth first.
std::vector<narrow::NodePair> top_of_tree(const narrow::PairContext& ctx, int levels) {
  std::vector<narrow::NodePair> all, level{{0, 0}};
  for (int depth = 0; depth < levels; ++depth) {
    std::vector<narrow::NodePair> next;
    for (const narrow::NodePair n : level) {
      if (leaf_pair(ctx, n)) continue;
      narrow::NodePair kids[narrow::kMaxChildren];
      next.insert(next.end(), kids, kids + narrow::cd_children(ctx, n, kids));
    }
    all.insert(all.end(), level.begin(), level.end());
    level = std::move(next);
  }
  return all;
}

/// The keys of w's slots as the definition says them, in double: the sum of the center offsets
/// over the sum of the extents, from the slots' grid bounds and the staying box in `kept`.
std::vector<double> keys_by_definition(const narrow::detail::StayingCache::Entry& kept, const WideNode& w) {
  std::vector<double> keys;
  for (int k = 0; k < w.count(); ++k) {
    double offset = 0.0, extent = 0.0;
    for (int i = 0; i < 3; ++i) {
      offset += std::abs((double(w.low(i, k)) + w.high(i, k)) - (double(kept.lo[i]) + kept.hi[i]));
      extent += (double(w.high(i, k)) - w.low(i, k)) + (double(kept.hi[i]) - kept.lo[i]);
    }
    keys.push_back(offset / extent);
  }
  return keys;
}

TEST(VisitOrder, LimitedTraversalPopsTheNearestBoxesFirst) {
  std::mt19937_64 rng(4);
  int checked = 0, reordered = 0, written = 0;
  narrow::detail::StayingCache staying;
  for (int i = 0; i < 20; ++i) {
    const narrow::PairContext ctx(*shapes().torus, test::random_pose(rng, 0.5), *shapes().sphere, test::random_pose(rng, 0.5),
                                  QueryRequest{});
    const narrow::detail::WideLanes lanes = narrow::wide_lanes(ctx);
    staying.renew();
    for (const narrow::NodePair n : top_of_tree(ctx, 6)) {
      if (leaf_pair(ctx, n)) continue;
      // The visit as a limited traversal makes it: the children that pass, each with its key.
      std::vector<narrow::Candidate> out;
      QueryStats stats;
      narrow::NodePair passed[narrow::kMaxChildren];
      float order[narrow::kMaxChildren];
      const int passing = narrow::visit(ctx, n, out, stats, passed, {}, nullptr, {nullptr, &lanes, &staying, order});
      const narrow::WideVisit v = narrow::wide_visit(ctx, n, ctx.a().nodes[n.a], ctx.b().nodes[n.b]);
      bool held = false;
      const auto& kept = staying.find(v.stay, v.a_descends, held);
      ASSERT_TRUE(held) << "the visit kept its staying node";
      float keys[WideNode::kSlots];
      narrow::detail::slot_order_keys_portable(kept, *v.node, keys);
      const std::vector<double> defined = keys_by_definition(kept, *v.node);
      narrow::NodePair kids[narrow::kMaxChildren], stack[narrow::kMaxChildren];
      const int count = narrow::cd_children(ctx, n, kids);
      const auto slot_of = [&](narrow::NodePair c) { return static_cast<int>(std::find(kids, kids + count, c) - kids); };
      for (int k = 0; k < passing; ++k) ASSERT_LT(slot_of(passed[k]), count) << "a child of the visit";
      for (int k = 0; k < passing && passing >= 2; ++k, ++written) {
        ASSERT_EQ(std::bit_cast<std::uint32_t>(order[k]), std::bit_cast<std::uint32_t>(keys[slot_of(passed[k])])) << "its key";
      }
      for (int k = 0; k < count; ++k) EXPECT_NEAR(keys[k], defined[k], 1e-5 * (1.0 + defined[k])) << "the key is its definition";
      // Every child pushed with its key, as a limited traversal pushes them, then popped.
      narrow::NodePair* const top = narrow::push_nearest_first(kids, keys, count, stack);
      ASSERT_EQ(top - stack, count);
      const std::vector<narrow::NodePair> popped(std::make_reverse_iterator(top), std::make_reverse_iterator(stack));
      for (int k = 0; k < count; ++k) ASSERT_EQ(std::count(popped.begin(), popped.end(), kids[k]), 1) << "every child once";
      for (int k = 1; k < count; ++k) {
        const int before = slot_of(popped[k - 1]), after = slot_of(popped[k]);
        ASSERT_LE(keys[before], keys[after]) << "pose " << i << ": the nearer boxes first";
        if (keys[before] == keys[after]) EXPECT_LT(before, after) << "ties in cd_children order";
      }
      reordered += std::equal(kids, kids + count, popped.begin()) ? 0 : 1;
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_GT(written, 1000);
  EXPECT_GT(reordered, checked / 10) << "the order differs from cd_children's where the keys say so";
}

TEST(VisitOrder, SlotOrderKeysAreTheSameInEveryForm) {
  if (narrow::kSlotOrderKeys == nullptr) GTEST_SKIP() << "this CPU has one form";
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<float> coordinate(-2.0f, 2.0f);
  int checked = 0;
  for (const Model* model : {shapes().torus.get(), shapes().sphere.get()}) {
    for (const WideNode& w : data(*model).wide) {
      // Staying boxes near the slots and far from them (1e4 of the models' size away).
      for (const float far : {1.0f, 1e4f}) {
        narrow::detail::StayingCache::Entry kept{};
        for (int i = 0; i < 3; ++i) {
          const float x = far * coordinate(rng), y = far * coordinate(rng);
          kept.lo[i] = std::min(x, y);
          kept.hi[i] = std::max(x, y);
        }
        float portable[WideNode::kSlots], chosen[WideNode::kSlots];
        narrow::detail::slot_order_keys_portable(kept, w, portable);
        narrow::kSlotOrderKeys(kept, w, chosen);
        for (int k = 0; k < w.count(); ++k) {
          ASSERT_EQ(std::bit_cast<std::uint32_t>(portable[k]), std::bit_cast<std::uint32_t>(chosen[k])) << "slot " << k;
          ASSERT_GE(portable[k], 0.0f);
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(VisitOrder, DistanceAtContactTakesTheMostOverlappingTouchingChildFirst) {
  using Reached = narrow::TraversalScratch::Reached;
  using Waiting = util::GapBuckets<Reached>::Entry;
  std::mt19937_64 rng(5);
  QueryRequest request;
  request.kind = QueryKind::distance;
  request.tolerance = kUnbounded;
  int checked = 0;
  for (int i = 0; i < 10; ++i) {
    const narrow::PairContext ctx(*shapes().torus, test::random_pose(rng, 0.5), *shapes().sphere, test::random_pose(rng, 0.5),
                                  request);
    for (const narrow::NodePair n : top_of_tree(ctx, 5)) {
      if (leaf_pair(ctx, n)) continue;
      narrow::NodePair kids[narrow::kMaxChildren];
      const int count = narrow::cd_children(ctx, n, kids);
      if (count < 2) continue;
      // Every pattern of children at gap 0 (the others at gaps 1, 2, ...), each child's prepared nodes its own.
      for (int zeros = 0; zeros < (1 << count); ++zeros) {
        std::vector<narrow::TraversalScratch::NearA> na(static_cast<std::size_t>(count));
        std::vector<narrow::TraversalScratch::NearB> nb(static_cast<std::size_t>(count));
        for (int k = 0; k < count; ++k) {
          ctx.near(kids[k].a, static_cast<narrow::NearA&>(na[k]));
          ctx.near(kids[k].b, static_cast<narrow::NearB&>(nb[k]));
        }
        Waiting waiting[4];
        for (int k = 0; k < count; ++k) waiting[k] = Waiting{(zeros >> k) & 1 ? 0.0 : 1.0 + k, Reached{&na[k], &nb[k]}};
        int order[4] = {0, 1, 2, 3}, nearest = -1;
        narrow::touching_first(ctx, waiting, count, order, nearest);
        std::vector<int> seen(order, order + count);
        std::sort(seen.begin(), seen.end());
        for (int k = 0; k < count; ++k) ASSERT_EQ(seen[k], k) << "every child once";
        const int positive = count - __builtin_popcount(static_cast<unsigned>(zeros));
        for (int k = 0; k < count; ++k) {
          EXPECT_EQ(waiting[order[k]].key == 0.0, k >= positive) << "the children at a positive gap first";
          if (k > 0 && k < positive) EXPECT_LT(order[k - 1], order[k]) << "in cd_children order";
          if (k > positive) {
            const double before = ctx.sphere_apart(kids[order[k - 1]].a, kids[order[k - 1]].b);
            const double after = ctx.sphere_apart(kids[order[k]].a, kids[order[k]].b);
            ASSERT_GE(before, after) << "the touching ones from the least overlapping to the most";
            if (before == after) EXPECT_GT(order[k - 1], order[k]) << "equals popped in cd_children order";
          }
        }
        if (positive < count) EXPECT_EQ(nearest, order[count - 1]) << "the most overlapping is visited next";
        ++checked;
      }
      // Equals: the first child in every place, all at gap 0: the first is visited next, and the
      // rest wait in reverse, to be popped in cd_children order.
      narrow::TraversalScratch::NearA a0;
      narrow::TraversalScratch::NearB b0;
      ctx.near(kids[0].a, static_cast<narrow::NearA&>(a0));
      ctx.near(kids[0].b, static_cast<narrow::NearB&>(b0));
      Waiting equal[4];
      for (int k = 0; k < count; ++k) equal[k] = Waiting{0.0, Reached{&a0, &b0}};
      int order[4] = {0, 1, 2, 3}, nearest = -1;
      narrow::touching_first(ctx, equal, count, order, nearest);
      EXPECT_EQ(nearest, 0);
      for (int k = 0; k < count; ++k) EXPECT_EQ(order[k], count - 1 - k);
    }
  }
  EXPECT_GT(checked, 500);
}

}  // namespace
}  // namespace caliber
