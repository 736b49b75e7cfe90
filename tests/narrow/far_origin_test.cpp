// A mesh far from its own origin (a part in its assembly's or a survey's frame) costs what the same
// mesh at its origin costs: its node volumes are relative to its own center. The answers are the
// brute force's, whatever the method, and the volumes still cover every vertex.

#include <gtest/gtest.h>

#include <vector>

#include "bvh/model_data.h"
#include "caliber/engine.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/results.h"

namespace caliber {
namespace {

Mesh moved(Mesh mesh, const Eigen::Vector3d& by) {
  for (auto& v : mesh.vertices) v += by;
  return mesh;
}

QueryRequest kind(QueryKind k, double tolerance = 0.0) {
  QueryRequest r;
  r.kind = k;
  r.tolerance = tolerance;
  return r;
}

TEST(FarOrigin, TouchingSpheresFarInTheirVerticesCostWhatTheyCostAtTheOrigin) {
  // Two spheres of radius 0.01 touching, 1e7 from the origin: in their vertices, or by their poses.
  const Eigen::Vector3d far(1e7, -3e6, 5e6);
  const Mesh sphere = make_sphere(0.01, 24, 32);
  const auto near_a = build_model(sphere), near_b = build_model(sphere);
  const auto far_a = build_model(moved(sphere, far)), far_b = build_model(moved(sphere, far + Eigen::Vector3d(0.0199, 0, 0)));
  EXPECT_NE(data(*far_a).origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(data(*near_a).origin, Eigen::Vector3d::Zero()) << "a mesh about its origin keeps its volumes";
  Pose pa, pb;
  pa.translation = far;
  pb.translation = far + Eigen::Vector3d(0.0199, 0, 0);
  for (const QueryRequest& request : {kind(QueryKind::interference), kind(QueryKind::proximity, 1e-3),
                                      kind(QueryKind::contact, 1e-3), kind(QueryKind::distance)}) {
    const QueryResult posed = query(*near_a, pa, *near_b, pb, request);
    const QueryResult in_vertices = query(*far_a, Pose{}, *far_b, Pose{}, request);
    EXPECT_LE(in_vertices.stats.node_tests, 2 * posed.stats.node_tests + 16) << to_string(request.kind);
    EXPECT_LE(in_vertices.stats.leaf_tests, 2 * posed.stats.leaf_tests + 16) << to_string(request.kind);
    EXPECT_FALSE(in_vertices.contacts.empty()) << to_string(request.kind);
    // Exact: the brute force's pairs, and every method's bits.
    const QueryResult brute = query_brute_force(*far_a, Pose{}, *far_b, Pose{}, request);
    if (request.kind != QueryKind::distance) EXPECT_EQ(test::pairs_of(in_vertices), test::pairs_of(brute));
    if (request.kind == QueryKind::distance) EXPECT_EQ(in_vertices.contacts[0].distance, brute.contacts[0].distance);
  }
}

TEST(FarOrigin, EveryMethodGivesTheSameBitsOnFarPartsPosedAnywhere) {
  const Eigen::Vector3d far(-4e6, 2.5e6, 9e5);
  const auto a = build_model(moved(make_torus(1.0, 0.3, 32, 16), far));
  const auto b = build_model(moved(make_sphere(0.5, 16, 24), far + Eigen::Vector3d(0.9, 0.2, 0.1)));
  Pose pb;
  pb.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  pb.translation = far - pb.rotation * far;  // turns B about the far point, not the origin
  const QueryRequest request = kind(QueryKind::proximity, 0.05);
  const QueryResult one = query(*a, Pose{}, *b, pb, request);
  const QueryResult brute = query_brute_force(*a, Pose{}, *b, pb, request);
  ASSERT_FALSE(one.contacts.empty());
  EXPECT_EQ(test::pairs_of(one), test::pairs_of(brute));
  Frame frame;
  frame.models = {a, b};
  frame.poses = {Pose{}, pb};
  frame.pairs = {ObjectPair{0, 1}};
  frame.request = request;
  for (const Method m : {Method::sequential, Method::stealing, Method::hybrid, Method::apriori}) {
    EngineOptions options;
    options.method = m;
    options.threads = 2;
    Engine engine(options);
    const StepResult step = engine.step(frame);
    ASSERT_EQ(step.contacts.size(), one.contacts.size()) << to_string(m);
    for (std::size_t i = 0; i < one.contacts.size(); ++i) {
      EXPECT_EQ(step.contacts[i].tri_a, one.contacts[i].tri_a);
      EXPECT_EQ(step.contacts[i].tri_b, one.contacts[i].tri_b);
      EXPECT_EQ(step.contacts[i].distance, one.contacts[i].distance);
      EXPECT_EQ(step.contacts[i].point_a, one.contacts[i].point_a);
    }
  }
}

}  // namespace
}  // namespace caliber
