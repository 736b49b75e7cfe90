// The distance query: the closest triangle pair, against the brute-force minimum (same pair, same
// bits) at gaps from 1e-6 to 1 of the meshes' size, in contact, within and beyond a tolerance, and
// on the engine: every method and thread count gives the query's answer bit for bit.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "support/results.h"
#include "bvh/model_data.h"
#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

QueryRequest distance_request(double tolerance = kUnbounded) {
  QueryRequest r;
  r.kind = QueryKind::distance;
  r.tolerance = tolerance;
  return r;
}

struct Shapes {
  std::shared_ptr<const Model> sphere = build_model(make_sphere(1.0, 10, 14));
  std::shared_ptr<const Model> torus = build_model(make_torus(1.0, 0.35, 14, 10));
  std::shared_ptr<const Model> box = build_model(make_box(0.8, 0.5, 0.3, 3));
};

const Shapes& shapes() {
  static const Shapes s;
  return s;
}

/// B placed along a random direction so that its bounding sphere's gap to A's is `gap`, randomly
/// turned: the true gap between the meshes is then at least `gap` and usually a little more.
Pose separated(std::mt19937_64& rng, const Model& a, const Model& b, double gap) {
  const Pose turned = test::random_pose(rng, 0.0);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Vector3d dir(g(rng), g(rng), g(rng));
  dir.normalize();
  const double ra = data(a).nodes[0].radius, rb = data(b).nodes[0].radius;
  const Eigen::Vector3d ca(data(a).nodes[0].center[0], data(a).nodes[0].center[1], data(a).nodes[0].center[2]);
  const Eigen::Vector3d cb(data(b).nodes[0].center[0], data(b).nodes[0].center[1], data(b).nodes[0].center[2]);
  const Eigen::Vector3d where = ca + dir * (ra + rb + gap) - turned.rotation * cb;
  return Pose{turned.rotation, where};
}

/// The query against the oracle: with lowest_ids, identical to it; by default identical where the
/// meshes are apart, and where they intersect distance 0 on a pair the oracle finds intersecting,
/// with that pair's closest points (what lowest_ids gives for the same pair). Returns the default
/// answer.
QueryResult expect_oracle(const Model& a, const Pose& pa, const Model& b, const Pose& pb, QueryRequest request,
                          const std::string& what) {
  request.lowest_ids = true;
  const QueryResult slow = query_brute_force(a, pa, b, pb, request);
  const QueryResult exhaustive = query(a, pa, b, pb, request);
  test::expect_identical(exhaustive, slow, what + " (lowest ids)");
  request.lowest_ids = false;
  const QueryResult fast = query(a, pa, b, pb, request);
  if (slow.contacts.empty() || slow.contacts.front().distance > 0.0) {
    test::expect_identical(fast, slow, what);
    return fast;
  }
  EXPECT_EQ(fast.contacts.size(), 1u) << what;
  if (fast.contacts.size() != 1) return fast;
  const Contact& c = fast.contacts.front();
  EXPECT_EQ(c.distance, 0.0) << what;
  QueryRequest meet;
  meet.kind = QueryKind::interference;
  const QueryResult all = query_brute_force(a, pa, b, pb, meet);
  EXPECT_TRUE(std::any_of(all.contacts.begin(), all.contacts.end(),
                          [&](const Contact& k) { return k.tri_a == c.tri_a && k.tri_b == c.tri_b; }))
      << what << ": the pair reported at distance 0 intersects";
  EXPECT_LE(fast.stats.node_tests, exhaustive.stats.node_tests) << what << ": the first contact ends the traversal";
  return fast;
}

