// Methods as plans, tested without the runner: a plan covers each pair's CD tree exactly once
// (its stage and its run-time tasks, traversed here one after another, find what caliber::query
// finds with the same node tests), in hand-out order heaviest first.

#include <algorithm>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "support/results.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"
#include "plans/plan.h"
#include "plans/validate.h"
#include "plans/weights.h"

namespace caliber::plans {
namespace {

struct Pairs {
  std::shared_ptr<const Model> torus = build_model(make_torus(1.0, 0.3, 40, 24));
  std::shared_ptr<const Model> sphere = build_model(make_sphere(1.0, 24, 32));
  std::shared_ptr<const Model> box = build_model(make_box(0.2, 0.2, 0.2, 2));
  std::vector<ObjectPair> pairs{ObjectPair{0, 1}, ObjectPair{0, 2}};
  std::vector<Pose> poses{Pose{}, Pose::from_values(0.2, 0.1, 0.3, 0.9, 0.3, 0.1, 0.2),
                          Pose::from_values(1.0, 0.0, 0.0, 1, 0, 0, 0)};
  QueryRequest request;
  std::vector<narrow::PairContext> contexts;
  Pairs() {
    request.kind = QueryKind::proximity;
    request.tolerance = 0.05;
    contexts.emplace_back(*torus, poses[0], *sphere, poses[1], request);
    contexts.emplace_back(*torus, poses[0], *box, poses[2], request);
  }
};

/// Runs a plan's tasks one after another on this thread and returns, per pair, the sorted triangle
/// pairs found and the node tests made (the stage's included).
std::vector<std::pair<std::vector<TrianglePair>, std::uint64_t>> run_serially(const Plan& plan, const Pairs& p) {
  std::vector<std::vector<narrow::Candidate>> found(p.pairs.size());
  std::vector<QueryStats> stats(p.pairs.size());
  for (std::size_t s = 0; s < plan.splits.size(); ++s) {
    const std::uint32_t i = plan.split_pairs[s];
    found[i] = plan.splits[s].candidates;
    stats[i] = plan.splits[s].stats;
  }
  narrow::TraversalScratch scratch;
  for (const RunTask& t : plan.run) {
    EXPECT_FALSE(t.roots.empty());
    for (const Root& r : t.roots) {
      std::vector<char> reached(r.taboo >= 0 ? plan.taboos[r.taboo].nodes.size() : 0);
      const narrow::TabooView taboo =
          r.taboo >= 0 ? narrow::TabooView{&plan.taboos[r.taboo], reached.data()} : narrow::TabooView{};
      narrow::traverse_depth_first(p.contexts[r.pair], r.node, scratch, found[r.pair], stats[r.pair], r.root_test(), taboo);
    }
  }
  std::vector<std::pair<std::vector<TrianglePair>, std::uint64_t>> out;
  for (std::size_t i = 0; i < p.pairs.size(); ++i) {
    std::vector<TrianglePair> pairs;
    for (const narrow::Candidate& c : found[i]) pairs.push_back({c.tri_a, c.tri_b});
    std::sort(pairs.begin(), pairs.end(),
              [](auto x, auto y) { return std::pair(x.tri_a, x.tri_b) < std::pair(y.tri_a, y.tri_b); });
    out.emplace_back(pairs, stats[i].node_tests);
  }
  return out;
}

void expect_covers_like_query(const Plan& plan, const Pairs& p, const std::string& what) {
  EXPECT_EQ(plan_problem(plan, p.pairs.size()), "") << what;
  const auto got = run_serially(plan, p);
  for (std::size_t i = 0; i < p.pairs.size(); ++i) {
    const ObjectPair t = p.pairs[i];
    const Model& b = t.b == 1 ? *p.sphere : *p.box;
    const QueryResult want = query(*p.torus, p.poses[t.a], b, p.poses[t.b], p.request);
    ASSERT_EQ(got[i].first.size(), want.contacts.size()) << what << " pair " << i;
    for (std::size_t k = 0; k < want.contacts.size(); ++k) {
      EXPECT_EQ(got[i].first[k].tri_a, want.contacts[k].tri_a) << what;
      EXPECT_EQ(got[i].first[k].tri_b, want.contacts[k].tri_b) << what;
    }
    EXPECT_EQ(got[i].second, want.stats.node_tests) << what << " pair " << i << ": each CD node tested once";
  }
}

TEST(Plans, WholePairsInPairOrder) {
  const Plan plan = plan_pairs(3);
  ASSERT_EQ(plan.run.size(), 3u);
  for (std::uint32_t i = 0; i < 3; ++i) {
    ASSERT_EQ(plan.run[i].roots.size(), 1u);
    EXPECT_EQ(plan.run[i].roots[0].pair, i);
    EXPECT_FALSE(plan.run[i].roots[0].tested);
  }
  EXPECT_FALSE(plan.weighted);
  const Pairs p;
  expect_covers_like_query(plan_pairs(p.pairs.size()), p, "whole pairs");
}

TEST(Plans, APrioriSplitsTheHeavyPairAndCoversItOnce) {
  const Pairs p;
  EngineOptions options;
  options.method = Method::apriori;
  options.threads = 8;
  const Plan plan = plan_calibrated(options, p.pairs, p.contexts, History{});
  ASSERT_GE(plan.split, 1u);
  EXPECT_EQ(plan.split_pairs.front(), 0u) << "the torus-sphere pair is heavy";
  EXPECT_EQ(plan.splits.size(), plan.split);
  EXPECT_GT(plan.run.size(), 8u);
  EXPECT_TRUE(std::is_sorted(plan.run.begin(), plan.run.end(), [](const RunTask& x, const RunTask& y) {
    return x.weight > y.weight;
  })) << "handed out heaviest first";
  expect_covers_like_query(plan, p, "apriori");
}

// plan_problem finds each kind of broken plan it names, and none in the plans the methods make.
TEST(Plans, ProblemsOfBrokenPlansAreFound) {
  const Pairs p;
  EngineOptions options;
  options.method = Method::apriori;
  options.threads = 8;
  const Plan good = plan_calibrated(options, p.pairs, p.contexts, History{});
  ASSERT_EQ(plan_problem(good, p.pairs.size()), "");
  ASSERT_GE(good.split, 1u);
  const auto broken = [&](auto&& change) {
    Plan plan = good;
    change(plan);
    return plan_problem(plan, p.pairs.size());
  };
  const auto first_root = [](Plan& plan) -> Root& { return const_cast<Root&>(plan.run.front().roots[0]); };
  EXPECT_NE(broken([](Plan& plan) { plan.run.front().roots = RootList{}; }), "");
  EXPECT_NE(broken([](Plan& plan) { plan.run.front().weight = -1.0; }), "");
  EXPECT_NE(broken([](Plan& plan) { plan.run.front().weight += 1.0; }), "") << "the sum of the roots' weights";
  EXPECT_NE(broken([&](Plan& plan) { first_root(plan).pair = 7; }), "");
  EXPECT_NE(broken([&](Plan& plan) { first_root(plan).taboo = 3; }), "");
  EXPECT_NE(broken([&](Plan& plan) { first_root(plan).stage = 1 << 20; }), "");
  EXPECT_NE(broken([](Plan& plan) { plan.splits.pop_back(); }), "");
  EXPECT_NE(broken([](Plan& plan) { plan.run.push_back(plan_pairs(2).run[1]); }), "") << "a pair run from its root twice";
  EXPECT_NE(broken([](Plan& plan) { plan.run.push_back(plan_pairs(1).run[0]); }), "") << "a split pair run from its root";
  EXPECT_EQ(plan_problem(plan_pairs(3), 3), "");
  EXPECT_NE(plan_problem(plan_pairs(2), 3), "") << "a pair never run";
}

TEST(Plans, HybridScalesByLastStepsNodeTests) {
  const Pairs p;
  EngineOptions options;
  options.method = Method::hybrid;
  options.threads = 4;
  History history;
  history.node_tests[p.pairs[0]] = 1000;
  const InitialWeights w = initial_weights(Method::hybrid, p.pairs, p.contexts, history);
  EXPECT_DOUBLE_EQ(w.weight[0], 1000.0 + kPairWeight) << "a pair with history weighs what it took, and the pair's own work";
  EXPECT_DOUBLE_EQ(w.scale[1], w.scale[0]) << "a pair without takes the measured ratio";
  EXPECT_DOUBLE_EQ(scale_of(w, p.contexts, 0), 1000.0 / apriori_weight(p.contexts[0], {0, 0}));
  expect_covers_like_query(plan_calibrated(options, p.pairs, p.contexts, history), p, "hybrid");
}

TEST(Plans, HybridRatioComesFromAnEvenSampleOfThePairsWithHistory) {
  // More pairs with history than the sample holds: the ratio for the pairs without comes from
  // every stride-th pair with history, and the others' roots are estimated only when asked for.
  const Pairs p;
  const std::size_t known = 2 * kRatioSample + 3, fresh = 5, n = known + fresh;
  std::vector<narrow::PairContext> contexts;
  std::vector<ObjectPair> pairs;
  History history;
  for (std::size_t i = 0; i < n; ++i) {
    contexts.push_back(p.contexts[i % 2]);
    pairs.push_back(ObjectPair{0, static_cast<std::uint32_t>(i + 1)});
    if (i < known) history.node_tests[pairs.back()] = 100 + i % 7;
  }
  const narrow::PairContexts view{contexts.data(), contexts.size()};
  const InitialWeights w = initial_weights(Method::hybrid, pairs, view, history);
  const std::size_t stride = (known + kRatioSample - 1) / kRatioSample;
  double measured = 0.0, estimated = 0.0;
  std::size_t sampled = 0;
  for (std::size_t i = 0; i < known; i += stride, ++sampled) {
    measured += static_cast<double>(100 + i % 7);
    estimated += apriori_weight(contexts[i], {0, 0});
  }
  EXPECT_LE(sampled, kRatioSample);
  const double ratio = measured / estimated;
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double root = apriori_weight(contexts[i], {0, 0});
    if (i < known) {
      EXPECT_EQ(w.weight[i], static_cast<double>(100 + i % 7) + kPairWeight) << "pair " << i;
      EXPECT_DOUBLE_EQ(scale_of(w, view, i), static_cast<double>(100 + i % 7) / root) << "pair " << i;
    } else {
      EXPECT_DOUBLE_EQ(w.scale[i], ratio) << "pair " << i;
      EXPECT_DOUBLE_EQ(w.weight[i], ratio * root + kPairWeight) << "pair " << i;
    }
    total += w.weight[i];
  }
  EXPECT_DOUBLE_EQ(w.total, total);

