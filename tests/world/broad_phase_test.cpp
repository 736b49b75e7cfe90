// The broad phase over models and poses held in memory (caliber/broad_phase.h): every object pair
// that the exact query finds within reach is kept, fixed pairs and ignored pairs are not, the pairs
// are those whose boxes overlap, and bad input is an error naming the problem.

#include <algorithm>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "support/error_message.h"

#include "caliber/broad_phase.h"
#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

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
  EXPECT_EQ(message([&] { return broad_phase(two, poses, -1.0); }), "broad phase: reach must be finite and >= 0");
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