TEST(Distance, EqualsTheBruteForceMinimumAtEveryScaleOfGap) {
  std::mt19937_64 rng(7);
  const Model* models[] = {shapes().sphere.get(), shapes().torus.get(), shapes().box.get()};
  int cases = 0;
  for (const double gap : {1e-6, 1e-4, 1e-2, 0.1, 0.5, 1.0, 2.0}) {
    for (int k = 0; k < 6; ++k) {
      const Model& a = *models[k % 3];
      const Model& b = *models[(k + 1) % 3];
      const Pose pa = test::random_pose(rng, 0.0);
      const Pose pb_local = separated(rng, a, b, gap);
      const Pose pb{pa.rotation * pb_local.rotation, pa.apply(pb_local.translation)};
      const std::string what = "gap " + std::to_string(gap) + " case " + std::to_string(k);
      const QueryResult fast = query(a, pa, b, pb, distance_request());
      const QueryResult slow = query_brute_force(a, pa, b, pb, distance_request());
      test::expect_identical(fast, slow, what);
      ASSERT_EQ(fast.contacts.size(), 1u) << what;
      const Contact& c = fast.contacts.front();
      EXPECT_GE(c.distance, gap * (1 - 1e-9)) << what << ": the spheres' gap is a lower bound";
      EXPECT_NEAR((c.point_b - c.point_a).norm(), c.distance, 1e-12 * (1 + c.distance)) << what;
      EXPECT_LT(fast.stats.leaf_tests, slow.stats.leaf_tests / 20) << what << ": the bound prunes";
      ++cases;
    }
  }
  EXPECT_EQ(cases, 42);
}

TEST(Distance, KeptOrientedBoxesChangeNothing) {
  // Models built with BuildOptions::oriented_boxes give the same answer, bit for bit, after the
  // same node and leaf tests (the bound reads the same numbers), and the oracle's.
  BuildOptions kept;
  kept.oriented_boxes = true;
  const auto torus = build_model(make_torus(1.0, 0.35, 14, 10), kept);
  const auto box = build_model(make_box(0.8, 0.5, 0.3, 3), kept);
  std::mt19937_64 rng(11);
  for (const double gap : {1e-6, 1e-3, 0.1, 1.0}) {
    for (int k = 0; k < 4; ++k) {
      const Pose pa = test::random_pose(rng, 0.0);
      const Pose pb_local = separated(rng, *shapes().torus, *shapes().box, gap);
      const Pose pb{pa.rotation * pb_local.rotation, pa.apply(pb_local.translation)};
      const std::string what = "gap " + std::to_string(gap) + " case " + std::to_string(k);
      const QueryResult computed = query(*shapes().torus, pa, *shapes().box, pb, distance_request());
      const QueryResult read = query(*torus, pa, *box, pb, distance_request());
      test::expect_identical(read, computed, what);
      EXPECT_EQ(read.stats.node_tests, computed.stats.node_tests) << what;
      EXPECT_EQ(read.stats.leaf_tests, computed.stats.leaf_tests) << what;
      // One side with them, the other without.
      test::expect_identical(query(*torus, pa, *shapes().box, pb, distance_request()), computed, what + " (A's kept)");
      test::expect_identical(query_brute_force(*torus, pa, *box, pb, distance_request()), computed, what + " (oracle)");
    }
  }
}

TEST(Distance, RandomPosesAgreeWithTheOracleIncludingOverlaps) {
  std::mt19937_64 rng(11);
  const auto torus = build_model(make_torus(1.0, 0.35, 10, 6));
  const auto sphere = build_model(make_sphere(1.0, 6, 8));
  int overlapping = 0, apart = 0;
  for (int i = 0; i < 80; ++i) {
    const Model& a = *torus;
    const Model& b = i % 2 ? *sphere : *torus;
    const Pose pa = test::random_pose(rng, 1.2);
    const Pose pb = test::random_pose(rng, 1.2);
    const QueryResult fast = expect_oracle(a, pa, b, pb, distance_request(), "pose " + std::to_string(i));
    ASSERT_EQ(fast.contacts.size(), 1u);
    (fast.contacts.front().distance == 0.0 ? overlapping : apart)++;
  }
  EXPECT_GT(overlapping, 10) << "overlapping poses must be tested: the first contact, or the lowest ids at 0";
  EXPECT_GT(apart, 10);
}

