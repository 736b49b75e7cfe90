// The closest-points kernel against the oracle of tests/geometry beside a cap: B is a long thin
// triangle whose third corner lies 1e-13 to 1e-4 of its length off the middle of its long edge, and
// A's first corner hovers 1e-12 to 0.1 above (or below) B's face, projecting inside it; one pair in
// three swapped. The distance is then the corner's height, which only the face pair gives; the
// edge pairs are as far as the corner is from B's edges in B's plane. Prints the largest error in
// units of 2^-52 of the pair's largest coordinate, the most below the oracle, and how many pairs
// are off by more than 256 units.
//
//   g++ -O2 -std=c++20 -Isrc -Iinclude -Itests -I/usr/include/eigen3 cap_pairs.cpp \
//       tests/geometry/triangle_distance_oracle.cpp build/libcaliber.a -ltbb -o cap_pairs

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include <Eigen/Geometry>

#include "geometry/triangle_distance.h"
#include "geometry/triangle_distance_oracle.h"

int main() {
  using Vec3 = Eigen::Vector3d;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto point = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  const auto log_between = [&](double lo, double hi) {
    return std::pow(10.0, std::uniform_real_distribution<double>(lo, hi)(rng));
  };
  double worst = 0, below = 0;
  int off = 0;
  for (int it = 0; it < 200000; ++it) {
    const Vec3 p = point(), q = point(), d = q - p, side = d.cross(point()).normalized(), up = d.cross(side).normalized();
    const double height = log_between(-13, -4) * d.norm(), along = 0.5 + 0.45 * u(rng);
    Vec3 b[3] = {p, q, p + 0.5 * d + height * side};
    const double h = log_between(-12, -1) * (it % 2 ? 1 : -1);
    const Vec3 x = p + along * d + height * 0.3 * std::abs(u(rng)) * side + h * up;
    const double away = h > 0 ? 1 : -1;
    Vec3 a[3] = {x, x + away * (up + 0.3 * point()), x + away * (up + 0.3 * point())};
    if (it % 3 == 0) std::swap(a, b);
    const double got = caliber::geometry::closest_points_triangles(a, b).distance;
    const double truth = caliber::geometry::oracle::triangles_distance(a, b);
    double largest = 0;
    for (int i = 0; i < 3; ++i) largest = std::max({largest, a[i].cwiseAbs().maxCoeff(), b[i].cwiseAbs().maxCoeff()});
    const double error = (got - truth) / (0x1p-52 * largest);
    worst = std::max(worst, std::abs(error));
    below = std::min(below, error);
    off += std::abs(error) > 256;
  }
  std::printf("caps: 200000 pairs, worst %.3g units, most below %.3g, off by more than 256: %d\n", worst, below, off);
}
