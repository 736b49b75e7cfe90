// The node slab (docs/architecture.md, "Why the slab"): two flat patches lying parallel a small
// gap apart, A tilted in its own mesh's frame so that all its boxes are thick (funnel's wall), B
// flat in its frame and posed parallel to A (a part resting on that wall). The slab of A against
// B's thin boxes must prune them (no leaf test at all when the gap is beyond the tolerance) and
// never prune what the leaf test keeps: at gaps on both sides of the tolerance, and touching, the
// answer is the oracle's, also when both patches are tilted in their own frames. When both are, the
// boxes are thick on both sides and only the disks (narrow::disks_beyond_slabs: each node's
// sphere cut by its slab, against the other's slab) cut the tree early.

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/pair_context.h"
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
  EXPECT_TRUE(apart.contacts.empty());
  // Without the slab every box of the tilted patch overlaps B's down to the leaves (thousands of
  // leaf tests: 3,988 with the slab test switched off); with it, the tests stop near the roots.
  EXPECT_EQ(apart.stats.leaf_tests, 0u);
  EXPECT_LT(apart.stats.node_tests, 50u);

  QueryRequest proximity;
  proximity.kind = QueryKind::proximity;
  proximity.tolerance = 0.02;
  const QueryResult near = query(*a, identity, *b, pose_at_gap(identity, z_onto_normal(), 0.01), proximity);
  EXPECT_FALSE(near.contacts.empty()) << "0.01 apart is within a tolerance of 0.02";
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
        const std::string what =
            "pose " + std::to_string(pose) + " gap " + std::to_string(gap) + " kind " + std::to_string(static_cast<int>(kind));
        const QueryResult fast = query(*a, common, b, pb, request);
        test::expect_identical(fast, query_brute_force(*a, common, b, pb, request), what);
        if (::testing::Test::HasFatalFailure()) return;
        (fast.contacts.empty() ? empty : non_empty) += 1;
      }
    }
  }
  // Both answers occur, so the comparison is not vacuous.
  EXPECT_GT(non_empty, 20);
  EXPECT_GT(empty, 10);
}

TEST(NodeSlab, BothTiltedParallelPatchesApartAreCutHighInTheTree) {
  const auto a = build_model(patch(16, 0.0, kNormal));
  const auto b = build_model(patch(16, 0.37, kNormal));
  const Pose identity = Pose::from_values(0, 0, 0, 1, 0, 0, 0);
  QueryRequest interference;
  interference.kind = QueryKind::interference;
  const QueryResult apart = query(*a, identity, *b, pose_at_gap(identity, Eigen::Quaterniond::Identity(), 0.01), interference);
  EXPECT_TRUE(apart.contacts.empty());
  // Both patches' boxes are thick, so the boxes and the slab-against-box tests let every pair down
  // to the leaves (11.5k node tests and 2.9k leaf tests). The staying node's slab projected along
  // the slot's slab (detail::WideTest: lambda times the slot's slab plus the rest of its box) is as
  // thin along the other's slab axis as the slot's own slab: a few visits refuse every pair.
  EXPECT_EQ(apart.stats.leaf_tests, 0u);
  EXPECT_LT(apart.stats.node_tests, 100u);
}

/// Every vertex of the triangles below node `n` of `model` (leaves hold triangle ids).
std::vector<Eigen::Vector3d> vertices_below(const Model& model, std::uint32_t n) {
  std::vector<Eigen::Vector3d> out;
  std::vector<std::uint32_t> todo{n};
  while (!todo.empty()) {
    const BvhNode& node = data(model).nodes[todo.back()];
    todo.pop_back();
    if (node.is_leaf()) {
      for (int k = 0; k < 3; ++k) out.push_back(model.mesh().vertices[model.mesh().triangles[node.index][k]]);
    } else {
      todo.push_back(node.index);
      todo.push_back(node.index + 1);
    }
  }
  return out;
}

/// Whether every point lies beyond the slab lo <= axis . x <= hi by more than `reach` along the
/// axis, all on the same side.
bool all_beyond(const std::vector<Eigen::Vector3d>& points, const float axis[3], float lo, float hi, double reach) {
  const Eigen::Vector3d m(axis[0], axis[1], axis[2]);
  bool above = true, below = true;
  for (const Eigen::Vector3d& p : points) {
    above = above && m.dot(p) > hi + reach * m.norm();
    below = below && m.dot(p) < lo - reach * m.norm();
  }
  return above || below;
}