  // Thousands of light pairs: the cart is merged into tasks 16 times finer than Omega (a dozen
  // tasks of Omega would end on a long tail), each pair in exactly one task.
  EngineOptions options;
  options.method = Method::hybrid;
  options.threads = 2;
  const Plan plan = plan_calibrated(options, pairs, view, history);
  ASSERT_EQ(plan.split, 0u);
  EXPECT_EQ(plan.carted, n);
  const double cart_omega = plan.omega / static_cast<double>(kCartFiner);
  std::vector<int> seen(n, 0);
  double heaviest = 0.0;
  for (std::size_t i = 0; i < n; ++i) heaviest = std::max(heaviest, w.weight[i]);
  for (const RunTask& t : plan.run) {
    EXPECT_LT(t.weight, cart_omega + heaviest) << "a task passes the cart's caliber by less than one item";
    for (const Root& r : t.roots) ++seen[r.pair];
  }
  EXPECT_GE(plan.run.size(), static_cast<std::size_t>(w.total / (cart_omega + heaviest)));
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int k) { return k == 1; }));
}

TEST(Plans, PairTableFindsSortedPairsInOneMerge) {
  PairTable<int> table;
  for (const auto& [p, v] : {std::pair{ObjectPair{0, 3}, 1}, {ObjectPair{1, 2}, 2}, {ObjectPair{2, 5}, 3}, {ObjectPair{4, 6}, 4}})
    table[p] = v;
  // Absent pairs before, between and after the keys; a pair twice (the batch repeats one pair).
  const std::vector<ObjectPair> asked = {{0, 1}, {0, 3}, {1, 2}, {1, 2}, {1, 9}, {4, 6}, {7, 8}};
  const std::vector<const int*> found = table.find_sorted(asked);
  ASSERT_EQ(found.size(), asked.size());
  for (std::size_t i = 0; i < asked.size(); ++i) EXPECT_EQ(found[i], table.find(asked[i])) << "pair " << i;
  EXPECT_EQ(*found[1], 1);
  EXPECT_EQ(*found[3], 2);
  EXPECT_EQ(*found[5], 4);
  EXPECT_EQ(found[0], nullptr);
  EXPECT_EQ(found[6], nullptr);
  EXPECT_TRUE(PairTable<int>{}.find_sorted(asked)[1] == nullptr);
}

TEST(Plans, APosterioriSplitsOnLastStepsContactsWithTabooLists) {
  const Pairs p;
  EngineOptions options;
  options.method = Method::aposteriori;
  options.threads = 8;
  History history;
  const QueryResult last = query(*p.torus, p.poses[0], *p.sphere, p.poses[1], p.request);
  ASSERT_GT(last.contacts.size(), 10u);
  history.reported[p.pairs[0]] = test::pairs_of(last);
  history.node_tests[p.pairs[0]] = last.stats.node_tests;
  const Plan plan = plan_calibrated(options, p.pairs, p.contexts, history);
  ASSERT_EQ(plan.taboos.size(), 1u);
  EXPECT_GT(plan.taboo_nodes, 0u);
  EXPECT_TRUE(std::is_sorted(plan.taboos[0].nodes.begin(), plan.taboos[0].nodes.end()));
  // The sub-tasks may test below a node the original task prunes: the contacts are the same, the
  // node tests at least query's.
  const auto got = run_serially(plan, p);
  EXPECT_EQ(got[0].first.size(), last.contacts.size());
  EXPECT_GE(got[0].second, last.stats.node_tests);
}

}  // namespace
}  // namespace caliber::plans
