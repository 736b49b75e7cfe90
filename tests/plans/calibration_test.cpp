// Calibration rules in isolation: Omega, keep / split / cart at the epsilon boundaries, cart merging.

#include <gtest/gtest.h>

#include "plans/calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <queue>
#include <tuple>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/procedural.h"
#include "parallel/executor.h"
#include "plans/weights.h"

namespace caliber::plans {
namespace {

Root item(std::uint32_t pair, double weight) { return Root{pair, narrow::NodePair{0, 0}, false, weight}; }

TEST(Calibration, ThresholdIsTotalOverBetaThreads) {
  EXPECT_DOUBLE_EQ(caliber_threshold(1200.0, 2.0, 4), 150.0);
  EXPECT_DOUBLE_EQ(caliber_threshold(1200.0, 1.0, 1), 1200.0);
  EXPECT_GT(caliber_threshold(0.0, 2.0, 4), 0.0) << "a step without work still has a positive caliber";
}

TEST(Calibration, ClassifyAtTheEpsilonBoundaries) {
  EXPECT_EQ(classify(100.0, 100.0, 10.0), Verdict::keep);
  EXPECT_EQ(classify(110.0, 100.0, 10.0), Verdict::keep) << "Omega + eps is kept";
  EXPECT_EQ(classify(90.0, 100.0, 10.0), Verdict::keep) << "Omega - eps is kept";
  EXPECT_EQ(classify(110.000001, 100.0, 10.0), Verdict::split);
  EXPECT_EQ(classify(89.999999, 100.0, 10.0), Verdict::cart);
  EXPECT_EQ(classify(100.0, 100.0, 0.0), Verdict::keep);
}

TEST(Calibration, CartMergesHeaviestWithLightestUntilOmega) {
  // Omega 10: 9 takes 1 (=10); 8 takes 1, 2 (=11); 7 takes 3 (=10); 6 alone is left with nothing? No:
  // 6 takes 4 (=10); 5 is last and alone.
  std::vector<Root> cart = {item(0, 5), item(1, 1), item(2, 9), item(3, 2), item(4, 8),
                            item(5, 1), item(6, 7), item(7, 3), item(8, 6), item(9, 4)};
  const std::vector<RunTask> tasks = merge_cart(cart, 10.0);
  ASSERT_EQ(tasks.size(), 5u);
  // Each task's roots in the cart's order: 9 (pair 2) with 1 (pair 1) comes out {1, 9}.
  const std::vector<std::vector<double>> want = {{1, 9}, {2, 8, 1}, {7, 3}, {6, 4}, {5}};
  for (std::size_t t = 0; t < tasks.size(); ++t) {
    std::vector<double> got;
    for (const Root& r : tasks[t].roots) got.push_back(r.weight);
    EXPECT_EQ(got, want[t]) << "task " << t;
  }
  std::size_t roots = 0;
  for (const RunTask& t : tasks) {
    EXPECT_FALSE(t.roots.empty());
    roots += t.roots.size();
  }
  EXPECT_EQ(roots, cart.size()) << "every item in exactly one task";
}

TEST(Calibration, CartEdgeCases) {
  EXPECT_TRUE(merge_cart({}, 10.0).empty());
  const auto one = merge_cart({item(0, 3)}, 10.0);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].roots.size(), 1u);
  // 300 tiny items of weight 1 with Omega 25: 12 tasks of 25 (the heaviest-first rule, all equal).
  std::vector<Root> tiny;
  for (std::uint32_t i = 0; i < 300; ++i) tiny.push_back(item(i, 1.0));
  const auto tasks = merge_cart(tiny, 25.0);
  EXPECT_EQ(tasks.size(), 12u);
  for (const RunTask& t : tasks) EXPECT_EQ(t.weight, 25.0);
}

