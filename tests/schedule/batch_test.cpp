// Engine::query_many: every entry equals caliber::query at its poses, bit for bit, for every kind,
// method and thread count, with max_pairs, across the batch's internal chunks, with one side fixed
// or both moving; poses from raw arrays; bad batches refused naming the pose.

#include <limits>
#include <random>
#include <string>
#include <utility>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/batch.h"
#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "caliber/sweep.h"
#include "schedule/engine_impl.h"
#include "support/random_poses.h"
#include "support/torus_sphere.h"

namespace caliber {
namespace {

const test::TorusSphere& shapes() { return test::torus_sphere(); }

/// Poses near the origin: about half of them put the sphere through the torus.
std::vector<Pose> poses_near(std::size_t n, std::uint64_t seed, double spread) {
  std::mt19937_64 rng(seed);
  std::vector<Pose> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(test::random_pose(rng, spread));
  return out;
}

/// Entry i of `batch` is caliber::query at its poses, to the last bit.
void expect_queries(const BatchResult& batch, std::span<const Pose> pa, std::span<const Pose> pb, const QueryRequest& request,
                    const std::string& what) {
  const std::size_t n = std::max(pa.size(), pb.size());
  ASSERT_EQ(batch.size(), n) << what;
  ASSERT_EQ(batch.limit_reached.size(), n) << what;
  EXPECT_EQ(batch.kind, request.kind) << what;
  QueryStats total;
  for (std::size_t i = 0; i < n; ++i) {
    const QueryResult want =
        query(*shapes().torus, pa[pa.size() == 1 ? 0 : i], *shapes().sphere, pb[pb.size() == 1 ? 0 : i], request);
    QueryResult got;
    got.kind = batch.kind;
    const std::span<const Contact> c = batch.contacts_of(i);
    got.contacts.assign(c.begin(), c.end());
    EXPECT_EQ(batch.hit(i), !want.contacts.empty()) << what << " entry " << i;
    EXPECT_EQ(batch.limit_reached[i] != 0, want.limit_reached) << what << " entry " << i;
    for (const Contact& k : got.contacts) ASSERT_TRUE(k.object_a == 0 && k.object_b == 1) << what;
    test::expect_identical(got, want, what + " entry " + std::to_string(i));
    total.node_tests += want.stats.node_tests;
    total.leaf_tests += want.stats.leaf_tests;
  }
  // Depth-first traversals: the same work as the single queries, however split. (The pieces of a
  // split distance traversal each look for their own nearest pair: more work, the same answer.)
  if (request.kind != QueryKind::distance) {
    EXPECT_EQ(batch.stats.node_tests, total.node_tests) << what;
    EXPECT_EQ(batch.stats.leaf_tests, total.leaf_tests) << what;
  }
}

const Method kMethods[] = {Method::sequential,  Method::exploitation, Method::stealing,
                           Method::aposteriori, Method::apriori,      Method::hybrid};

TEST(Batch, EveryKindMethodAndThreadCountEqualsSingleQueries) {
  // 40 entries, then 2: few enough that stealing and the calibrated methods split them.
  for (const std::size_t entries : {std::size_t{40}, std::size_t{2}}) {
    const std::vector<Pose> pb = poses_near(entries, 11, 0.3);
    const std::vector<Pose> pa{Pose::from_values(0.05, -0.02, 0.01, 1, 0.1, 0, 0.05)};
    // Distance twice: stopping at the first contact, and with ties at 0 to the lowest ids.
    for (const auto& [kind, lowest_ids] :
         {std::pair{QueryKind::interference, false}, std::pair{QueryKind::proximity, false}, std::pair{QueryKind::contact, false},
          std::pair{QueryKind::distance, false}, std::pair{QueryKind::distance, true}}) {
      QueryRequest request;
      request.kind = kind;
      request.tolerance = kind == QueryKind::distance ? kUnbounded : 0.03;
      request.lowest_ids = lowest_ids;
      for (const Method method : kMethods) {
        for (const int threads : {1, 2, 3}) {
          EngineOptions options;
          options.method = method;
          options.threads = threads;
          Engine engine(options);
          const std::string what = std::to_string(entries) + " entries " + std::string(to_string(kind)) +
                                   (request.lowest_ids ? " (lowest ids) " : " ") + std::string(to_string(method)) + " " +
                                   std::to_string(threads) + " threads";
          expect_queries(engine.query_many(*shapes().torus, pa, *shapes().sphere, pb, request), pa, pb, request, what);
        }
      }
    }
  }
}

TEST(Batch, MaxPairsEntriesAreTheQueriesFirstPairs) {
  const std::vector<Pose> pa = poses_near(30, 5, 0.6);
  const std::vector<Pose> pb = poses_near(30, 6, 0.6);
  for (const std::size_t limit : {std::size_t{1}, std::size_t{7}}) {
    for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity, QueryKind::contact}) {
      QueryRequest request;
      request.kind = kind;
      request.tolerance = 0.05;
      request.max_pairs = limit;
      for (const Method method : kMethods) {
        EngineOptions options;
        options.method = method;
        options.threads = 2;
        Engine engine(options);
        const std::string what =
            std::string(to_string(kind)) + " max_pairs " + std::to_string(limit) + " " + std::string(to_string(method));
        const BatchResult batch = engine.query_many(*shapes().torus, pa, *shapes().sphere, pb, request);
        expect_queries(batch, pa, pb, request, what);
        std::size_t cut = 0;
        for (const std::uint8_t r : batch.limit_reached) cut += r;
        EXPECT_GT(cut, 0u) << what << ": some entries must find as many pairs as the limit";
      }
    }
  }
}

