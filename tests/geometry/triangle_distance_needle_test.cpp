// A needle beside a nearly parallel edge: every edge pair through the needle's nearest corner is
// nearly parallel, and the nearest pair is that corner with its nearest point on the other
// triangle's edge, which the kernel leaves to the edge pairs (it takes a corner only into the
// other's face). With Ericson's parameter for the edge pairs, which cancels for nearly parallel
// edges, a kernel that did so gave 0.0010000006 for a distance of 0.001, and a proximity query at
// 0.0010000001 kept no contact.

#include "geometry/triangle_distance.h"

#include <cstring>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
#include "geometry/triangle_distance_oracle.h"

namespace caliber::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

/// A pair of triangles and the pair's distance, with its nearest points.
struct Needle {
  Vec3 a[3], b[3];
  Vec3 on_a, on_b;
};

/// A's edge 0 along x from 0 to 1; B's edge 0 from (0.8, -0.001) to (-0.5, -0.001000001), 0.001
/// below A's edge at its corner x = 0.8 and a little farther at x = 0: B's third corner 1e-9 above
/// its second (a needle) or on it (a segment). Each also with A and B swapped.
std::vector<Needle> needles() {
  std::vector<Needle> out;
  for (const double z : {1e-9, 0.0}) {
    Needle n{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
             {{0.8, -0.001, 0}, {-0.5, -0.001000001, 0}, {-0.5, -0.001000001, z}},
             {0.8, 0, 0},
             {0.8, -0.001, 0}};
    out.push_back(n);
    Needle swapped = n;
    for (int i = 0; i < 3; ++i) std::swap(swapped.a[i], swapped.b[i]);
    std::swap(swapped.on_a, swapped.on_b);
    out.push_back(swapped);
  }
  return out;
}

/// The distance within a few units of its last place, the points within as little of the scale.
void expect_nearest(const ClosestPoints& got, const Needle& n, const char* form) {
  EXPECT_NEAR(got.distance, 0.001, 1e-18) << form;
  EXPECT_LT((got.on_a - n.on_a).norm(), 1e-15) << form;
  EXPECT_LT((got.on_b - n.on_b).norm(), 1e-15) << form;
}

TEST(TriangleDistanceNeedle, EveryFormTakesTheCornerNearTheEdge) {
  for (const Needle& n : needles()) {
    expect_nearest(closest_points_triangles(n.a, n.b), n, "dispatched");
    expect_nearest(detail::closest_points_triangles_portable(n.a, n.b), n, "portable");
    if (const detail::TriangleKernel avx2 = detail::closest_points_triangles_avx2_if_supported()) {
      expect_nearest(avx2(n.a, n.b), n, "avx2");
    }
    // The batch, alone in it and in every lane of a full one.
    for (const int size : {1, TriangleBatch::kLanes}) {
      TriangleBatch batch;
      for (int l = 0; l < size; ++l) batch.add(n.a, n.b);
      ClosestPointsBatch lanes;
      std::memset(&lanes, 0xFF, sizeof lanes);
      closest_points_triangles_batch(batch, lanes);
      for (int l = 0; l < size; ++l) expect_nearest(lanes.get(l), n, "batch");
    }
  }
}

TEST(TriangleDistanceNeedle, QueriesKeepThePairAtItsDistance) {
  for (const Needle& n : needles()) {
    Mesh ma, mb;
    ma.vertices = {n.a[0], n.a[1], n.a[2]};
    mb.vertices = {n.b[0], n.b[1], n.b[2]};
    ma.triangles = {{0, 1, 2}};
    mb.triangles = {{0, 1, 2}};
    const std::shared_ptr<const Model> a = build_model(ma), b = build_model(mb);
    QueryRequest request;
    request.kind = QueryKind::proximity;
    request.tolerance = 0.0010000001;
    EXPECT_EQ(query(*a, Pose{}, *b, Pose{}, request).contacts.size(), 1u);
    request.kind = QueryKind::distance;
    request.tolerance = kUnbounded;
    const QueryResult nearest = query(*a, Pose{}, *b, Pose{}, request);
    ASSERT_EQ(nearest.contacts.size(), 1u);
    EXPECT_NEAR(nearest.contacts[0].distance, 0.001, 1e-18);
  }
}

}  // namespace
}  // namespace caliber::geometry

