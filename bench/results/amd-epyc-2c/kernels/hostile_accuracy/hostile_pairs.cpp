// The closest-points kernel's distance against the oracle of tests/geometry (every feature pair in
// __float128, the exact intersection test for 0) on five kinds of hostile triangle pairs: a needle
// beside an edge of the other, nearly parallel, crossing it or a gap apart; two slivers; a triangle
// turned about an edge of the other by 1e-10 to 0.3 rad; nearly coplanar crossings; tiny neighbours.
// Prints, per kind, the largest error in units of 2^-52 of the pair's largest coordinate and the
// pairs off by more than 256 units (2^-44), and, with DUMP set, every pair's distance.
//
//   g++ -O2 -std=c++20 -Isrc -Iinclude -Itests -I/usr/include/eigen3 hostile_pairs.cpp \
//       tests/geometry/triangle_distance_oracle.cpp build/libcaliber.a -ltbb -o hostile_pairs
//   ./hostile_pairs SEED PAIRS

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <Eigen/Geometry>

#include "geometry/triangle_distance.h"
#include "geometry/triangle_distance_oracle.h"

namespace {

using caliber::geometry::ClosestPoints;
using Vec3 = Eigen::Vector3d;

struct Source {
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  double any() { return u(rng); }
  Vec3 point() { return Vec3(any(), any(), any()); }
  double log_between(double lo, double hi) { return std::pow(10.0, std::uniform_real_distribution<double>(lo, hi)(rng)); }
  double sign() { return any() > 0 ? 1.0 : -1.0; }
};

/// Pair `it` of kind it % 5 (A's corners are already random points).
void make_pair(Source& r, int it, Vec3 (&a)[3], Vec3 (&b)[3]) {
  switch (it % 5) {
    case 0: {  // a needle beside edge e of A, nearly parallel, crossing it or a gap away
      const int e = it % 3;
      const Vec3 p = a[e], d = a[(e + 1) % 3] - p, across = d.cross(r.point()).normalized();
      const double angle = r.log_between(-14, -1), gap = (it % 2) ? r.log_between(-12, -1) * r.sign() : 0.0;
      const Vec3 dir = d + angle * d.norm() * across.cross(d).normalized() * r.sign();
      const Vec3 mid = p + (0.5 + 0.6 * r.any()) * d + gap * across;
      b[0] = mid - (0.1 + std::abs(r.any())) * dir;
      b[1] = mid + (0.1 + std::abs(r.any())) * dir;
      b[2] = b[it % 2] + r.log_between(-15, -6) * r.point();
      break;
    }
    case 1: {  // two slivers, close
      for (Vec3* t : {a, b}) {
        t[0] = r.point();
        t[1] = r.point();
        t[2] = 0.5 * (t[0] + t[1]) + r.log_between(-15, -6) * r.point();
      }
      const Vec3 offset = b[0] - a[0] - r.log_between(-12, -1) * r.point();
      for (auto& v : b) v -= offset * (0.9 + 0.1 * r.any());
      break;
    }
    case 2: {  // A turned about its edge 0 by a small angle, shifted along it (touching or crossing)
      const Vec3 p = a[0], d = a[1] - a[0];
      const Eigen::AngleAxisd turn(r.log_between(-10, -0.5) * r.sign(), d.normalized());
      const Vec3 shift = (0.3 * r.any()) * d + r.log_between(-16, -8) * r.point() * (it % 2);
      for (int i = 0; i < 3; ++i) b[i] = p + turn * (a[(i + (it / 5) % 3) % 3] - p) + shift;
      break;
    }
    case 3: {  // nearly coplanar with A, crossing it
      const Vec3 n = (a[1] - a[0]).cross(a[2] - a[0]).normalized();
      for (auto& v : b) {
        const double s = r.any(), t = r.any();
        v = a[0] + s * (a[1] - a[0]) + t * (a[2] - a[0]) + r.log_between(-14, -2) * r.any() * n;
      }
      break;
    }
    default:  // tiny neighbours of A's first corner
      for (auto& v : b) v = a[0] + r.log_between(-8, -1) * r.point();
      break;
  }
}

}  // namespace

int main(int argc, char** argv) {
  Source r{std::mt19937_64(argc > 1 ? std::atoi(argv[1]) : 1)};
  const int pairs = argc > 2 ? std::atoi(argv[2]) : 200000;
  const bool dump = std::getenv("DUMP") != nullptr;
  double worst[5] = {0, 0, 0, 0, 0};
  int off[5] = {0, 0, 0, 0, 0};
  for (int it = 0; it < pairs; ++it) {
    Vec3 a[3], b[3];
    for (auto& v : a) v = r.point();
    make_pair(r, it, a, b);
    const double scale = r.log_between(-3, 3);
    for (int i = 0; i < 3; ++i) a[i] *= scale, b[i] *= scale;
    const ClosestPoints got = caliber::geometry::closest_points_triangles(a, b);
    const double truth = caliber::geometry::oracle::triangles_distance(a, b);
    double largest = 0.0;
    for (int i = 0; i < 3; ++i) largest = std::max({largest, a[i].cwiseAbs().maxCoeff(), b[i].cwiseAbs().maxCoeff()});
    const double error = (got.distance - truth) / (0x1p-52 * largest);
    const int k = it % 5;
    if (dump) std::printf("D %d %.17g %.17g %d\n", it, got.distance, 0x1p-52 * largest, k);
    worst[k] = std::max(worst[k], std::abs(error));
    off[k] += std::abs(error) > 256.0;
  }
  for (int k = 0; k < 5; ++k)
    std::printf("kind %d: %d pairs, worst %.3g units, off by more than 256: %d\n", k, pairs / 5, worst[k], off[k]);
}