TEST(Batch, OneEngineAnswersEachCallAfresh) {
  // Entries traversed whole write into results the engine keeps from call to call: each call's
  // entries must be its own, whatever the call before left there (a limit reached, many contacts,
  // another kind, more entries, entries the method split: 6 entries on 2 threads).
  EngineOptions options;
  options.threads = 2;
  Engine engine(options);
  std::uint64_t seed = 8;
  for (const auto& [kind, limit, entries] : {std::tuple{QueryKind::proximity, std::size_t{7}, std::size_t{40}},
                                             std::tuple{QueryKind::proximity, std::size_t{0}, std::size_t{40}},
                                             std::tuple{QueryKind::interference, std::size_t{1}, std::size_t{24}},
                                             std::tuple{QueryKind::distance, std::size_t{0}, std::size_t{6}},
                                             std::tuple{QueryKind::contact, std::size_t{0}, std::size_t{40}},
                                             std::tuple{QueryKind::interference, std::size_t{0}, std::size_t{17}},
                                             std::tuple{QueryKind::interference, std::size_t{0}, std::size_t{6}}}) {
    const std::vector<Pose> pa = poses_near(entries, ++seed, 0.6);
    const std::vector<Pose> pb = poses_near(entries, ++seed, 0.6);
    QueryRequest request;
    request.kind = kind;
    request.tolerance = kind == QueryKind::distance ? kUnbounded : 0.05;
    request.max_pairs = limit;
    const std::string what =
        std::string(to_string(kind)) + " max_pairs " + std::to_string(limit) + ", " + std::to_string(entries) + " entries";
    expect_queries(engine.query_many(*shapes().torus, pa, *shapes().sphere, pb, request), pa, pb, request, what);
  }
}

TEST(Batch, ManyEntriesAcrossChunksAndEitherSideFixed) {
  // More entries than one run of the method takes (8192), cheap ones: the sphere far off most
  // of the time.
  const std::vector<Pose> many = poses_near(8192 + 300, 21, 3.0);
  const std::vector<Pose> one{Pose{}};
  QueryRequest request;
  request.kind = QueryKind::distance;
  request.tolerance = 0.5;
  EngineOptions options;
  options.threads = 2;
  Engine engine(options);
  expect_queries(engine.query_many(*shapes().torus, one, *shapes().sphere, many, request), one, many, request, "B moves");
  const std::vector<Pose> few(many.begin(), many.begin() + 50);
  expect_queries(engine.query_many(*shapes().torus, few, *shapes().sphere, one, request), few, one, request, "A moves");
  const BatchResult empty = engine.query_many(*shapes().torus, one, *shapes().sphere, {}, request);
  EXPECT_EQ(empty.size(), 0u);
  EXPECT_TRUE(empty.contacts.empty());
}