// Where the meshes intersect, the distance query reports the first hit: the pair an interference
// query stopping at one pair finds (and the oracle finds intersecting), at distance 0.
TEST(Distance, AtContactTheFirstHitIsReported) {
  std::mt19937_64 rng(23);
  const auto torus = build_model(make_torus(1.0, 0.35, 24, 12));
  const auto sphere = build_model(make_sphere(1.0, 12, 16));
  QueryRequest first;
  first.max_pairs = 1;
  int hits = 0;
  for (int i = 0; i < 60; ++i) {
    const Model& b = i % 2 ? *sphere : *torus;
    const Pose pa = test::random_pose(rng, 1.0), pb = test::random_pose(rng, 1.0);
    const QueryResult hit = query(*torus, pa, b, pb, first);
    const QueryResult near = query(*torus, pa, b, pb, distance_request());
    ASSERT_EQ(near.contacts.size(), 1u);
    if (hit.contacts.empty()) {
      EXPECT_GT(near.contacts.front().distance, 0.0) << "pose " << i << ": no intersecting pair, no contact";
      continue;
    }
    ++hits;
    EXPECT_EQ(near.contacts.front().distance, 0.0) << "pose " << i;
    EXPECT_EQ(near.contacts.front().tri_a, hit.contacts.front().tri_a) << "pose " << i;
    EXPECT_EQ(near.contacts.front().tri_b, hit.contacts.front().tri_b) << "pose " << i;
    // Without the first hit: distance 0 too, on a pair the oracle's test finds intersecting.
    QueryRequest alone = distance_request();
    alone.first_hit = false;
    const QueryResult own = query(*torus, pa, b, pb, alone);
    ASSERT_EQ(own.contacts.size(), 1u);
    EXPECT_EQ(own.contacts.front().distance, 0.0) << "pose " << i;
    QueryRequest every;  // every intersecting pair
    const QueryResult all = query(*torus, pa, b, pb, every);
    EXPECT_TRUE(std::any_of(
        all.contacts.begin(), all.contacts.end(),
        [&](const Contact& x) { return x.tri_a == own.contacts.front().tri_a && x.tri_b == own.contacts.front().tri_b; }))
        << "pose " << i;
  }
  EXPECT_GT(hits, 15) << "intersecting poses must be tested";
}

// Parallel plates facing each other, shifted sideways: every triangle pair across the gap that
// overlaps sideways is exactly as close as the closest, so the answer is decided by the tie rule
// (lowest ids), and the nodes' bounds in their slab's frame are as tight as they get (a prune
// that is one rounding too eager shows here). Then slightly tilted, and far apart.
TEST(Distance, FacingPlatesTieAndTheLowestIdsWin) {
  const auto plate = build_model(make_plate(1.0, 0.02, 8));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> shift(-0.75, 0.75);
  int cases = 0;
  for (const double gap : {0.0, 1e-9, 0.001, 0.25, 3.0}) {
    for (int k = 0; k < 4; ++k) {
      const double sx = k == 0 ? 0.0 : shift(rng), sy = k == 0 ? 0.0 : shift(rng);
      Pose pb{Eigen::Quaterniond::Identity(), Eigen::Vector3d(sx, sy, 0.02 + gap)};
      if (k == 3) pb.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(1e-4, Eigen::Vector3d(1.0, 2.0, 0.0).normalized()));
      const std::string what = "gap " + std::to_string(gap) + " case " + std::to_string(k);
      const QueryResult fast = expect_oracle(*plate, Pose{}, *plate, pb, distance_request(), what);
      ASSERT_EQ(fast.contacts.size(), 1u) << what;
      ++cases;
    }
  }
  EXPECT_EQ(cases, 20);
}

/// The single queries' answers for the frame's pairs, in its order.
std::vector<Contact> queries_of(const Frame& frame) {
  std::vector<Contact> want;
  for (const ObjectPair& t : frame.pairs) {
    const QueryResult r = query(*frame.models[t.a], frame.poses[t.a], *frame.models[t.b], frame.poses[t.b], frame.request);
    for (const Contact& c : test::between(r, t.a, t.b)) want.push_back(c);
  }
  return want;
}

