#include "geometry/triangle_distance.h"

#include <random>

#include <gtest/gtest.h>

namespace caliber::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

/// Distance by dense sampling of both triangles (an upper bound that converges to the truth).
double sampled_distance(const Vec3 a[3], const Vec3 b[3], int n) {
  std::vector<Vec3> pa, pb;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const double u = double(i) / n, v = double(j) / n;
      pa.push_back(a[0] + u * (a[1] - a[0]) + v * (a[2] - a[0]));
      pb.push_back(b[0] + u * (b[1] - b[0]) + v * (b[2] - b[0]));
    }
  }
  double best = 1e300;
  for (const auto& p : pa)
    for (const auto& q : pb) best = std::min(best, (p - q).norm());
  return best;
}

TEST(TriangleDistance, ParallelFaces) {
  const Vec3 a[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Vec3 b[3] = {{0, 0, 0.25}, {1, 0, 0.25}, {0, 1, 0.25}};
  EXPECT_DOUBLE_EQ(closest_points_triangles(a, b).distance, 0.25);
}

TEST(TriangleDistance, SkewEdges) {
  const Vec3 a[3] = {{-1, 0, 0}, {1, 0, 0}, {0, 0, -1}};
  const Vec3 b[3] = {{0, -1, 0.5}, {0, 1, 0.5}, {0, 0, 1.5}};
  const ClosestPoints cp = closest_points_triangles(a, b);
  EXPECT_NEAR(cp.distance, 0.5, 1e-15);
  EXPECT_NEAR((cp.on_a - Vec3(0, 0, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((cp.on_b - Vec3(0, 0, 0.5)).norm(), 0.0, 1e-15);
}

TEST(TriangleDistance, VertexAboveFace) {
  const Vec3 a[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Vec3 b[3] = {{1, 1, 2}, {1, 2, 5}, {2, 1, 5}};
  const ClosestPoints cp = closest_points_triangles(a, b);
  EXPECT_NEAR(cp.distance, 2.0, 1e-15);
  EXPECT_NEAR((cp.on_a - Vec3(1, 1, 0)).norm(), 0.0, 1e-15);
}

TEST(TriangleDistance, DegenerateInputsGiveFinitePointsOnTheTriangles) {
  const Vec3 a[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Vec3 point[3] = {{1, 1, 3}, {1, 1, 3}, {1, 1, 3}};
  const Vec3 segment[3] = {{5, 5, 1}, {7, 7, 1}, {6, 6, 1}};
  ClosestPoints cp = closest_points_triangles(a, point);
  EXPECT_NEAR(cp.distance, 3.0, 1e-15);
  EXPECT_TRUE(cp.on_a.allFinite());
  cp = closest_points_triangles(segment, a);
  EXPECT_NEAR(cp.distance, std::sqrt(19.0), 1e-12);  // (5,5,1) to (2,2,0) on the hypotenuse x+y=4
  cp = closest_points_triangles(point, point);
  EXPECT_EQ(cp.distance, 0.0);
}

TEST(TriangleDistance, RandomTrianglesMatchDenseSampling) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int iter = 0; iter < 200; ++iter) {
    Vec3 a[3], b[3];
    for (auto& v : a) v = Vec3(u(rng), u(rng), u(rng));
    for (auto& v : b) v = Vec3(u(rng), u(rng), u(rng)) + Vec3(1.5, 0, 0);
    const ClosestPoints cp = closest_points_triangles(a, b);
    const double sampled = sampled_distance(a, b, 40);
    EXPECT_LE(cp.distance, sampled + 1e-12) << "iteration " << iter;  // it is the minimum
    EXPECT_GE(cp.distance, sampled - 0.15) << "iteration " << iter;   // sampling step bound
    EXPECT_NEAR((cp.on_b - cp.on_a).norm(), cp.distance, 1e-15);
  }
}

}  // namespace
}  // namespace caliber::geometry
