// The node slab (docs/architecture.md, "Why the slab"): two flat patches lying parallel a small
// gap apart, A tilted in its own mesh's frame so that all its boxes are thick (funnel's wall), B
// flat in its frame and posed parallel to A (a part resting on that wall). The slab of A against
// B's thin boxes must prune them (no leaf test at all when the gap is beyond the tolerance) and
// never prune what the leaf test keeps: at gaps on both sides of the tolerance, and touching, the
// answer is the oracle's, also when both patches are tilted in their own frames.

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

const Eigen::Vector3d kNormal = Eigen::Vector3d(1.0, 2.0, 3.0).normalized();

/// An n x n grid of unit cells (2 n^2 triangles) in the plane through the origin with the given
/// unit normal, shifted by `shift` along the plane's first axis (so that two patches do not share
/// vertices). The first axis is the normal rotated onto: the normal's cross product with x.
Mesh patch(int n, double shift, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d u = normal.cross(Eigen::Vector3d::UnitX()).normalized();
  const Eigen::Vector3d v = normal.cross(u);
  Mesh m;
  m.source = "tilted patch";
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) m.vertices.push_back((i - 0.5 * n + shift) * u + (j - 0.5 * n) * v);
  }
  const auto at = [n](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return m;
}

/// B's pose: B's own rotation `own` (which turns its normal onto kNormal), then `common`, then a
/// shift of `gap` along the patches' normal in A's frame.
Pose pose_at_gap(const Pose& common, const Eigen::Quaterniond& own, double gap) {
  Pose p = common;
  p.rotation = common.rotation * own;
  p.translation = common.translation + common.rotation_matrix() * (gap * kNormal);
  return p;
}

/// The rotation that turns B's flat patch (normal z) parallel to A's tilted one.
Eigen::Quaterniond z_onto_normal() { return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), kNormal); }

TEST(NodeSlab, ParallelPatchesApartAreCutBeforeTheLeaves) {
  const auto a = build_model(patch(16, 0.0, kNormal));
  const auto b = build_model(patch(16, 0.37, Eigen::Vector3d::UnitZ()));
  const Pose identity = Pose::from_values(0, 0, 0, 1, 0, 0, 0);
  QueryRequest interference;
  interference.kind = QueryKind::interference;
  const QueryResult apart = query(*a, identity, *b, pose_at_gap(identity, z_onto_normal(), 0.01), interference);
  EXPECT_TRUE(apart.pairs.empty());
  // Without the slab every box of the tilted patch overlaps B's down to the leaves (thousands of
  // leaf tests: 3,988 with the slab test switched off); with it, the tests stop near the roots.
  EXPECT_EQ(apart.stats.leaf_tests, 0u);
  EXPECT_LT(apart.stats.node_tests, 50u);

  QueryRequest proximity;
  proximity.kind = QueryKind::proximity;
  proximity.tolerance = 0.02;
  const QueryResult near = query(*a, identity, *b, pose_at_gap(identity, z_onto_normal(), 0.01), proximity);
  EXPECT_FALSE(near.pairs.empty()) << "0.01 apart is within a tolerance of 0.02";
}

TEST(NodeSlab, GapsAroundTheToleranceGiveTheOracleAnswer) {
  const auto a = build_model(patch(8, 0.0, kNormal));
  const auto b_flat = build_model(patch(8, 0.37, Eigen::Vector3d::UnitZ()));
  const auto b_tilted = build_model(patch(8, 0.37, kNormal));
  std::mt19937_64 rng(20261123);
  const double tolerance = 0.01;
  int non_empty = 0, empty = 0;
  for (int pose = 0; pose < 8; ++pose) {
    const bool flat = pose % 2 == 0;
    const Model& b = flat ? *b_flat : *b_tilted;
    const Eigen::Quaterniond own = flat ? z_onto_normal() : Eigen::Quaterniond::Identity();
    const Pose common = pose < 2 ? Pose::from_values(0, 0, 0, 1, 0, 0, 0) : test::random_pose(rng, 3.0);
    for (const double gap : {0.0, 1e-12, 0.5 * tolerance, tolerance * (1 - 1e-9), tolerance * (1 + 1e-6), 0.011, -0.004}) {
      for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity, QueryKind::contact}) {
        QueryRequest request;
        request.kind = kind;
        request.tolerance = tolerance;
        request.angle_deg = 180.0;  // parallel patches face the same way: let the cone test pass
        const Pose pb = pose_at_gap(common, own, gap);
        const std::string what = "pose " + std::to_string(pose) + " gap " + std::to_string(gap) + " kind " +
                                 std::to_string(static_cast<int>(kind));
        const QueryResult fast = query(*a, common, b, pb, request);
        test::expect_identical(fast, query_brute_force(*a, common, b, pb, request), what);
        if (::testing::Test::HasFatalFailure()) return;
        (fast.pairs.empty() ? empty : non_empty) += 1;
      }
    }
  }
  // Both answers occur, so the comparison is not vacuous.
  EXPECT_GT(non_empty, 20);
  EXPECT_GT(empty, 10);
}

}  // namespace
}  // namespace caliber
