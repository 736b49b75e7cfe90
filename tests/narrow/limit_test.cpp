// QueryRequest::max_pairs: a query that finds that many pairs stops there, says so, and reports
// only pairs of the full answer (with the full answer's bits); one that finds fewer is unchanged.
// On the engine, every method and thread count keeps to the limit (which pairs may differ).

#include <algorithm>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "support/results.h"
#include "caliber/engine.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/random_poses.h"
#include "support/torus_sphere.h"

namespace caliber {
namespace {

const test::TorusSphere& shapes() { return test::torus_sphere(); }

/// Every reported pair of `part` is in `full`, with the same contact to the last bit.
void expect_part_of(const QueryResult& part, const QueryResult& full, const std::string& what) {
  const std::vector<TrianglePair> full_pairs = test::pairs_of(full), part_pairs = test::pairs_of(part);
  for (std::size_t k = 0; k < part.contacts.size(); ++k) {
    const auto it = std::lower_bound(full_pairs.begin(), full_pairs.end(), part_pairs[k]);
    ASSERT_TRUE(it != full_pairs.end() && *it == part_pairs[k]) << what << ": a pair the full answer lacks";
    if (!full.contacts.empty()) {
      const Contact& a = part.contacts[k];
      const Contact& b = full.contacts[static_cast<std::size_t>(it - full_pairs.begin())];
      EXPECT_EQ(a.distance, b.distance) << what;
      EXPECT_EQ(a.point_a, b.point_a) << what;
      EXPECT_EQ(a.point_b, b.point_b) << what;
    }
  }
}

TEST(MaxPairs, StopsEarlyFlagsAndReportsOnlyTrueAnswers) {
  const Pose pb = Pose::from_values(0.9, 0.1, 0.05, 1, 0.2, 0.1, 0);
  for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity}) {
    QueryRequest request;
    request.kind = kind;
    request.tolerance = 0.02;
    const QueryResult full = query(*shapes().torus, Pose{}, *shapes().sphere, pb, request);
    ASSERT_GT(full.contacts.size(), 20u) << "the test pose must give many pairs";
    EXPECT_FALSE(full.limit_reached);
    for (const std::size_t limit : {std::size_t{1}, std::size_t{7}, full.contacts.size() - 1}) {
      request.max_pairs = limit;
      const std::string what = std::string(to_string(kind)) + " limit " + std::to_string(limit);
      const QueryResult part = query(*shapes().torus, Pose{}, *shapes().sphere, pb, request);
      EXPECT_TRUE(part.limit_reached) << what;
      EXPECT_EQ(part.contacts.size(), limit) << what;
      expect_part_of(part, full, what);
      if (limit < 10) EXPECT_LT(part.stats.leaf_tests, full.stats.leaf_tests) << what << ": it stopped early";
    }
    // A limit of the answer's size: every pair, flagged (it stopped at the last one it found,
    // before the traversal's end); one more: every pair, the whole traversal, unflagged.
    request.max_pairs = full.contacts.size();
    const QueryResult at = query(*shapes().torus, Pose{}, *shapes().sphere, pb, request);
    EXPECT_TRUE(at.limit_reached) << "the query cannot know there is no more";
    EXPECT_EQ(test::pairs_of(at), test::pairs_of(full));
    expect_part_of(at, full, "limit of the answer's size");
    request.max_pairs = full.contacts.size() + 1;
    const QueryResult same = query(*shapes().torus, Pose{}, *shapes().sphere, pb, request);
    EXPECT_FALSE(same.limit_reached) << "a limit the answer does not reach changes nothing";
    test::expect_identical(same, full, "limit " + std::to_string(request.max_pairs));
    EXPECT_EQ(same.stats.node_tests, full.stats.node_tests);
    EXPECT_EQ(same.stats.leaf_tests, full.stats.leaf_tests);
    EXPECT_LT(at.stats.node_tests + at.stats.leaf_tests, same.stats.node_tests + same.stats.leaf_tests)
        << to_string(kind) << ": at the limit it stops at once";
  }
}

TEST(MaxPairs, FirstAnswersWhetherTheyTouch) {
  std::mt19937_64 rng(9);
  QueryRequest any;
  any.max_pairs = 1;
  int touching = 0;
  for (int i = 0; i < 60; ++i) {
    const Pose pa = test::random_pose(rng, 1.0);
    const Pose pb = test::random_pose(rng, 1.0);
    const QueryResult full = query(*shapes().torus, pa, *shapes().sphere, pb, QueryRequest{});
    const QueryResult first = query(*shapes().torus, pa, *shapes().sphere, pb, any);
    ASSERT_EQ(first.contacts.empty(), full.contacts.empty()) << "pose " << i;
    EXPECT_EQ(first.limit_reached, !full.contacts.empty()) << "pose " << i;
    expect_part_of(first, full, "pose " + std::to_string(i));
    touching += full.contacts.empty() ? 0 : 1;
  }
  EXPECT_GT(touching, 10);
  EXPECT_LT(touching, 55);
}