/// The merge by its definition: the items sorted by (weight, pair, node) with std::sort, the
/// heaviest left taking the lightest left until omega; each task's items in cart order.
std::vector<std::vector<std::size_t>> reference_merge(const std::vector<Root>& cart, double omega) {
  std::vector<std::size_t> order(cart.size());
  for (std::size_t k = 0; k < cart.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    const Root &p = cart[x], &q = cart[y];
    return std::tie(p.weight, p.pair, p.node.a, p.node.b) < std::tie(q.weight, q.pair, q.node.a, q.node.b);
  });
  std::vector<std::vector<std::size_t>> tasks;
  std::size_t light = 0, heavy = order.size();
  while (light < heavy) {
    std::vector<std::size_t>& t = tasks.emplace_back(1, order[--heavy]);
    double w = cart[t[0]].weight;
    while (w < omega && light < heavy) {
      t.push_back(order[light]);
      w += cart[order[light++]].weight;
    }
    std::sort(t.begin(), t.end());
  }
  return tasks;
}

TEST(Calibration, CartMergeEqualsTheDefinitionOnRandomCarts) {
  // Tied weights (measured node tests are integers), weights spread over many orders of magnitude,
  // nodes above 2^24 and pairs above 2^16 (every byte of the radix sort's keys), and carts with a
  // zero or infinite weight (sorted by comparison instead).
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const std::size_t n = 1 + rng() % 3000;
    std::vector<Root> cart;
    double total = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      double w = 0.0;
      switch (trial % 4) {
        case 0:
          w = static_cast<double>(1 + rng() % 40);
          break;  // ties
        case 1:
          w = std::ldexp(1.0 + static_cast<double>(rng() % 1000) / 1000.0, static_cast<int>(rng() % 80) - 40);
          break;
        case 2:
          w = 1.0 + static_cast<double>(rng() % 1000000) * 1e-3;
          break;
        default:
          w = static_cast<double>(rng() % 5);
          break;  // zeros: the fallback
      }
      const auto pair = static_cast<std::uint32_t>(rng() % (trial % 2 == 0 ? 50 : 200000));
      const narrow::NodePair node{static_cast<std::uint32_t>(rng() % 3 == 0 ? rng() : rng() % 8),
                                  static_cast<std::uint32_t>(rng() % 3 == 0 ? rng() : rng() % 8)};
      cart.push_back(Root{pair, node, false, w});
      total += w;
    }
    if (trial == 7) cart[n / 2].weight = std::numeric_limits<double>::infinity();
    // No two items share pair and node (the cart's total order).
    std::sort(cart.begin(), cart.end(), [](const Root& x, const Root& y) {
      return std::tie(x.pair, x.node.a, x.node.b) < std::tie(y.pair, y.node.a, y.node.b);
    });
    cart.erase(
        std::unique(cart.begin(), cart.end(), [](const Root& x, const Root& y) { return x.pair == y.pair && x.node == y.node; }),
        cart.end());
    if (trial % 3 != 0) std::shuffle(cart.begin(), cart.end(), rng);  // else in (pair, node) order, as whole pairs come
    for (std::size_t k = 0; k < cart.size(); ++k) cart[k].stage = static_cast<std::int32_t>(k);  // identifies the item
    const double omega = total / static_cast<double>(1 + rng() % 40);
    const std::vector<std::vector<std::size_t>> want = reference_merge(cart, omega);
    const std::vector<RunTask> got = merge_cart(cart, omega);
    ASSERT_EQ(got.size(), want.size()) << "trial " << trial;
    for (std::size_t t = 0; t < got.size(); ++t) {
      std::vector<std::size_t> items;
      for (const Root& r : got[t].roots) items.push_back(static_cast<std::size_t>(r.stage));
      ASSERT_EQ(items, want[t]) << "trial " << trial << ", task " << t;
    }
  }
}

