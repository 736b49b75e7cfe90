// triangles_intersect_batch against triangles_intersect, pair by pair, in each of its forms.

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "geometry/triangle_distance.h"
#include "geometry/triangle_intersect.h"

namespace caliber::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

struct Pair {
  Vec3 a[3], b[3];
};

bool scalar(const Pair& p) { return triangles_intersect(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2]); }

/// The batch forms this build and CPU have: the public one (the best), the pair-by-pair one, and
/// the AVX-512 and AVX2 ones where there are.
std::vector<std::pair<std::string, std::function<unsigned(TriangleBatch&)>>> forms() {
  std::vector<std::pair<std::string, std::function<unsigned(TriangleBatch&)>>> out;
  out.emplace_back("public", [](TriangleBatch& b) { return triangles_intersect_batch(b); });
  out.emplace_back("by pair", [](TriangleBatch& b) {
    b.pad();
    return detail::triangles_intersect_batch_by_pair(b);
  });
  if (const detail::IntersectBatch avx512 = detail::triangles_intersect_batch_avx512_if_supported()) {
    out.emplace_back("avx512", [avx512](TriangleBatch& b) {
      b.pad();
      return avx512(b);
    });
  }
  if (const detail::IntersectBatch avx2 = detail::triangles_intersect_batch_avx2_if_supported()) {
    out.emplace_back("avx2", [avx2](TriangleBatch& b) {
      b.pad();
      return avx2(b);
    });
  }
  return out;
}

/// Every form's bits equal triangles_intersect's on `pairs`, in batches of 1 to 8 pairs (bits past
/// a batch's size clear). Returns how many pairs meet.
int expect_as_scalar(const std::vector<Pair>& pairs, const std::string& what) {
  int meet = 0;
  for (const Pair& p : pairs) meet += scalar(p);
  for (const auto& [name, form] : forms()) {
    std::size_t i = 0;
    for (int size = 1; i < pairs.size(); size = size % TriangleBatch::kLanes + 1) {
      TriangleBatch batch;
      unsigned want = 0;
      for (int l = 0; l < size && i < pairs.size(); ++l, ++i) {
        batch.add(pairs[i].a, pairs[i].b);
        want |= static_cast<unsigned>(scalar(pairs[i])) << l;
      }
      const int n = batch.size;
      const unsigned got = form(batch);
      EXPECT_EQ(got, want) << what << ", form " << name << ", the batch ending at pair " << i << " (" << n << " pairs)";
      if (got != want) return meet;
    }
  }
  return meet;
}

// Small integer coordinates: corners in the other's plane, coplanar pairs, segments touching at an
// end, degenerate triangles (repeated or collinear corners), all exact.
TEST(TriangleIntersectBatch, AgreesOnAGrid) {
  std::mt19937_64 rng(31);
  std::uniform_int_distribution<int> u(-2, 2);
  std::vector<Pair> pairs(40000);
  for (Pair& p : pairs) {
    for (auto& v : p.a) v = Vec3(u(rng), u(rng), u(rng));
    for (auto& v : p.b) v = Vec3(u(rng), u(rng), u(rng));
  }
  const int meet = expect_as_scalar(pairs, "grid");
  EXPECT_GT(meet, 5000);
  EXPECT_LT(meet, 35000);
}

// Random reals, and pairs a rounding away from touching: B shares a corner or an edge of A, or
// has a corner on A's plane moved by an ulp or two.
TEST(TriangleIntersectBatch, AgreesOnRandomAndNearlyTouchingPairs) {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Pair> pairs;
  for (int iter = 0; iter < 30000; ++iter) {
    Pair p;
    for (auto& v : p.a) v = Vec3(u(rng), u(rng), u(rng));
    for (auto& v : p.b) v = Vec3(u(rng), u(rng), u(rng)) * 0.5 + Vec3(0.3, 0, 0);
    switch (iter % 4) {
      case 1:  // a shared corner
        p.b[0] = p.a[iter % 3];
        break;
      case 2:  // a shared edge
        p.b[0] = p.a[0], p.b[1] = p.a[1];
        break;
      case 3: {  // a corner on A's plane, then an ulp or two off it
        const double s = 0.5 * (u(rng) + 1.0), t = 0.5 * (1.0 - s) * (u(rng) + 1.0);
        p.b[0] = p.a[0] + s * (p.a[1] - p.a[0]) + t * (p.a[2] - p.a[0]);
        for (int k = 0; k < iter % 3; ++k) p.b[0].x() = std::nextafter(p.b[0].x(), 2.0);
        break;
      }
      default:
        break;
    }
    pairs.push_back(p);
  }
  const int meet = expect_as_scalar(pairs, "random");
  EXPECT_GT(meet, 5000);
  EXPECT_LT(meet, 28000);
}

// NaN, infinite and huge coordinates: whatever triangles_intersect says, the batch says.
TEST(TriangleIntersectBatch, AgreesOnNaNInfinityAndHugeCoordinates) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<Pair> pairs;
  for (const double odd : {nan, inf, -inf, 1e300, 1e-300}) {
    for (int k = 0; k < 6; ++k) {
      Pair p{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(0.3, 0.1, 1)}};
      (k < 3 ? p.a[k] : p.b[k - 3]).y() = odd;
      pairs.push_back(p);
    }
  }
  expect_as_scalar(pairs, "odd coordinates");
}

}  // namespace
}  // namespace caliber::geometry