/// Calls f(engine, name) with an engine of every method at 1 and at 3 threads.
template <class F>
void for_each_engine(F&& f) {
  for (const Method method :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    for (const int threads : {1, 3}) {
      EngineOptions options;
      options.method = method;
      options.threads = threads;
      Engine engine(options);
      f(engine, std::string(to_string(method)) + " x" + std::to_string(threads));
    }
  }
}

TEST(MaxPairs, EveryMethodKeepsToTheLimit) {
  Frame frame;
  frame.models = {shapes().torus, shapes().sphere, shapes().torus};
  frame.poses = {Pose{}, Pose::from_values(0.9, 0.1, 0.05, 1, 0.2, 0.1, 0), Pose::from_values(0.2, 0.3, 0.1, 1, 0, 0.3, 0.1)};
  frame.pairs = {ObjectPair{0, 1}, ObjectPair{0, 2}, ObjectPair{1, 2}};
  frame.request.kind = QueryKind::proximity;
  frame.request.tolerance = 0.02;
  std::map<std::pair<std::uint32_t, std::uint32_t>, QueryResult> full;
  for (const ObjectPair& t : frame.pairs) {
    const QueryResult& f = full[{t.a, t.b}] =
        query(*frame.models[t.a], frame.poses[t.a], *frame.models[t.b], frame.poses[t.b], frame.request);
    ASSERT_GT(f.contacts.size(), 30u) << t.a << "-" << t.b;
  }
  frame.request.max_pairs = 25;
  for_each_engine([&](Engine& engine, const std::string& what) {
    const StepResult step = engine.step(frame);
    EXPECT_TRUE(step.limit_reached) << what;
    for (const PairRecord& t : step.pair_records) {
      EXPECT_TRUE(t.limit_reached) << what;
      EXPECT_EQ(t.contacts, 25u) << what;
    }
    for (const Contact& c : step.contacts) {
      const QueryResult& f = full[{c.object_a, c.object_b}];
      const std::vector<TrianglePair> f_pairs = test::pairs_of(f);
      const auto it = std::lower_bound(f_pairs.begin(), f_pairs.end(), TrianglePair{c.tri_a, c.tri_b});
      ASSERT_TRUE(it != f_pairs.end() && *it == (TrianglePair{c.tri_a, c.tri_b})) << what;
      EXPECT_EQ(c.point_a, f.contacts[static_cast<std::size_t>(it - f_pairs.begin())].point_a) << what;
    }
  });
}

TEST(MaxPairs, EveryMethodFlagsALimitOfTheAnswersSizeAlike) {
  // A limit the answer reaches exactly: every pair reported, flagged (no traversal can know there
  // is no more); one more: every pair, unflagged. The same on every method and thread count.
  Frame frame;
  frame.models = {shapes().torus, shapes().sphere};
  frame.poses = {Pose{}, Pose::from_values(0.9, 0.1, 0.05, 1, 0.2, 0.1, 0)};
  frame.pairs = {ObjectPair{0, 1}};
  frame.request.kind = QueryKind::proximity;
  frame.request.tolerance = 0.02;
  const QueryResult full = query(*frame.models[0], frame.poses[0], *frame.models[1], frame.poses[1], frame.request);
  ASSERT_GT(full.contacts.size(), 20u);
  for (const std::size_t limit : {full.contacts.size(), full.contacts.size() + 1}) {
    frame.request.max_pairs = limit;
    for_each_engine([&](Engine& engine, const std::string& name) {
      const std::string what = name + " limit " + std::to_string(limit);
      const StepResult step = engine.step(frame);
      EXPECT_EQ(step.limit_reached, limit == full.contacts.size()) << what;
      ASSERT_EQ(step.contacts.size(), full.contacts.size()) << what;
      for (std::size_t k = 0; k < full.contacts.size(); ++k) {
        EXPECT_EQ(step.contacts[k].tri_a, full.contacts[k].tri_a) << what;
        EXPECT_EQ(step.contacts[k].tri_b, full.contacts[k].tri_b) << what;
        EXPECT_EQ(step.contacts[k].distance, full.contacts[k].distance) << what;
      }
    });
  }
}

TEST(MaxPairs, DistanceIgnoresIt) {
  QueryRequest request;
  request.kind = QueryKind::distance;
  request.tolerance = kUnbounded;
  const Pose pb = Pose::from_values(3, 0, 0, 1, 0, 0, 0);
  const QueryResult plain = query(*shapes().torus, Pose{}, *shapes().sphere, pb, request);
  request.max_pairs = 1;
  const QueryResult limited = query(*shapes().torus, Pose{}, *shapes().sphere, pb, request);
  test::expect_identical(limited, plain, "distance");
  EXPECT_FALSE(limited.limit_reached);
}

}  // namespace
}  // namespace caliber
