// Known answers for each query kind, on configurations built so the answer is known.

#include <gtest/gtest.h>

#include "support/results.h"
#include "bvh/model_data.h"
#include "caliber/error.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

Pose at(double x, double y = 0, double z = 0) { return Pose::from_values(x, y, z, 1, 0, 0, 0); }

/// Triangles of a make_box(…, 1) cube whose normal is `dir`.
std::vector<std::uint32_t> face(const Model& m, const Eigen::Vector3d& dir) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t t = 0; t < m.normals().size(); ++t) {
    if ((m.normals()[t] - dir).norm() < 1e-12) out.push_back(t);
  }
  return out;
}

class Cubes : public ::testing::Test {
 protected:
  std::shared_ptr<const Model> cube = build_model(make_box(0.5, 0.5, 0.5, 1));
};

TEST_F(Cubes, SeparatedCubesDoNotInterfere) {
  const QueryResult r = query(*cube, at(0), *cube, at(1.25), QueryRequest{});
  EXPECT_TRUE(r.contacts.empty());
  EXPECT_TRUE(r.contacts.empty());
  EXPECT_GE(r.stats.node_tests, 1u);
}

TEST_F(Cubes, ProximityRespectsTheTolerance) {
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = 0.2;
  EXPECT_TRUE(query(*cube, at(0), *cube, at(1.25), request).contacts.empty());
  request.tolerance = 0.25;  // exactly the gap: included (distance <= d)
  const QueryResult r = query(*cube, at(0), *cube, at(1.25), request);
  ASSERT_FALSE(r.contacts.empty());
  for (const Contact& c : r.contacts) {
    EXPECT_EQ(c.distance, 0.25);
    EXPECT_EQ(c.point_a.x(), 0.5);
    EXPECT_EQ(c.point_b.x(), 0.75);
  }
  EXPECT_EQ(r.contacts.size(), r.contacts.size());
  const std::vector<TrianglePair> sorted = test::pairs_of(r);
  EXPECT_TRUE(std::is_sorted(sorted.begin(), sorted.end()));
}

TEST_F(Cubes, ContactReducesFacingFacesToOneLocalMinimum) {
  QueryRequest request;
  request.kind = QueryKind::contact;
  request.tolerance = 0.3;
  request.angle_deg = 10;
  const QueryResult r = query(*cube, at(0), *cube, at(1.25), request);
  const auto a_face = face(*cube, Eigen::Vector3d(1, 0, 0));
  const auto b_face = face(*cube, Eigen::Vector3d(-1, 0, 0));
  ASSERT_EQ(a_face.size(), 2u);
  ASSERT_EQ(b_face.size(), 2u);
  // All four facing pairs are at the same distance; the tie goes to the lowest ids.
  ASSERT_EQ(r.contacts.size(), 1u);
  const Contact& c = r.contacts[0];
  EXPECT_EQ(c.tri_a, a_face[0]);
  EXPECT_EQ(c.tri_b, b_face[0]);
  EXPECT_EQ(c.distance, 0.25);
  EXPECT_EQ(c.normal, Eigen::Vector3d(1, 0, 0)) << "normal points from A to B";
}

TEST_F(Cubes, ContactNormalFollowsTheOrderOfTheObjects) {
  QueryRequest request;
  request.kind = QueryKind::contact;
  request.tolerance = 0.3;
  const QueryResult r = query(*cube, at(1.25), *cube, at(0), request);
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_EQ(r.contacts[0].normal, Eigen::Vector3d(-1, 0, 0));
}

TEST_F(Cubes, ResultsAreInWorldCoordinates) {
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = 0.3;
  // Both cubes turned 90 degrees about z and moved: world-space gap along y.
  const Pose pa = Pose::from_values(10, 20, 30, 1, 0, 0, 1);
  const Pose pb = Pose::from_values(10, 21.25, 30, 1, 0, 0, 1);
  const QueryResult r = query(*cube, pa, *cube, pb, request);
  ASSERT_FALSE(r.contacts.empty());
  for (const Contact& c : r.contacts) {
    EXPECT_NEAR(c.point_a.y(), 20.5, 1e-12);
    EXPECT_NEAR(c.point_b.y(), 20.75, 1e-12);
    EXPECT_NEAR(c.normal.y(), 1.0, 1e-12);
  }
}