/// Every method on 1 to 3 threads, cut into many tasks, reports `want` bit for bit, two steps each
/// (the second uses what the temporal methods learnt); then also(engine, what) on each engine.
template <class Also>
void expect_every_method(const Frame& frame, const std::vector<Contact>& want, Also&& also) {
  for (const Method method :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    for (const int threads : {1, 2, 3}) {
      EngineOptions options;
      options.method = method;
      options.threads = threads;
      options.beta = 16;  // many tasks, so that pairs are split
      options.stealing_depth = 3;
      Engine engine(options);
      const std::string what = std::string(to_string(method)) + " x" + std::to_string(threads);
      for (int step = 0; step < 2; ++step) {
        const StepResult got = engine.step(frame);
        ASSERT_EQ(got.contacts.size(), want.size()) << what;
        for (std::size_t i = 0; i < want.size(); ++i) {
          EXPECT_EQ(got.contacts[i].object_a, want[i].object_a) << what;
          EXPECT_EQ(got.contacts[i].object_b, want[i].object_b) << what;
          test::expect_identical(QueryResult{QueryKind::distance, {got.contacts[i]}, {}},
                                 QueryResult{QueryKind::distance, {want[i]}, {}}, what);
        }
      }
      also(engine, what);
    }
  }
}

/// Two tetrahedra have 16 triangle pairs: the query tests them all once the roots are within reach
/// (no traversal), so at distance 0 too it reports the lowest ids, the brute force's answer, and
/// every method and thread count reports the same.
TEST(Distance, FewTrianglePairsAreAllTestedAndTheLowestIdsWin) {
  const auto tetra = build_model(mesh_from_buffers(std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1},
                                                   std::vector<std::int64_t>{0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3}, "tetra"));
  std::mt19937_64 rng(11);
  int touching = 0, beyond_tolerance = 0;
  for (int k = 0; k < 200; ++k) {
    const Pose pa = test::random_pose(rng, 0.0);
    const Pose pb = test::random_pose(rng, 1.2);
    for (const double tolerance : {kUnbounded, 0.2}) {
      QueryRequest request = distance_request(tolerance);
      const std::string what = "pose " + std::to_string(k) + " tolerance " + std::to_string(tolerance);
      const QueryResult fast = query(*tetra, pa, *tetra, pb, request);
      request.lowest_ids = true;
      test::expect_identical(fast, query_brute_force(*tetra, pa, *tetra, pb, request), what);
      if (fast.contacts.empty()) {
        ++beyond_tolerance;
        continue;
      }
      EXPECT_EQ(fast.stats.leaf_tests, 16u) << what;
      touching += fast.contacts.front().distance == 0.0 ? 1 : 0;
    }
  }
  EXPECT_GE(touching, 40) << "poses where the tetrahedra intersect";
  EXPECT_GE(beyond_tolerance, 20) << "poses farther apart than the tolerance";

  Frame frame;
  frame.models = {tetra, tetra, tetra, tetra};
  for (int i = 0; i < 4; ++i) frame.poses.push_back(test::random_pose(rng, 0.6));
  for (std::uint32_t a = 0; a < 4; ++a) {
    for (std::uint32_t b = a + 1; b < 4; ++b) frame.pairs.push_back(ObjectPair{a, b});
  }
  frame.request = distance_request();
  const std::vector<Contact> want = queries_of(frame);
  ASSERT_GE(std::count_if(want.begin(), want.end(), [](const Contact& c) { return c.distance == 0.0; }), 1);
  const std::vector<Pose> poses_b(frame.poses.begin() + 1, frame.poses.end());
  expect_every_method(frame, want, [&](Engine& engine, const std::string& what) {
    // A batch: object 0 against the others, entry by entry the query's answer.
    const BatchResult batch = engine.query_many(*tetra, std::vector<Pose>{frame.poses[0]}, *tetra, poses_b, frame.request);
    for (std::size_t e = 0; e < poses_b.size(); ++e) {
      const QueryResult one = query(*tetra, frame.poses[0], *tetra, poses_b[e], frame.request);
      const auto got = batch.contacts_of(e);
      ASSERT_EQ(got.size(), one.contacts.size()) << what << " entry " << e;
      for (std::size_t i = 0; i < got.size(); ++i) {
        test::expect_identical(QueryResult{QueryKind::distance, {got[i]}, {}},
                               QueryResult{QueryKind::distance, {one.contacts[i]}, {}}, what + " batch");
      }
    }
  });
}

