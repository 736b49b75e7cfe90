// The broad phase over models and poses held in memory (caliber/broad_phase.h, Engine::find_pairs):
// every object pair that the exact query finds within reach is kept, fixed pairs and ignored pairs
// are not, the pairs are exactly those whose boxes overlap (against every pair of boxes, and against
// a plain sort along x on the paper's scenes), the engine's tree kept from frame to frame gives the
// same pairs, and bad input is an error naming the problem.

#include <algorithm>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "support/error_message.h"

#include "broad/world_box.h"
#include "caliber/broad_phase.h"
#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "support/random_poses.h"
#include "support/x_sort_pairs.h"

namespace caliber {
namespace {

using broad::world_box;
using broad::WorldBox;
using test::pairs_by_x_sort;

/// Every pair of boxes compared: the pairs the broad phase must give, no more, no less.
std::vector<ObjectPair> every_overlap(const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                                      double reach) {
  std::vector<WorldBox> boxes;
  for (std::size_t i = 0; i < models.size(); ++i) boxes.push_back(world_box(*models[i], poses[i], 0.5 * reach));
  std::vector<ObjectPair> pairs;
  for (std::uint32_t a = 0; a < boxes.size(); ++a) {
    for (std::uint32_t b = a + 1; b < boxes.size(); ++b) {
      if (test::boxes_overlap(boxes[a], boxes[b])) pairs.push_back({a, b});
    }
  }
  return pairs;
}

TEST(BroadPhase, PairsAreExactlyThoseWhoseBoxesOverlapFrameAfterFrame) {
  const std::vector<std::shared_ptr<const Model>> shapes = {
      build_model(make_sphere(0.3, 6, 8)), build_model(make_box(0.05, 0.5, 0.05, 1)), build_model(make_box(2.0, 0.1, 2.0, 1))};
  std::mt19937_64 rng(7);
  EngineOptions options;
  options.threads = 2;
  Engine engine(options);
  // Sizes around the tree's leaf and chunk sizes; dense and sparse; objects that share a pose.
  for (const std::uint32_t n : {0u, 1u, 2u, 3u, 4u, 5u, 9u, 64u, 300u, 1500u, 3000u}) {
    for (const double spread : {1.0, 6.0}) {
      std::vector<std::shared_ptr<const Model>> models;
      std::vector<Pose> poses;
      for (std::uint32_t i = 0; i < n; ++i) {
        models.push_back(shapes[i % 7 == 3 ? 2 : i % 2]);
        poses.push_back(i % 11 == 5 ? poses[i / 2] : test::random_pose(rng, spread * std::cbrt(double(n) + 1.0)));
      }
      Frame frame;
      frame.models = models;
      for (int step = 0; step < 4; ++step) {
        // Small drifts keep the engine's order (refitted); the jump at step 3 makes it re-sort.
        for (Pose& p : poses) p.translation += Eigen::Vector3d(0.05, -0.03, 0.02) * (step == 3 ? 40.0 : 1.0);
        if (step == 3) std::shuffle(poses.begin(), poses.end(), rng);
        const double reach = step == 2 ? 0.2 : 0.0;
        const std::vector<ObjectPair> want = every_overlap(models, poses, reach);
        const std::string what =
            std::to_string(n) + " objects, spread " + std::to_string(spread) + ", step " + std::to_string(step);
        ASSERT_EQ(broad_phase(models, poses, reach), want) << what;
        frame.poses = poses;
        frame.request.kind = reach > 0.0 ? QueryKind::proximity : QueryKind::interference;
        frame.request.tolerance = reach;
        engine.find_pairs(frame);
        ASSERT_EQ(frame.pairs, want) << what << " (the engine's broad phase)";
        // Fixed objects and ignored pairs: the same pairs less those.
        std::vector<bool> fixed(n);
        for (std::uint32_t i = 0; i < n; ++i) fixed[i] = i % 5 == step;
        const std::vector<ObjectPair> ignored(want.begin(), want.begin() + std::min<std::ptrdiff_t>(3, std::ssize(want)));
        std::vector<ObjectPair> kept;
        for (const ObjectPair& p : want) {
          if (!(fixed[p.a] && fixed[p.b]) && std::find(ignored.begin(), ignored.end(), p) == ignored.end()) kept.push_back(p);
        }
        engine.find_pairs(frame, fixed, ignored);
        ASSERT_EQ(frame.pairs, kept) << what << " (fixed and ignored)";
      }
    }
  }
}

TEST(BroadPhase, SamePairsAsAnXSortOnThePaperScenes) {
  if (!std::filesystem::exists(std::filesystem::path(CALIBER_MESH_DATA) / "dragknob.off")) {
    GTEST_SKIP() << "run scripts/fetch_meshes.sh first";
  }
  for (const char* name : {"two_small.json", "two_large.json", "funnel.json", "front_car.json"}) {
    const World world(load_scene(std::filesystem::path(CALIBER_SCENES) / name));
    Engine engine;
    for (const int step : {0, 40, 80, 149}) {
      std::vector<WorldBox> boxes;
      const std::vector<Pose> poses = world.poses_at(step);
      for (std::size_t i = 0; i < poses.size(); ++i) {
        const auto [lo, hi] = world.bounds(i, poses[i], 0.5 * reach(world.request()));
        boxes.push_back({lo, hi});
      }
      std::vector<ObjectPair> want;
      for (const ObjectPair& p : pairs_by_x_sort(boxes)) {
        if (!(world.scene().objects[p.a].motion.type == Motion::Type::fixed &&
              world.scene().objects[p.b].motion.type == Motion::Type::fixed)) {
          want.push_back(p);
        }
      }
      EXPECT_EQ(world.broad_phase(poses), want) << name << " step " << step;
      EXPECT_EQ(world.frame(step, engine).pairs, want) << name << " step " << step << " (the engine's broad phase)";
    }
  }
}

TEST(BroadPhase, KeepsEveryPairWithinReachAndSkipsFixedAndIgnoredOnes) {
  const std::vector<std::shared_ptr<const Model>> shapes = {
      build_model(make_sphere(0.4, 8, 12)), build_model(make_torus(0.5, 0.15, 12, 8)), build_model(make_box(0.3, 0.2, 0.5, 2))};
  std::mt19937_64 rng(20261126);
  for (const double reach : {0.0, 0.05, 0.3}) {
    for (int trial = 0; trial < 4; ++trial) {
      const std::uint32_t n = 16;
      std::vector<std::shared_ptr<const Model>> models;
      std::vector<Pose> poses;
      std::vector<bool> fixed;
      for (std::uint32_t i = 0; i < n; ++i) {
        models.push_back(shapes[i % 3]);
        poses.push_back(test::random_pose(rng, 2.0));
        fixed.push_back(i % 5 == 0);
      }
      const std::vector<ObjectPair> ignored = {{3, 7}, {1, 2}};
      const std::vector<ObjectPair> got = broad_phase(models, poses, reach, fixed, ignored);
      EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
      EXPECT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end());
      QueryRequest request;
      request.kind = reach > 0.0 ? QueryKind::proximity : QueryKind::interference;
      request.tolerance = reach;
      const std::vector<ObjectPair> all = broad_phase(models, poses, reach);
      for (std::uint32_t a = 0; a < n; ++a) {
        for (std::uint32_t b = a + 1; b < n; ++b) {
          const ObjectPair p{a, b};
          const bool kept = std::binary_search(got.begin(), got.end(), p);
          const bool skipped = (fixed[a] && fixed[b]) || p == ignored[0] || p == ignored[1];
          if (skipped) EXPECT_FALSE(kept) << a << ", " << b;
          if (!skipped) EXPECT_EQ(kept, std::binary_search(all.begin(), all.end(), p)) << "only fixed and ignored pairs differ";
          if (!query_brute_force(*models[a], poses[a], *models[b], poses[b], request).contacts.empty()) {
            EXPECT_TRUE(std::binary_search(all.begin(), all.end(), p)) << "a pair within reach was dropped: " << a << ", " << b;
          }
        }
      }
    }
  }
}

TEST(BroadPhase, BadInputIsAnErrorNamingTheProblem) {
  const auto sphere = build_model(make_sphere(0.4, 8, 12));
  const auto message = [](auto&& call) { return test::error_message(call); };
  const std::vector<std::shared_ptr<const Model>> two = {sphere, sphere};
  const std::vector<Pose> poses(2);
  EXPECT_EQ(message([&] { return broad_phase(two, std::vector<Pose>(1), 0.0); }),
            "broad phase: 2 models but 1 poses (one per object)");
  EXPECT_EQ(message([&] { return broad_phase(two, poses, 0.0, {true}); }),
            "broad phase: 2 objects but 1 fixed flags (none, or one per object)");
  EXPECT_EQ(message([&] { return broad_phase(two, poses, -1.0); }),
            "reach: must be finite, >= 0 and at most 1e15 (caliber's limit on coordinates), not -1");
  EXPECT_EQ(message([&] { return broad_phase(two, poses, 1e300); }),
            "reach: must be finite, >= 0 and at most 1e15 (caliber's limit on coordinates), not 1e+300");
  EXPECT_EQ(message([&] { return broad_phase(two, poses, std::numeric_limits<double>::infinity()); }),
            "reach: must be finite, >= 0 and at most 1e15 (caliber's limit on coordinates), not inf");
  EXPECT_EQ(broad_phase(two, poses, 1e15).size(), 1u);  // the largest reach, as the largest tolerance
  EXPECT_EQ(message([&] {
              return broad_phase(two, poses, 0.0, {}, {{1, 1}});
            }),
            "broad phase: ignored pair (1, 1) must name two objects a < b < 2");
  EXPECT_EQ(message([&] { return broad_phase({sphere, nullptr}, poses, 0.0); }), "broad phase: object 1 has no model");
  EXPECT_EQ(broad_phase(two, poses, 0.0), (std::vector<ObjectPair>{{0, 1}})) << "two spheres in one place";
  EXPECT_TRUE(broad_phase({}, {}, 0.0).empty());
}

}  // namespace
}  // namespace caliber