TEST(Calibration, SubtreeCountsAddUpTheStage) {
  // The root's visit tested two children: child 1 passed and became a sub-task root (its
  // depth-first traversal took 10 node tests), child 2 failed (no record of its own).
  std::vector<StageRecord> stage(2);
  stage[0].node = {0, 0};
  stage[0].children = 2;
  stage[0].passed = 0b01;
  stage[0].child[0] = {1, 1};
  stage[0].child[1] = {2, 1};
  stage[1].node = {1, 1};
  stage[1].root = true;
  const NodeCounts counts = subtree_counts(stage, {0, 10});
  ASSERT_EQ(counts.size(), 3u);
  EXPECT_EQ(counts[0], std::make_pair(narrow::NodePair{0, 0}, std::uint64_t{13}));
  EXPECT_EQ(counts[1], std::make_pair(narrow::NodePair{1, 1}, std::uint64_t{11}));
  EXPECT_EQ(counts[2], std::make_pair(narrow::NodePair{2, 1}, std::uint64_t{1}));
}

TEST(Calibration, SummaryTreeCountsTheContactsBelowEachNode) {
  const auto a = build_model(make_sphere(1.0, 8, 12));
  const auto b = build_model(make_torus(1.0, 0.3, 10, 8));
  std::vector<TrianglePair> reported;
  for (std::uint32_t i = 0; i < 40; ++i) reported.push_back({(i * 7) % 192, (i * 13) % 160});
  // The summary follows the CD tree of the query's kind (the distance query descends both sides
  // more often): every child is a child of its node there, and the two trees differ here.
  std::vector<std::vector<narrow::NodePair>> nodes_of_kind;
  int both_and_one[2] = {0, 0};
  const narrow::PairContext ctx_for_root(*a, Pose{}, *b, Pose{}, QueryRequest{});
  for (const QueryKind kind : {QueryKind::distance, QueryKind::interference}) {
    QueryRequest request;
    request.kind = kind;
    const narrow::PairContext kind_ctx(*a, Pose{}, *b, Pose{}, request);
    const auto kind_summary = build_summary(kind_ctx, reported);
    nodes_of_kind.emplace_back();
    for (const SummaryNode& s : kind_summary) {
      nodes_of_kind.back().push_back(s.node);
      narrow::NodePair kids[narrow::kMaxChildren];
      const int count = s.children == 0 ? 0 : narrow::cd_children(kind_ctx, s.node, kids);
      for (std::uint32_t c = 0; c < s.children; ++c) {
        const narrow::NodePair child = kind_summary[s.first + c].node;
        EXPECT_NE(std::find(kids, kids + count, child), kids + count) << to_string(kind);
        // Each child is tested as its parent's visit tests it: in the binary tree (distance), with
        // the disks where both sides descend; in the wide tree, as a slot of the side that descends.
        const narrow::RootTest want = kind == QueryKind::distance
                                          ? (count == 4 ? narrow::RootTest::with_disks : narrow::RootTest::as_root)
                                          : (child.a != s.node.a ? narrow::RootTest::child_of_a : narrow::RootTest::child_of_b);
        EXPECT_EQ(kind_summary[s.first + c].test, want) << to_string(kind);
        both_and_one[want == narrow::RootTest::with_disks || want == narrow::RootTest::child_of_a] += 1;
      }
    }
  }
  EXPECT_NE(nodes_of_kind[0], nodes_of_kind[1]);
  EXPECT_GT(both_and_one[0], 0);
  EXPECT_GT(both_and_one[1], 0);
  EXPECT_EQ(build_summary(ctx_for_root, reported)[0].test, narrow::RootTest::as_root) << "the root is tested as a root";
  const narrow::PairContext ctx(*a, Pose{}, *b, Pose{}, QueryRequest{});
  const auto summary = build_summary(ctx, reported);
  ASSERT_FALSE(summary.empty());
  EXPECT_EQ(summary[0].contacts, reported.size());
  for (const SummaryNode& s : summary) {
    if (s.children == 0) {
      const BvhNode &la = data(*a).nodes[s.node.a], &lb = data(*b).nodes[s.node.b];
      EXPECT_TRUE(la.is_leaf() && lb.is_leaf()) << "only leaf pairs end the summary";
      // Each reported pair ends at the leaves of its own two triangles.
      const auto own = std::count_if(reported.begin(), reported.end(),
                                     [&](const TrianglePair& p) { return p.tri_a == la.index && p.tri_b == lb.index; });
      EXPECT_EQ(static_cast<std::uint32_t>(own), s.contacts);
      continue;
    }
    std::uint32_t below = 0;
    for (std::uint32_t c = 0; c < s.children; ++c) below += summary[s.first + c].contacts;
    EXPECT_EQ(below, s.contacts);
  }
  EXPECT_TRUE(build_summary(ctx, {}).empty());
  // Splitting it: chosen roots are distinct, sorted on the taboo list, and never the root.
  const PosterioriSplit split = split_aposteriori(summary, 0, 4000.0, 500.0, 50.0, 64);
  EXPECT_FALSE(split.taboo.empty());
  EXPECT_TRUE(std::is_sorted(split.taboo.begin(), split.taboo.end()));
  EXPECT_EQ(split.taboo.size(), split.roots.size() + split.cart.size());
  for (const narrow::NodePair& n : split.taboo) EXPECT_FALSE(n.a == 0 && n.b == 0);
  EXPECT_LE(split_aposteriori(summary, 0, 4000.0, 500.0, 50.0, 3).taboo.size(), 3u) << "the cap holds";
  // Each root is tested as its parent's visit would test it.
  for (const std::vector<Root>* list : {&split.roots, &split.cart}) {
    for (const Root& r : *list) {
      const auto s = std::find_if(summary.begin(), summary.end(), [&](const SummaryNode& x) { return x.node == r.node; });
      ASSERT_NE(s, summary.end());
      EXPECT_EQ(r.test, s->test);
      EXPECT_EQ(r.root_test(), s->test);
    }
  }
}

