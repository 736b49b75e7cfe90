// PairContext::gather_corners (a leaf batch's corners read straight into its lanes, B's moved into
// A's frame there) against A's vertices and b_vertex (what the unbuffered leaf test reads): the
// same bits, on random poses (rotations and translations of every size, far from the origin too)
// and batches of every size.

#include <cstdint>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/pair_context.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

/// Checks `gather` (null: PairContext::gather_corners, the form the CPU gets) on 64 random poses.
void expect_same_bits_as_corners(detail::GatherCorners gather) {
  const auto a = build_model(make_torus(1.0, 0.35, 24, 16));
  const auto b = build_model(make_box(0.6, 0.4, 0.3, 6));
  std::mt19937_64 rng(20261202);
  std::uniform_int_distribution<std::uint32_t> pick_a(0, static_cast<std::uint32_t>(a->triangle_count() - 1));
  std::uniform_int_distribution<std::uint32_t> pick_b(0, static_cast<std::uint32_t>(b->triangle_count() - 1));
  long compared = 0;
  for (int p = 0; p < 64; ++p) {
    // Translations from a fraction of the meshes' size to 1e6 of it: b_vertex's products and sums
    // round differently at each, so a different order of operations would show.
    const double far = p % 4 == 0 ? 1e6 : (p % 4 == 1 ? 1e3 : 1.0);
    Pose pose_b = test::random_pose(rng, far);
    const PairContext ctx(*a, test::random_pose(rng, 0.5), *b, pose_b, QueryRequest{});
    BufferedPairs waiting;
    waiting.batch.size = 1 + p % geometry::TriangleBatch::kLanes;
    for (int l = 0; l < waiting.batch.size; ++l) {
      waiting.ta[l] = pick_a(rng);
      waiting.tb[l] = pick_b(rng);
    }
    if (gather == nullptr) {
      ctx.gather_corners(waiting);
    } else {
      gather(ctx.a(), ctx.b(), ctx.b_move(), waiting);
    }
    // Every lane, those past the pairs too (they repeat lane 0's).
    for (int l = 0; l < geometry::TriangleBatch::kLanes; ++l) {
      const int from = l < waiting.batch.size ? l : 0;
      Eigen::Vector3d ga[3], gb[3];
      waiting.batch.get(l, ga, gb);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d ca = ctx.a().mesh.vertices[ctx.a().mesh.triangles[waiting.ta[from]][k]];
        const Eigen::Vector3d cb = ctx.b_vertex(waiting.tb[from], k);
        for (int c = 0; c < 3; ++c) {
          ASSERT_TRUE(same_bits(ca[c], ga[k][c])) << "pose " << p << ", lane " << l << ": A's corner " << k;
          ASSERT_TRUE(same_bits(cb[c], gb[k][c])) << "pose " << p << ", lane " << l << ": B's corner " << k;
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 64 * 8 * 9);
}

TEST(GatherCorners, SameBitsAsCorners) { expect_same_bits_as_corners(nullptr); }

TEST(GatherCorners, PortableFormSameBitsAsCorners) { expect_same_bits_as_corners(detail::gather_corners_portable); }

TEST(GatherCorners, Avx2FormSameBitsAsCorners) {
  const detail::GatherCorners avx2 = detail::gather_corners_avx2_if_supported();
  if (avx2 == nullptr) GTEST_SKIP() << "no AVX2 on this CPU";
  expect_same_bits_as_corners(avx2);
}

TEST(GatherCorners, AnEmptyBatchReadsNothing) {
  const auto a = build_model(make_box(1.0, 1.0, 1.0, 2));
  const PairContext ctx(*a, Pose{}, *a, Pose{}, QueryRequest{});
  BufferedPairs waiting;
  // Ids no mesh has: an empty batch must not read them (ASan would see the read).
  for (int l = 0; l < geometry::TriangleBatch::kLanes; ++l) waiting.ta[l] = waiting.tb[l] = 0xFFFFFFF0u;
  waiting.batch.size = 0;
  ctx.gather_corners(waiting);
  detail::gather_corners_portable(ctx.a(), ctx.b(), ctx.b_move(), waiting);
  if (const detail::GatherCorners avx2 = detail::gather_corners_avx2_if_supported()) {
    avx2(ctx.a(), ctx.b(), ctx.b_move(), waiting);
  }
  EXPECT_EQ(waiting.batch.size, 0);
}

}  // namespace
}  // namespace caliber::narrow