TEST(Distance, TheToleranceBoundsTheAnswer) {
  std::mt19937_64 rng(3);
  const Model& a = *shapes().sphere;
  const Model& b = *shapes().box;
  const Pose pb = separated(rng, a, b, 0.25);
  const QueryResult any = query(a, Pose{}, b, pb, distance_request());
  ASSERT_EQ(any.contacts.size(), 1u);
  const double d = any.contacts.front().distance;
  const QueryResult within = query(a, Pose{}, b, pb, distance_request(d));
  test::expect_identical(within, any, "tolerance exactly the distance");
  const QueryResult beyond = query(a, Pose{}, b, pb, distance_request(std::nextafter(d, 0.0)));
  EXPECT_TRUE(beyond.contacts.empty() && beyond.contacts.empty()) << "nothing within a tolerance below the distance";
  test::expect_identical(beyond, query_brute_force(a, Pose{}, b, pb, distance_request(std::nextafter(d, 0.0))), "oracle");
  EXPECT_LE(beyond.stats.node_tests, any.stats.node_tests) << "a tolerance never costs more";
  const QueryResult far_below = query(a, Pose{}, b, pb, distance_request(0.5 * d));
  EXPECT_TRUE(far_below.contacts.empty());
  EXPECT_LT(far_below.stats.node_tests, any.stats.node_tests) << "a tolerance well below the distance answers early";
}

TEST(Distance, OnlyDistanceTakesAnUnboundedTolerance) {
  QueryRequest r = distance_request();
  EXPECT_NO_THROW(validate_request(r));
  r.kind = QueryKind::proximity;
  EXPECT_THROW(validate_request(r), Error);
  r = distance_request(-1.0);
  EXPECT_THROW(validate_request(r), Error);
  r = distance_request(std::numeric_limits<double>::quiet_NaN());
  EXPECT_THROW(validate_request(r), Error);
  EXPECT_EQ(parse_query_kind("distance"), QueryKind::distance);
  EXPECT_EQ(to_string(QueryKind::distance), "distance");
}

TEST(Distance, EveryMethodAndThreadCountGivesTheQuerysAnswer) {
  std::mt19937_64 rng(5);
  Frame frame;
  frame.models = {shapes().torus, shapes().sphere, shapes().box, shapes().torus};
  for (int i = 0; i < 4; ++i) frame.poses.push_back(test::random_pose(rng, 1.5));
  for (std::uint32_t a = 0; a < 4; ++a) {
    for (std::uint32_t b = a + 1; b < 4; ++b) frame.pairs.push_back(ObjectPair{a, b});
  }
  // Within a tolerance, and without one (any distance: every pair answers); at distance 0 the first
  // hit, the distance traversal's own first contact (first_hit = false), and the lowest ids.
  struct Case {
    double tolerance;
    bool lowest_ids, first_hit;
  };
  for (const Case c :
       {Case{1.5, false, true}, Case{kUnbounded, false, true}, Case{kUnbounded, false, false}, Case{kUnbounded, true, true}}) {
    const double tolerance = c.tolerance;
    frame.request = distance_request(tolerance);
    frame.request.lowest_ids = c.lowest_ids;
    frame.request.first_hit = c.first_hit;
    const std::vector<Contact> want = queries_of(frame);
    ASSERT_GE(want.size(), tolerance == kUnbounded ? 6u : 3u)
        << "most pairs must be within the tolerance for this to test anything";
    ASSERT_GE(std::count_if(want.begin(), want.end(), [](const Contact& c) { return c.distance == 0.0; }), 2)
        << "pairs that intersect: pieces of the split traversal stop at their own first contact";
    expect_every_method(frame, want, [](Engine&, const std::string&) {});
  }
}

}  // namespace
}  // namespace caliber