/// The paper's alternate traversal as written (and as split_pair ran it until it went level by
/// level): a max-heap of untested nodes keyed by weight; pop the heaviest, test it, leaf-test a leaf
/// pair, push the children of a heavy node, keep or cart a light one. The reference for the cut.
SplitResult priority_queue_stage(const narrow::PairContext& ctx, std::uint32_t pair, double root_weight, double scale,
                                 double omega, double eps) {
  struct Entry {
    double weight;
    narrow::NodePair node;
    narrow::NodePair parent;  ///< whose visit tests it (narrow::child_test); the root's its own
    bool operator<(const Entry& o) const {
      if (weight != o.weight) return weight < o.weight;
      if (node.a != o.node.a) return node.a > o.node.a;
      return node.b > o.node.b;
    }
  };
  SplitResult out;
  std::priority_queue<Entry> queue;
  queue.push(Entry{root_weight, narrow::NodePair{0, 0}, narrow::NodePair{0, 0}});
  narrow::NodePair kids[narrow::kMaxChildren];
  while (!queue.empty()) {
    const Entry e = queue.top();
    queue.pop();
    ++out.stats.node_tests;
    if (!narrow::child_test(ctx, e.parent, e.node)) continue;
    const BvhNode& a = ctx.a().nodes[e.node.a];
    const BvhNode& b = ctx.b().nodes[e.node.b];
    if (a.is_leaf() && b.is_leaf()) {
      ++out.stats.leaf_tests;
      ctx.leaf_test(a.index, b.index, out.candidates);
      continue;
    }
    const Verdict v = classify(e.weight, omega, eps);
    if (v == Verdict::split) {
      const int count = narrow::cd_children(ctx, e.node, kids);
      for (int i = 0; i < count; ++i) queue.push(Entry{scale * apriori_weight(ctx, kids[i]), kids[i], e.node});
    } else {
      (v == Verdict::keep ? out.roots : out.cart).push_back(Root{pair, e.node, true, e.weight});
    }
  }
  return out;
}