TEST(Batch, ContactsGrowTowardWhatTheEntriesAreOnCourseToGive) {
  constexpr std::size_t kMost = std::size_t{1} << 40;
  // A fifth of the entries done: five times as many to come, a quarter more (within 8 times need).
  EXPECT_EQ(schedule::batch_capacity(1000, 800, 2000, kMost), 3125u);
  EXPECT_EQ(schedule::batch_capacity(1000, 1000, 10000, kMost), 8000u);
  // Near the end, or at it: at least twice what is needed (growth stays geometric).
  EXPECT_EQ(schedule::batch_capacity(1000, 9900, 10000, kMost), 2000u);
  EXPECT_EQ(schedule::batch_capacity(1000, 10000, 10000, kMost), 2000u);
  // Within what a vector may hold, and never below what is needed; near that, no double in the way.
  EXPECT_EQ(schedule::batch_capacity(1000, 1, 1000000, 3000), 3000u);
  EXPECT_EQ(schedule::batch_capacity(1000, 1, 1000000, 500), 1000u);
  const std::size_t most = std::vector<Contact>().max_size();
  EXPECT_EQ(schedule::batch_capacity(most / 2, 1, 1000, most), most);
  const std::size_t below = schedule::batch_capacity(most / 8 - 1, 1, 1000, most);  // 8 need, within rounding
  EXPECT_LE(below, most);
  EXPECT_GE(below, most - 64);
  const std::size_t huge = std::numeric_limits<std::size_t>::max();
  EXPECT_EQ(schedule::batch_capacity(huge / 2, 1, 1000, huge), huge);
  // What each entry gave since the growth before: 1,000 contacts over the last 1,000 entries, 5,000
  // entries to come.
  EXPECT_EQ(schedule::batch_capacity(2000, 5000, 10000, kMost, {1000, 4000}), 8750u);
  EXPECT_EQ(schedule::batch_capacity(2000, 9000, 10000, kMost, {1000, 8000}), 4000u);  // 3,000 * 1.25
  // No entry done yet counts as one.
  EXPECT_EQ(schedule::batch_capacity(10, 0, 3, kMost), 50u);
}

TEST(Batch, ContactsComeLateOrEarlyAndTheBatchGrowsToHoldThem) {
  // A batch's contacts grow toward what its entries are on course to give (make_room): here that
  // guess is wrong both ways, the contacts coming after many entries without any, or before them;
  // across a chunk on two threads, entry by entry on one.
  const Pose far = Pose::from_values(10.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0);
  const std::vector<Pose> touching = poses_near(300, 23, 0.4);
  std::vector<Pose> late(8192, far);
  late.insert(late.end(), touching.begin(), touching.end());
  std::vector<Pose> early = touching;
  early.insert(early.end(), 8192, far);
  early.insert(early.end(), touching.begin(), touching.begin() + 20);
  const std::vector<Pose> one{Pose{}};
  QueryRequest request;  // interference: every pair, tens of contacts an entry that touches
  for (const int threads : {1, 2}) {
    EngineOptions options;
    options.threads = threads;
    Engine engine(options);
    for (const auto& [poses, name] : {std::pair{&late, "late"}, std::pair{&early, "early"}}) {
      const BatchResult batch = engine.query_many(*shapes().torus, one, *shapes().sphere, *poses, request);
      ASSERT_GT(batch.contacts.size(), 1000u) << name;
      // Room for what the entries were on course to give, never more than 8 times what they gave.
      EXPECT_LE(batch.contacts.capacity(), 8 * batch.contacts.size()) << name;
      expect_queries(batch, one, *poses, request, std::string(name) + ", " + std::to_string(threads) + " threads");
    }
  }
}

TEST(Batch, TheHookBetweenChunksIsCalledAndMayStopTheCall) {
  const std::vector<Pose> many = poses_near(3 * 8192 + 5, 22, 3.0);
  const std::vector<Pose> one{Pose{}};
  QueryRequest request;
  request.kind = QueryKind::distance;
  int calls = 0;
  EngineOptions options;
  options.threads = 2;
  options.between_chunks = [&] { ++calls; };
  Engine counting(options);
  expect_queries(counting.query_many(*shapes().torus, one, *shapes().sphere, many, request), one, many, request, "hooked");
  EXPECT_EQ(calls, 3) << "between the four chunks";
  struct Stop {};
  options.between_chunks = [&] { throw Stop{}; };
  Engine stopping(options);
  EXPECT_THROW((void)stopping.query_many(*shapes().torus, one, *shapes().sphere, many, request), Stop);
  // The engine takes its next call as usual.
  const std::vector<Pose> few(many.begin(), many.begin() + 40);
  expect_queries(stopping.query_many(*shapes().torus, one, *shapes().sphere, few, request), one, few, request, "after");
  const std::vector<SweptPose> motions(
      3 * 8192, SweptPose{Pose::from_values(3, 0, 0, 1, 0, 0, 0), Pose::from_values(-3, 0, 0, 1, 0, 0, 0)});
  const SweptPose still{};
  EXPECT_THROW((void)stopping.sweep_many(*shapes().torus, {&still, 1}, *shapes().sphere, motions), Stop);
}

