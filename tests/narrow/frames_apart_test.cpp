// frames_apart, the distance bound's separation of two Frames along the direction
// between a point of each: never above the distance of any two points of the boxes (corners,
// points on faces, inside), on random boxes at random poses, some overlapping; and tight where the
// Frames' own axes are not (two flat squares offset along a diagonal).

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "narrow/frames_apart.h"

namespace caliber::narrow {
namespace {

/// frames_apart with PairContext's allowances.
double apart_of(const OrientedBox& a, const OrientedBox& b, const double d[3]) {
  double r[3][3], t[3];
  frames_relative(a, b, d, r, t);
  return frames_apart(a.half, b.half, r, t, 1e-12, 1.0 - 3e-9);
}

OrientedBox random_frame(std::mt19937_64& rng, double spread) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Matrix3d r =
      Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
  OrientedBox f{};
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < 3; ++i) f.axis[k][i] = r(i, k);
    f.center[k] = spread * normal(rng);
    // Some boxes flat (a triangle fan's slab), some long, some of no extent along an axis.
    const double u = unit(rng);
    f.half[k] = u < 0.1 ? 0.0 : u < 0.3 ? 1e-3 * unit(rng) : unit(rng);
  }
  return f;
}

/// The point of f at frame coordinates t (each in [-1, 1] of the half-extents).
Eigen::Vector3d point_of(const OrientedBox& f, const double t[3]) {
  Eigen::Vector3d x(f.center[0], f.center[1], f.center[2]);
  for (int k = 0; k < 3; ++k) x += t[k] * f.half[k] * Eigen::Vector3d(f.axis[k][0], f.axis[k][1], f.axis[k][2]);
  return x;
}

TEST(FramesApart, NeverAboveThePointsDistance) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::uniform_int_distribution<int> corner(0, 1);
  long positive = 0, checked = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const OrientedBox a = random_frame(rng, 1.0), b = random_frame(rng, trial % 2 == 0 ? 1.0 : 4.0);
    const double d[3] = {b.center[0] - a.center[0], b.center[1] - a.center[1], b.center[2] - a.center[2]};
    const double apart = apart_of(a, b, d);
    ASSERT_GE(apart, 0.0);
    positive += apart > 0.0;
    // Corners against corners, points on faces (one coordinate at +-1) and inside.
    double least = INFINITY;
    for (int s = 0; s < 400; ++s) {
      double ta[3], tb[3];
      for (int k = 0; k < 3; ++k) {
        ta[k] = s < 64 ? 2.0 * corner(rng) - 1.0 : coordinate(rng);
        tb[k] = s < 64 ? 2.0 * corner(rng) - 1.0 : coordinate(rng);
      }
      if (s >= 64 && s < 300) {
        ta[s % 3] = 2.0 * corner(rng) - 1.0;
        tb[(s / 3) % 3] = 2.0 * corner(rng) - 1.0;
      }
      least = std::min(least, (point_of(b, tb) - point_of(a, ta)).norm());
      ++checked;
    }
    ASSERT_LE(apart, least) << "trial " << trial;
  }
  EXPECT_GT(positive, 1000);
  EXPECT_EQ(checked, 4000L * 400);
}

TEST(FramesApart, TightWhereTheFramesAxesAreNot) {
  // Two unit squares (no thickness) in the plane z = 0, offset by 3 along x and y: 1 apart along
  // each axis, sqrt(2) apart. The Frames' own axes see 1; frames_apart sees about sqrt(2).
  OrientedBox a{}, b{};
  for (int k = 0; k < 3; ++k) a.axis[k][k] = b.axis[k][k] = 1.0;
  a.half[0] = a.half[1] = b.half[0] = b.half[1] = 1.0;
  b.center[0] = b.center[1] = 3.0;
  const double d[3] = {3.0, 3.0, 0.0};
  const double apart = apart_of(a, b, d);
  EXPECT_LE(apart, std::sqrt(2.0));
  EXPECT_GT(apart, std::sqrt(2.0) * (1.0 - 1e-8));
  // Overlapping: nothing.
  b.center[0] = b.center[1] = 1.5;
  const double near[3] = {1.5, 1.5, 0.0};
  EXPECT_EQ(apart_of(a, b, near), 0.0);
}

}  // namespace
}  // namespace caliber::narrow