TEST_F(Cubes, OverlappingCubesInterfereAndHaveZeroDistance) {
  const QueryResult inter = query(*cube, at(0), *cube, at(0.75, 0.1, 0.2), QueryRequest{});
  ASSERT_FALSE(inter.contacts.empty());
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = 0.0;
  const QueryResult prox = query(*cube, at(0), *cube, at(0.75, 0.1, 0.2), request);
  EXPECT_EQ(test::pairs_of(prox), test::pairs_of(inter)) << "with d = 0, proximity reports exactly the intersecting pairs";
  for (const Contact& c : prox.contacts) EXPECT_EQ(c.distance, 0.0);
}

TEST_F(Cubes, FaceToFaceTouchingIsAnIntersection) {
  // B's -x face lies in A's +x face plane: touching counts as intersecting (closed triangles).
  const QueryResult r = query(*cube, at(0), *cube, at(1.0, 0.25, 0), QueryRequest{});
  EXPECT_FALSE(r.contacts.empty());
  const QueryResult apart = query(*cube, at(0), *cube, at(1.0 + 1e-12, 0.25, 0), QueryRequest{});
  EXPECT_TRUE(apart.contacts.empty());
}

TEST(QueryGroups, IncompatibleGroupsNeverTouch) {
  Mesh a = make_box(0.5, 0.5, 0.5, 2);
  Mesh b = a;
  a.groups.assign(a.triangles.size(), 0);
  b.groups.assign(b.triangles.size(), 1);
  for (std::size_t t = 0; t < b.groups.size(); t += 3) b.groups[t] = 2;  // some of B in group 2
  const auto ma = build_model(a);
  const auto mb = build_model(b);
  GroupCompatibility groups;
  groups.compatible[0] = 1u << 2;  // 0 touches only 2
  groups.compatible[1] = 0;
  groups.compatible[2] = 1u;
  for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity, QueryKind::contact}) {
    QueryRequest request;
    request.kind = kind;
    request.tolerance = 0.1;
    request.angle_deg = 60;
    request.groups = &groups;
    const QueryResult r = query(*ma, at(0), *mb, at(0.9, 0.2, 0.1), request);
    for (const Contact& p : r.contacts) EXPECT_EQ(b.groups[p.tri_b], 2) << "kind " << to_string(kind);
    test::expect_identical(r, query_brute_force(*ma, at(0), *mb, at(0.9, 0.2, 0.1), request), "groups");
    if (kind != QueryKind::contact) {  // (fewer candidates can leave more local minima)
      QueryRequest all = request;
      all.groups = nullptr;
      EXPECT_GT(query(*ma, at(0), *mb, at(0.9, 0.2, 0.1), all).contacts.size(), r.contacts.size());
    }
  }
}

TEST(QueryRequestValidation, RejectsBadOptions) {
  const auto m = build_model(make_box(1, 1, 1, 1));
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = -1;
  EXPECT_THROW((void)query(*m, Pose{}, *m, Pose{}, request), Error);
  request.tolerance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)query(*m, Pose{}, *m, Pose{}, request), Error);
  request.tolerance = 0.1;
  request.angle_deg = 181;
  EXPECT_THROW((void)query(*m, Pose{}, *m, Pose{}, request), Error);
  request.angle_deg = -0.5;
  EXPECT_THROW((void)query(*m, Pose{}, *m, Pose{}, request), Error);
  EXPECT_THROW((void)parse_query_kind("collide"), Error);
  Pose bad;
  bad.rotation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_THROW((void)query(*m, bad, *m, Pose{}, QueryRequest{}), Error);
}

TEST(QueryContact, NeedsAdjacency) {
  BuildOptions options;
  options.adjacency = false;
  const auto m = build_model(make_box(1, 1, 1, 1), options);
  QueryRequest request;
  request.kind = QueryKind::contact;
  request.tolerance = 5;
  request.angle_deg = 180;
  EXPECT_THROW((void)query(*m, Pose{}, *m, at(2.5), request), Error);
}

TEST(QueryStats, CountsWork) {
  const auto m = build_model(make_sphere(1, 16, 24));
  const QueryResult r = query(*m, at(0), *m, at(1.5), QueryRequest{});
  EXPECT_GT(r.stats.node_tests, 1u);
  EXPECT_GT(r.stats.leaf_tests, 0u);
  EXPECT_LE(r.stats.leaf_tests, r.stats.node_tests);
  EXPECT_FALSE(r.contacts.empty());
}

}  // namespace
}  // namespace caliber