// What the disks claim, checked on the vertices themselves: wherever they refuse a pair the rest of
// the node test lets through, every vertex below one node lies beyond the other node's slab by
// more than the tolerance (on overlapping and nearby poses of curved, boxy and flat meshes).
TEST(NodeSlab, DisksRefuseOnlyWhatLiesBeyondASlab) {
  const auto torus = build_model(make_torus(1.0, 0.35, 40, 24));
  const auto box = build_model(make_box(0.6, 0.4, 0.3, 12));
  const auto flat_a = build_model(patch(12, 0.0, kNormal));
  const auto flat_b = build_model(patch(12, 0.37, kNormal));
  const std::pair<const Model*, const Model*> pairs[] = {
      {torus.get(), box.get()}, {torus.get(), torus.get()}, {flat_a.get(), flat_b.get()}};
  std::mt19937_64 rng(20261125);
  long refused = 0;
  for (const auto& [a, b] : pairs) {
    for (const double tolerance : {0.0, 0.02}) {
      QueryRequest request;
      request.kind = tolerance > 0.0 ? QueryKind::proximity : QueryKind::interference;
      request.tolerance = tolerance;
      for (int p = 0; p < 12; ++p) {
        const Pose pose_a = test::random_pose(rng, 0.3);
        Pose pose_b = test::random_pose(rng, 1.0);
        if (a == flat_a.get()) {  // nearly parallel, a small gap apart
          pose_b = pose_a;
          pose_b.rotation = pose_a.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * (p - 6), Eigen::Vector3d::UnitX()));
          pose_b.translation += pose_a.rotation_matrix() * ((0.004 * p - 0.01) * kNormal);
        }
        const narrow::PairContext ctx(*a, pose_a, *b, pose_b, request);
        const Eigen::Matrix3d to_a = pose_a.rotation_matrix().transpose();
        const Eigen::Matrix3d to_b = pose_b.rotation_matrix().transpose();
        std::vector<std::pair<std::uint32_t, std::uint32_t>> work{{0, 0}};
        for (std::size_t w = 0; w < work.size() && w < 4000; ++w) {
          const BvhNode& na = data(*a).nodes[work[w].first];
          const BvhNode& nb = data(*b).nodes[work[w].second];
          if (na.is_leaf() || nb.is_leaf()) continue;
          for (std::uint32_t k = 0; k < 4; ++k) {
            const std::uint32_t ia = na.index + k / 2, ib = nb.index + k % 2;
            auto sa = ctx.prepare_a(ia);
            auto sb = ctx.prepare_b(ib);
            ctx.prepare_disk_a(sa);
            ctx.prepare_disk_b(sb);
            if (!ctx.node_test(sa, sb)) continue;
            if (ctx.node_test_2x2_lane(sa, sb)) {
              work.emplace_back(ia, ib);
              continue;
            }
            ++refused;
            // B's vertices in A's frame against A's slab; A's in B's frame against B's slab.
            std::vector<Eigen::Vector3d> below_b = vertices_below(*b, ib), below_a = vertices_below(*a, ia);
            for (Eigen::Vector3d& v : below_b)
              v = to_a * (pose_b.rotation_matrix() * v + pose_b.translation - pose_a.translation);
            for (Eigen::Vector3d& v : below_a)
              v = to_b * (pose_a.rotation_matrix() * v + pose_a.translation - pose_b.translation);
            const BvhNodeFilter& fa = data(*a).filters[ia];
            const BvhNodeFilter& fb = data(*b).filters[ib];
            EXPECT_TRUE(all_beyond(below_b, fa.cone_axis, fa.slab_lo, fa.slab_hi, tolerance) ||
                        all_beyond(below_a, fb.cone_axis, fb.slab_lo, fb.slab_hi, tolerance))
                << "pose " << p << " nodes " << ia << " " << ib;
            if (::testing::Test::HasFailure()) return;
          }
        }
      }
    }
  }
  EXPECT_GT(refused, 500) << "the disks refuse pairs, so the check says something";
}

}  // namespace
}  // namespace caliber
