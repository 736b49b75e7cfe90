// Engine::sweep: continuous collision detection for many objects, against caliber::sweep on every
// pair (the swept boxes must not drop a pair that touches), at several thread counts; and
// Engine::sweep_many, one pair along many motions, against caliber::sweep on every entry, heavy
// sweeps split across threads among them.

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/sweep.h"
#include "schedule/engine_impl.h"
#include "support/torus_sphere.h"

namespace caliber {
namespace {

struct Objects {
  std::vector<std::shared_ptr<const Model>> models;
  std::vector<Pose> from, to;
};

/// Parts on a line, each flying to a random place among the others, turning: many pairs meet
/// between the two poses without touching at either (thin plates among them).
Objects flying_parts(std::size_t n, unsigned seed) {
  const auto sphere = build_model(make_sphere(0.3, 8, 12));
  const auto plate = build_model(make_plate(0.4, 0.01, 2));
  const auto box = build_model(make_box(0.1, 0.1, 0.3, 1));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto turn = [&] {
    Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
    return q.norm() < 1e-3 ? Eigen::Quaterniond::Identity() : q.normalized();
  };
  Objects o;
  for (std::size_t i = 0; i < n; ++i) {
    o.models.push_back(i % 3 == 0 ? sphere : i % 3 == 1 ? plate : box);
    Pose a, b;
    a.translation = Eigen::Vector3d(1.0 * static_cast<double>(i), 0.0, 0.0);
    a.rotation = turn();
    b.translation = Eigen::Vector3d(static_cast<double>(n) * 0.5 * (1.0 + u(rng)), 0.5 * u(rng), 0.5 * u(rng));
    b.rotation = turn();
    o.from.push_back(a);
    o.to.push_back(b);
  }
  return o;
}

TEST(EngineSweep, EveryPairThatTouchesAsCaliberSweepFindsItWhateverTheMethodAndThreads) {
  const Objects o = flying_parts(24, 7);
  SweepRequest request;
  request.tolerance = 1e-5;
  std::vector<PairSweep> brute;
  for (std::uint32_t a = 0; a < o.models.size(); ++a) {
    for (std::uint32_t b = a + 1; b < o.models.size(); ++b) {
      const SweepResult r = sweep(*o.models[a], {o.from[a], o.to[a]}, *o.models[b], {o.from[b], o.to[b]}, request);
      if (r.status != SweepStatus::free) brute.push_back(PairSweep{ObjectPair{a, b}, r});
    }
  }
  ASSERT_GT(brute.size(), 10u) << "the scene should make pairs meet";
  for (const Method method : {Method::stealing, Method::sequential, Method::hybrid, Method::apriori}) {
    for (const int threads : {1, 2, 3}) {
      EngineOptions options;
      options.method = method;
      options.threads = threads;
      Engine engine(options);
      const std::vector<PairSweep> got = engine.sweep(o.models, o.from, o.to, request);
      const std::string where = std::string(to_string(method)) + ", " + std::to_string(threads) + " threads";
      ASSERT_EQ(got.size(), brute.size()) << where;
      for (std::size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].pair, brute[k].pair) << where << ", pair " << k;
        EXPECT_EQ(got[k].result.status, brute[k].result.status) << where;
        EXPECT_EQ(got[k].result.time, brute[k].result.time) << where << ": bit for bit";
        EXPECT_EQ(got[k].result.closest.tri_a, brute[k].result.closest.tri_a) << where;
        EXPECT_EQ(got[k].result.closest.tri_b, brute[k].result.closest.tri_b) << where;
      }
    }
  }
}

TEST(EngineSweep, FixedAndIgnoredPairsAreSkipped) {
  const Objects o = flying_parts(12, 3);
  Engine engine;
  const std::vector<PairSweep> all = engine.sweep(o.models, o.from, o.to);
  ASSERT_FALSE(all.empty());
  const ObjectPair first = all.front().pair;
  const std::vector<PairSweep> without = engine.sweep(o.models, o.from, o.to, {}, {}, {first});
  EXPECT_EQ(without.size(), all.size() - 1);
  for (const PairSweep& p : without) EXPECT_NE(p.pair, first);
  std::vector<bool> fixed(o.models.size(), false);
  fixed[first.a] = fixed[first.b] = true;
  for (const PairSweep& p : engine.sweep(o.models, o.from, o.to, {}, fixed)) EXPECT_NE(p.pair, first);
}

TEST(EngineSweep, BadInputIsAnErrorNamingTheObject) {
  const Objects o = flying_parts(4, 1);
  Engine engine;
  std::vector<Pose> short_to(o.to.begin(), o.to.end() - 1);
  EXPECT_THROW(static_cast<void>(engine.sweep(o.models, o.from, short_to)), Error);
  std::vector<Pose> bad = o.to;
  bad[2].translation.x() = std::nan("");
  try {
    static_cast<void>(engine.sweep(o.models, o.from, bad));
    FAIL() << "a NaN pose was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("end pose of object 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(static_cast<void>(engine.sweep(o.models, o.from, o.to, {}, {}, {ObjectPair{2, 1}})), Error);
  SweepRequest negative;
  negative.tolerance = -1.0;
  EXPECT_THROW(static_cast<void>(engine.sweep(o.models, o.from, o.to, negative)), Error);
}

/// Random motions of B through or past A: from one side, turning, to the other.
std::vector<SweptPose> passes(std::size_t n, double reach, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<SweptPose> out;
  for (std::size_t i = 0; i < n; ++i) {
    SweptPose m;
    const Eigen::Vector3d side = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    m.start.translation = reach * side + 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    m.end.translation = -reach * side + 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    m.start.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(u(rng), side));
    m.end.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
    out.push_back(m);
  }
  return out;
}

