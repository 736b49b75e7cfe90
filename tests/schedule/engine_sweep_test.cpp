// Engine::sweep: continuous collision detection for many objects, against caliber::sweep on every
// pair (the swept boxes must not drop a pair that touches), at several thread counts.

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/sweep.h"

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

TEST(EngineSweep, EveryPairThatTouchesAsCaliberSweepFindsIt) {
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
  for (const int threads : {1, 2, 3}) {
    EngineOptions options;
    options.threads = threads;
    Engine engine(options);
    const std::vector<PairSweep> got = engine.sweep(o.models, o.from, o.to, request);
    ASSERT_EQ(got.size(), brute.size()) << threads << " threads";
    for (std::size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k].pair, brute[k].pair) << threads << " threads, pair " << k;
      EXPECT_EQ(got[k].result.status, brute[k].result.status);
      EXPECT_EQ(got[k].result.time, brute[k].result.time) << "bit for bit";
      EXPECT_EQ(got[k].result.closest.tri_a, brute[k].result.closest.tri_a);
      EXPECT_EQ(got[k].result.closest.tri_b, brute[k].result.closest.tri_b);
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

}  // namespace
}  // namespace caliber
