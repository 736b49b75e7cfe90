// Contact::depth, the penetration estimate of intersecting pairs: B's deepest vertex behind the
// plane through A's closest point along the contact normal, on a case worked by hand, and against
// the formula in the world frame on random overlapping poses.

#include <random>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

TEST(Depth, ABoxPushedIntoABoxByAFifth) {
  const auto box = build_model(make_box(0.5, 0.5, 0.5, 1));
  QueryRequest request;
  request.kind = QueryKind::proximity;                            // every intersecting pair, whatever its normals
  const Pose up = Pose::from_values(0.1, 0.05, 0.8, 1, 0, 0, 0);  // B's bottom 0.2 below A's top
  const QueryResult r = query(*box, Pose{}, *box, up, request);
  int top = 0;
  for (const Contact& c : r.contacts) {
    ASSERT_EQ(c.distance, 0.0);
    EXPECT_GE(c.depth, 0.0);
    if (c.normal.z() > 0.999 && std::abs(c.point_a.z() - 0.5) < 1e-12) {  // A's top face against B's sides
      EXPECT_NEAR(c.depth, 0.2, 1e-12);
      ++top;
    }
  }
  EXPECT_GT(top, 0);
  request.kind = QueryKind::proximity;
  request.tolerance = 0.05;
  const QueryResult apart = query(*box, Pose{}, *box, Pose::from_values(0, 0, 1.02, 1, 0, 0, 0), request);
  ASSERT_FALSE(apart.contacts.empty());
  for (const Contact& c : apart.contacts) EXPECT_EQ(c.depth, 0.0) << "only intersecting pairs have a depth";
}

TEST(Depth, IsTheDeepestVertexOfBBehindAsPlane) {
  std::mt19937_64 rng(4);
  const auto torus = build_model(make_torus(1.0, 0.35, 16, 10));
  const auto sphere = build_model(make_sphere(0.8, 10, 14));
  QueryRequest request;
  request.kind = QueryKind::contact;
  request.tolerance = 0.01;
  request.angle_deg = 60;
  int checked = 0;
  for (int i = 0; i < 40; ++i) {
    const Pose pa = test::random_pose(rng, 0.6);
    const Pose pb = test::random_pose(rng, 0.6);
    const QueryResult r = query(*torus, pa, *sphere, pb, request);
    for (const Contact& c : r.contacts) {
      if (c.distance != 0.0) {
        EXPECT_EQ(c.depth, 0.0);
        continue;
      }
      double want = 0.0;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d v = pb.apply(sphere->mesh().vertices[sphere->mesh().triangles[c.tri_b][k]]);
        want = std::max(want, c.normal.dot(c.point_a - v));
      }
      EXPECT_NEAR(c.depth, want, 1e-12);
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

}  // namespace
}  // namespace caliber