using RootKey = std::tuple<std::uint32_t, std::uint32_t, double, bool>;

/// The roots in their order (the run-time task list keeps it for equal weights).
std::vector<RootKey> keys(const std::vector<Root>& roots) {
  std::vector<RootKey> k;
  for (const Root& r : roots) k.emplace_back(r.node.a, r.node.b, r.weight, r.tested);
  return k;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs(const std::vector<narrow::Candidate>& c) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> p;
  for (const narrow::Candidate& x : c) p.emplace_back(x.tri_a, x.tri_b);
  std::sort(p.begin(), p.end());
  return p;
}

TEST(Calibration, LevelStageCutsAsThePriorityQueueDoesAtAnyThreadCount) {
  const auto a = build_model(make_sphere(1.0, 24, 32));
  const auto b = build_model(make_torus(1.0, 0.3, 40, 24));
  QueryRequest request;
  request.kind = QueryKind::contact;
  request.tolerance = 0.05;
  const narrow::PairContext ctx(*a, Pose{}, *b, Pose::from_values(0.2, 0.1, 0.9, 0.9, 0.3, 0.1, 0.2), request);
  const double root = 40000.0;
  const double scale = root / apriori_weight(ctx, narrow::NodePair{0, 0});
  int compared = 0;
  for (const double omega : {root / 4, root / 24, root / 96, root / 400}) {
    const SplitResult want = priority_queue_stage(ctx, 0, root, scale, omega, 0.25 * omega);
    ASSERT_GT(want.stats.node_tests, 1u);
    for (const int threads : {1, 2, 4}) {
      parallel::Executor executor(threads);
      SplitResult got;
      executor.execute([&] { got = split_pair(ctx, 0, root, scale, omega, 0.25 * omega); });
      EXPECT_EQ(keys(got.roots), keys(want.roots)) << "omega " << omega << ", " << threads << " threads";
      // The cart in any order (merge_cart sorts it by weight, pair and node, a total order).
      std::vector<RootKey> got_cart = keys(got.cart), want_cart = keys(want.cart);
      std::sort(got_cart.begin(), got_cart.end());
      std::sort(want_cart.begin(), want_cart.end());
      EXPECT_EQ(got_cart, want_cart) << "omega " << omega << ", " << threads << " threads";
      EXPECT_EQ(pairs(got.candidates), pairs(want.candidates));
      EXPECT_EQ(got.stats.node_tests, want.stats.node_tests);
      EXPECT_EQ(got.stats.leaf_tests, want.stats.leaf_tests);
      // One record per node that passed; every node tested is the root or a child some visit tested.
      std::uint64_t tested = 1;
      for (const StageRecord& r : got.stage) tested += r.children;
      EXPECT_EQ(tested, got.stats.node_tests) << "every node tested once, by the root's test or its parent's visit";
      // Parents before children (what the node history adds up in reverse), every root's record
      // marked, and the same records whatever the thread count.
      for (const Root& r : got.roots) EXPECT_TRUE(got.stage[static_cast<std::size_t>(r.stage)].root);
      if (threads == 1) continue;
      SplitResult one;
      parallel::Executor single(1);
      single.execute([&] { one = split_pair(ctx, 0, root, scale, omega, 0.25 * omega); });
      ASSERT_EQ(one.stage.size(), got.stage.size());
      for (std::size_t k = 0; k < one.stage.size(); ++k) {
        EXPECT_EQ(one.stage[k].node, got.stage[k].node);
        EXPECT_EQ(one.stage[k].children, got.stage[k].children);
        EXPECT_EQ(one.stage[k].passed, got.stage[k].passed);
      }
      ++compared;
    }
  }
  EXPECT_EQ(compared, 8);
}

}  // namespace
}  // namespace caliber::plans