namespace caliber::geometry {
namespace {

/// An edge shorter than about 1.5e-154 has a subnormal squared length e, and 1 / e overflows: the
/// edge pairs take such an edge at its first corner (the nearest point on it is within its length).
/// A kernel that divided by it anyway kept the other edge's point at its start.
TEST(TriangleDistanceShortEdge, SegmentsAndEveryFormKeepTheNearestPoint) {
  Eigen::Vector3d c1, c2;
  closest_points_segments({0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, 1, 1e-155}, c1, c2);
  EXPECT_EQ(c1, Eigen::Vector3d(0.5, 0, 0));
  EXPECT_NEAR((c2 - c1).norm(), 1.0, 1e-15);

  const Eigen::Vector3d a[3] = {{0, 1, -1}, {0, 1, 1}, {0, 5, 0}};
  const Eigen::Vector3d b[3] = {{0, 0, 0}, {1e-155, 0, 0}, {0, 1e-155, 1e-155}};
  EXPECT_NEAR(closest_points_triangles(a, b).distance, 1.0, 1e-15);
  EXPECT_NEAR(detail::closest_points_triangles_portable(a, b).distance, 1.0, 1e-15);
  ClosestPoints within{};
  ASSERT_TRUE(closest_points_triangles_within(a, b, 1.2, within));
  EXPECT_NEAR(within.distance, 1.0, 1e-15);
  TriangleBatch batch;
  batch.add(a, b);
  batch.add(b, a);
  ClosestPointsBatch lanes;
  closest_points_triangles_batch(batch, lanes);
  EXPECT_NEAR(lanes.get(0).distance, 1.0, 1e-15);
  EXPECT_NEAR(lanes.get(1).distance, 1.0, 1e-15);
}

/// A face whose sides are near 1e80: |ab x ac|^2 overflows. The face pair then has no plane to
/// project along (1 / |n|^2 is 0, and a kernel that took the face anyway projected x onto itself:
/// distance 0), so the kernel takes such a triangle by its edges alone, never nearer than it is.
TEST(TriangleDistanceHugeFace, TakenByItsEdgesNeverBelowTheDistance) {
  const Eigen::Vector3d x(9e79, 7.5e72, 1e78);
  const Eigen::Vector3d b[3] = {{0, 0, 0}, {1e80, 0, 0}, {0, 1.5e74, 0}};
  const Eigen::Vector3d tilted[3] = {x, x + Eigen::Vector3d(2e80, 3e74, -2e78), x + Eigen::Vector3d(2e80, 4.5e74, -2e78)};
  const Eigen::Vector3d upright[3] = {x, x + Eigen::Vector3d(0, 0, 1e80), x + Eigen::Vector3d(1e78, 0, 1e80)};
  for (const auto* a : {tilted, upright}) {
    const double truth = oracle::triangles_distance(a, b);
    const ClosestPoints want = detail::closest_points_triangles_portable(a, b);
    EXPECT_GE(want.distance, truth * (1 - 0x1p-50));
    EXPECT_LE(want.distance, truth * (1 + 1e-9));
    EXPECT_EQ(closest_points_triangles(a, b).distance, want.distance);
    TriangleBatch batch;
    batch.add(a, b);
    batch.add(b, a);
    ClosestPointsBatch lanes;
    closest_points_triangles_batch(batch, lanes);
    EXPECT_EQ(lanes.get(0).distance, want.distance);
    EXPECT_EQ(lanes.get(1).distance, want.distance);
    ClosestPoints within{};
    ASSERT_TRUE(closest_points_triangles_within(a, b, 2 * truth, within));
    EXPECT_EQ(within.distance, want.distance);
  }
}

}  // namespace
}  // namespace caliber::geometry