TEST(Batch, BadBatchesAreErrorsNamingThePose) {
  Engine engine;
  const std::vector<Pose> three = poses_near(3, 1, 1.0), two = poses_near(2, 2, 1.0);
  const QueryRequest request;
  try {
    (void)engine.query_many(*shapes().torus, three, *shapes().sphere, two, request);
    FAIL() << "3 poses of A against 2 of B must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("3 poses of A but 2 of B"), std::string::npos) << e.what();
  }
  std::vector<Pose> bad = three;
  bad[2].translation.y() = std::numeric_limits<double>::quiet_NaN();
  try {
    (void)engine.query_many(*shapes().torus, std::span<const Pose>(two).first(1), *shapes().sphere, bad, request);
    FAIL() << "a NaN pose must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.source(), "poses of B[2]");
  }
  QueryRequest negative;
  negative.kind = QueryKind::proximity;
  negative.tolerance = -1.0;
  EXPECT_THROW((void)engine.query_many(*shapes().torus, three, *shapes().sphere, three, negative), Error);
}

TEST(Batch, PosesFromMatricesAndVectors) {
  const std::vector<Pose> poses = poses_near(5, 9, 2.0);
  std::vector<double> matrices, wxyz, xyzw;
  for (const Pose& p : poses) {
    const Eigen::Matrix4d m = p.matrix();
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) matrices.push_back(m(r, c));
    }
    const Eigen::Quaterniond& q = p.rotation;
    for (const double v : {p.translation.x(), p.translation.y(), p.translation.z(), q.w(), q.x(), q.y(), q.z()})
      wxyz.push_back(v);
    for (const double v : {p.translation.x(), p.translation.y(), p.translation.z(), q.x(), q.y(), q.z(), q.w()})
      xyzw.push_back(v);
  }
  const std::vector<Pose> from_m = poses_from_matrices(matrices);
  const std::vector<Pose> from_w = poses_from_vectors(wxyz, QuaternionOrder::wxyz);
  const std::vector<Pose> from_x = poses_from_vectors(xyzw, QuaternionOrder::xyzw);
  ASSERT_EQ(from_m.size(), 5u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Pose m = Pose::from_matrix(poses[i].matrix());
    EXPECT_EQ(from_m[i].rotation.coeffs(), m.rotation.coeffs());
    EXPECT_EQ(from_m[i].translation, m.translation);
    const Pose& p = poses[i];
    const Pose w = Pose::from_values(p.translation.x(), p.translation.y(), p.translation.z(), p.rotation.w(), p.rotation.x(),
                                     p.rotation.y(), p.rotation.z());
    EXPECT_EQ(from_w[i].rotation.coeffs(), w.rotation.coeffs());
    EXPECT_EQ(from_x[i].rotation.coeffs(), w.rotation.coeffs());
    EXPECT_EQ(from_x[i].translation, w.translation);
  }
  matrices[16 * 3 + 1] = 0.5;  // the fourth matrix is no longer a rotation
  try {
    (void)poses_from_matrices(matrices, 1e-9, "link poses");
    FAIL() << "a matrix that is not a rotation must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.source(), "link poses[3]");
  }
  xyzw[7 * 1 + 3] = xyzw[7 * 1 + 4] = xyzw[7 * 1 + 5] = xyzw[7 * 1 + 6] = 0.0;
  try {
    (void)poses_from_vectors(xyzw, QuaternionOrder::xyzw);
    FAIL() << "a zero quaternion must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.source(), "poses[1]");
  }
  EXPECT_THROW((void)poses_from_vectors(std::vector<double>(13, 0.0)), Error);
  EXPECT_THROW((void)poses_from_matrices(std::vector<double>(15, 0.0)), Error);
}

}  // namespace
}  // namespace caliber