void expect_same_sweep(const SweepResult& got, const SweepResult& want, const std::string& where) {
  EXPECT_EQ(got.status, want.status) << where;
  EXPECT_EQ(got.time, want.time) << where << ": bit for bit";
  EXPECT_EQ(got.queries, want.queries) << where;
  EXPECT_EQ(got.closest.tri_a, want.closest.tri_a) << where;
  EXPECT_EQ(got.closest.tri_b, want.closest.tri_b) << where;
  EXPECT_EQ(got.closest.distance, want.closest.distance) << where;
  EXPECT_EQ(got.closest.point_a, want.closest.point_a) << where;
  EXPECT_EQ(got.closest.point_b, want.closest.point_b) << where;
}

TEST(EngineSweepMany, EveryEntryIsCaliberSweepWhateverTheMethodAndThreads) {
  const test::TorusSphere& m = test::torus_sphere();
  const SweptPose still{Pose{}, Pose{}};
  for (const std::size_t n : {std::size_t{3}, std::size_t{40}}) {
    const std::vector<SweptPose> motions = passes(n, 3.0, 11);
    std::vector<SweepResult> want;
    for (const SweptPose& motion : motions) want.push_back(sweep(*m.torus, still, *m.sphere, motion));
    for (const Method method :
         {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
      for (const int threads : {1, 2, 3}) {
        EngineOptions options;
        options.method = method;
        options.threads = threads;
        Engine engine(options);
        const std::vector<SweepResult> got = engine.sweep_many(*m.torus, {&still, 1}, *m.sphere, motions);
        ASSERT_EQ(got.size(), n);
        for (std::size_t i = 0; i < n; ++i) {
          expect_same_sweep(
              got[i], want[i],
              std::string(to_string(method)) + ", " + std::to_string(threads) + " threads, entry " + std::to_string(i));
        }
      }
    }
  }
}

TEST(EngineSweepMany, AHeavySweepIsSplitAndStillCaliberSweeps) {
  // Two plates of 2 x 32 x 32 triangles that come together face to face while turning: every
  // query takes tens of thousands of node tests, so with few sweeps on 2 threads their
  // queries go through the method, cut into pieces.
  const auto plate = build_model(make_plate(1.0, 0.01, 32));
  const SweptPose still{Pose{}, Pose{}};
  std::vector<SweptPose> motions;
  for (int i = 0; i < 3; ++i) {
    SweptPose s;
    s.start.translation = Eigen::Vector3d(0.01 * i, 0.0, 0.5);
    s.end.translation = Eigen::Vector3d(0.0, 0.02 * i, -0.1);
    s.end.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitZ()));
    motions.push_back(s);
  }
  std::vector<SweepResult> want;
  for (const SweptPose& motion : motions) want.push_back(sweep(*plate, still, *plate, motion));
  for (const Method method : {Method::stealing, Method::apriori, Method::hybrid}) {
    EngineOptions options;
    options.method = method;
    options.threads = 2;
    Engine engine(options);
    const std::uint64_t split_before = schedule::g_split_sweep_queries.load();
    const std::vector<SweepResult> got = engine.sweep_many(*plate, {&still, 1}, *plate, motions);
    EXPECT_GT(schedule::g_split_sweep_queries.load(), split_before) << to_string(method) << ": no query was split";
    for (std::size_t i = 0; i < motions.size(); ++i) {
      ASSERT_EQ(want[i].status, SweepStatus::contact);
      expect_same_sweep(got[i], want[i], std::string(to_string(method)) + ", entry " + std::to_string(i));
    }
  }
}

TEST(EngineSweepMany, BadInputIsAnErrorNamingTheMotion) {
  const test::TorusSphere& m = test::torus_sphere();
  Engine engine;
  std::vector<SweptPose> three = passes(3, 3.0, 1), two = passes(2, 3.0, 2);
  EXPECT_THROW(static_cast<void>(engine.sweep_many(*m.torus, three, *m.sphere, two)), Error);
  EXPECT_EQ(engine.sweep_many(*m.torus, two, *m.sphere, {&three[0], 1}).size(), 2u) << "one motion kept for every entry";
  three[1].end.rotation = Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0);
  try {
    static_cast<void>(engine.sweep_many(*m.torus, {&two[0], 1}, *m.sphere, three));
    FAIL() << "a zero quaternion was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("motions of B[1].end"), std::string::npos) << e.what();
  }
  SweepRequest none;
  none.max_queries = 0;
  EXPECT_THROW(static_cast<void>(engine.sweep_many(*m.torus, two, *m.sphere, two, none)), Error);
  EXPECT_TRUE(engine.sweep_many(*m.torus, {}, *m.sphere, {}).empty());
}

}  // namespace
}  // namespace caliber
