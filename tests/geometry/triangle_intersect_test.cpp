#include "geometry/triangle_intersect.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "geometry/predicates.h"
#include "geometry/triangle_distance.h"

namespace caliber::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

bool tri_tri(const Vec3 a[3], const Vec3 b[3]) { return triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2]); }

/// The answer must not depend on argument order or vertex order: checks all 2 x 6 x 6 orders.
bool consistent_answer(const Vec3 a[3], const Vec3 b[3]) {
  const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  const bool want = tri_tri(a, b);
  for (const auto& pa : perms) {
    for (const auto& pb : perms) {
      const Vec3 ra[3] = {a[pa[0]], a[pa[1]], a[pa[2]]};
      const Vec3 rb[3] = {b[pb[0]], b[pb[1]], b[pb[2]]};
      EXPECT_EQ(tri_tri(ra, rb), want);
      EXPECT_EQ(tri_tri(rb, ra), want);
    }
  }
  return want;
}

TEST(TriangleIntersect, SeparatedByPlane) {
  const Vec3 a[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Vec3 b[3] = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  EXPECT_FALSE(consistent_answer(a, b));
}

TEST(TriangleIntersect, Piercing) {
  const Vec3 a[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Vec3 b[3] = {{1, 1, -1}, {1, 1, 1}, {2, 0.5, 1}};
  EXPECT_TRUE(consistent_answer(a, b));
}

TEST(TriangleIntersect, CrossingWithoutVertexInside) {
  // Two triangles that cross like links of a chain: each pierces the other through an edge.
  const Vec3 a[3] = {{-2, 0, 0}, {2, 0, 0}, {0, 0, 3}};
  const Vec3 b[3] = {{0, -2, 1}, {0, 2, 1}, {0, 0, -2}};
  EXPECT_TRUE(consistent_answer(a, b));
}

TEST(TriangleIntersect, TouchingAtOneVertex) {
  const Vec3 a[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Vec3 b[3] = {{0, 0, 0}, {-1, 0, 1}, {0, -1, 1}};
  EXPECT_TRUE(consistent_answer(a, b));
}

TEST(TriangleIntersect, VertexTouchingFaceInterior) {
  const Vec3 a[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Vec3 b[3] = {{1, 1, 0}, {1, 2, 3}, {2, 1, 3}};
  EXPECT_TRUE(consistent_answer(a, b));
  const Vec3 lifted[3] = {{1, 1, 1e-300}, {1, 2, 3}, {2, 1, 3}};  // a hair above: no contact
  EXPECT_FALSE(consistent_answer(a, lifted));
}

TEST(TriangleIntersect, EdgeOnEdge) {
  const Vec3 a[3] = {{0, 0, 0}, {2, 0, 0}, {1, 1, 0}};
  const Vec3 b[3] = {{1, 0, 0}, {3, 0, 0}, {2, 0, 1}};  // shares a stretch of the x axis, other plane
  EXPECT_TRUE(consistent_answer(a, b));
  const Vec3 c[3] = {{2.5, 0, 0}, {3, 0, 0}, {2.7, 0, 1}};  // same line, disjoint stretch
  EXPECT_FALSE(consistent_answer(a, c));
}

TEST(TriangleIntersect, CoplanarOverlapping) {
  const Vec3 a[3] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  const Vec3 b[3] = {{1, 1, 0}, {3, 1, 0}, {1, 3, 0}};  // touches a's hypotenuse at (1, 1)
  EXPECT_TRUE(consistent_answer(a, b));
  const Vec3 c[3] = {{0.5, 0.5, 0}, {1.5, 0.5, 0}, {0.5, 1.5, 0}};  // overlaps
  EXPECT_TRUE(consistent_answer(a, c));
  const Vec3 inside[3] = {{0.1, 0.1, 0}, {0.2, 0.1, 0}, {0.1, 0.2, 0}};  // held whole, no edge crossing
  EXPECT_TRUE(consistent_answer(a, inside));
}

TEST(TriangleIntersect, CoplanarDisjoint) {
  const Vec3 a[3] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  const Vec3 b[3] = {{1.01, 1.01, 0}, {3, 1, 0}, {1, 3, 0}};
  EXPECT_FALSE(consistent_answer(a, b));
}

TEST(TriangleIntersect, CoplanarInTiltedPlane) {
  // Plane x + y + z = 1 with coordinates that are exact binary fractions.
  const Vec3 a[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const Vec3 b[3] = {{0.5, 0.5, 0}, {0.5, 0, 0.5}, {0.75, 0.125, 0.125}};
  EXPECT_TRUE(consistent_answer(a, b));
  const Vec3 c[3] = {{1.5, -0.25, -0.25}, {1.25, 0, -0.25}, {1.25, -0.25, 0}};  // same plane, outside
  EXPECT_FALSE(consistent_answer(a, c));
}

TEST(TriangleIntersect, DegenerateSegmentTriangle) {
  const Vec3 a[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Vec3 seg[3] = {{1, 1, -1}, {1, 1, 1}, {1, 1, 0.5}};  // collinear: a segment through a's face
  EXPECT_TRUE(consistent_answer(a, seg));
  const Vec3 seg_off[3] = {{5, 5, -1}, {5, 5, 1}, {5, 5, 0}};
  EXPECT_FALSE(consistent_answer(a, seg_off));
  const Vec3 seg_in_plane[3] = {{-1, 1, 0}, {1, 1, 0}, {0, 1, 0}};  // crosses a's edge in a's plane
  EXPECT_TRUE(consistent_answer(a, seg_in_plane));
  const Vec3 skew[3] = {{-1, -1, 1}, {1, 1, 1}, {0, 0, 1}};
  EXPECT_FALSE(consistent_answer(a, skew));
}

TEST(TriangleIntersect, DegeneratePointTriangle) {
  const Vec3 a[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Vec3 on[3] = {{1, 1, 0}, {1, 1, 0}, {1, 1, 0}};
  const Vec3 off[3] = {{1, 1, 1e-9}, {1, 1, 1e-9}, {1, 1, 1e-9}};
  EXPECT_TRUE(consistent_answer(a, on));
  EXPECT_FALSE(consistent_answer(a, off));
}

TEST(TriangleIntersect, BothDegenerate) {
  const Vec3 s1[3] = {{0, 0, 0}, {2, 2, 2}, {1, 1, 1}};
  const Vec3 s2[3] = {{0, 2, 0}, {2, 0, 2}, {2, 0, 2}};  // crosses s1 at (1, 1, 1)
  EXPECT_TRUE(consistent_answer(s1, s2));
  const Vec3 s3[3] = {{0, 2, 0.001}, {2, 0, 2}, {2, 0, 2}};  // skew
  EXPECT_FALSE(consistent_answer(s1, s3));
  const Vec3 p1[3] = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  EXPECT_TRUE(consistent_answer(s1, p1));
  const Vec3 p2[3] = {{1, 1, 1.5}, {1, 1, 1.5}, {1, 1, 1.5}};
  EXPECT_FALSE(consistent_answer(s1, p2));
  EXPECT_TRUE(consistent_answer(p1, p1));
}

TEST(TriangleIntersect, IdenticalTriangles) {
  const Vec3 a[3] = {{0.1, 0.2, 0.3}, {1.7, -0.2, 0.9}, {0.4, 1.1, -0.6}};
  EXPECT_TRUE(consistent_answer(a, a));
}

TEST(TriangleIntersect, RandomAgreesWithDistanceWherePlain) {
  // Away from touching configurations, "intersect" and "distance is 0" must agree.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int yes = 0, no = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    Vec3 a[3], b[3];
    for (auto& v : a) v = Vec3(u(rng), u(rng), u(rng));
    for (auto& v : b) v = Vec3(u(rng), u(rng), u(rng)) + Vec3(0.5, 0, 0);
    const bool hit = tri_tri(a, b);
    const double d = closest_points_triangles(a, b).distance;
    if (hit) {
      ++yes;
      EXPECT_LT(d, 1e-9) << "iteration " << iter;
    } else {
      ++no;
      EXPECT_GT(d, 0.0) << "iteration " << iter;
    }
    EXPECT_EQ(tri_tri(b, a), hit);
  }
  EXPECT_GT(yes, 1000);
  EXPECT_GT(no, 1000);
}

/// Whether the pair takes the planes-crossing test: every corner strictly off the other's plane, and
/// each plane with corners of the other triangle on both sides.
bool planes_cross(const Vec3 a[3], const Vec3 b[3]) {
  int sa[3], sb[3];
  for (int i = 0; i < 3; ++i) {
    sa[i] = orient3d(b[0].data(), b[1].data(), b[2].data(), a[i].data());
    sb[i] = orient3d(a[0].data(), a[1].data(), a[2].data(), b[i].data());
  }
  for (int i = 0; i < 3; ++i) {
    if (sa[i] == 0 || sb[i] == 0) return false;
  }
  return !(sa[0] == sa[1] && sa[1] == sa[2]) && !(sb[0] == sb[1] && sb[1] == sb[2]);
}

/// triangles_intersect against the edge tests alone, in every argument and corner order.
void expect_as_edge_tests(const Vec3 a[3], const Vec3 b[3], int iter) {
  const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  for (const auto& pa : perms) {
    for (const auto& pb : perms) {
      const Vec3 ra[3] = {a[pa[0]], a[pa[1]], a[pa[2]]};
      const Vec3 rb[3] = {b[pb[0]], b[pb[1]], b[pb[2]]};
      const bool want = detail::triangles_intersect_by_edges(ra[0], ra[1], ra[2], rb[0], rb[1], rb[2]);
      ASSERT_EQ(tri_tri(ra, rb), want) << "iteration " << iter;
      ASSERT_EQ(tri_tri(rb, ra), want) << "iteration " << iter;
    }
  }
}

// Small integer coordinates make exact coincidences common: the two segments on the planes' common
// line touching at an end (an orientation of the two-orientation test exactly 0), corners in the
// other's plane (the edge tests' cases). Every kind must give the edge tests' answer.
TEST(TriangleIntersect, PlanesCrossingTestAgreesWithEdgeTestsOnAGrid) {
  std::mt19937_64 rng(23);
  std::uniform_int_distribution<int> u(-2, 2);
  int crossing_yes = 0, crossing_no = 0, touching = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    Vec3 a[3], b[3];
    for (auto& v : a) v = Vec3(u(rng), u(rng), u(rng));
    for (auto& v : b) v = Vec3(u(rng), u(rng), u(rng));
    expect_as_edge_tests(a, b, iter);
    if (HasFatalFailure()) return;
    if (!planes_cross(a, b)) continue;
    const bool hit = tri_tri(a, b);
    (hit ? crossing_yes : crossing_no) += 1;
    bool coplanar_edges = false;  // an edge of A and an edge of B on one plane: they may touch
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        coplanar_edges |= orient3d(a[i].data(), a[(i + 1) % 3].data(), b[j].data(), b[(j + 1) % 3].data()) == 0;
      }
    }
    touching += hit && coplanar_edges;
  }
  EXPECT_GT(crossing_yes, 1000);
  EXPECT_GT(crossing_no, 1000);
  EXPECT_GT(touching, 200);
}

TEST(TriangleIntersect, PlanesCrossingTestAgreesWithEdgeTestsOnRandomPairs) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int crossing_yes = 0, crossing_no = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    Vec3 a[3], b[3];
    for (auto& v : a) v = Vec3(u(rng), u(rng), u(rng));
    for (auto& v : b) v = Vec3(u(rng), u(rng), u(rng)) * 0.5 + Vec3(0.3, 0, 0);
    expect_as_edge_tests(a, b, iter);
    if (HasFatalFailure()) return;
    if (planes_cross(a, b)) (tri_tri(a, b) ? crossing_yes : crossing_no) += 1;
  }
  EXPECT_GT(crossing_yes, 1000);
  EXPECT_GT(crossing_no, 1000);
}

/// Whether closed 2-D triangles (integer corners, possibly degenerate) meet, by separating axes:
/// their Minkowski difference, a convex polygon, segment or point, misses the origin exactly where
/// one of the axes separates them, the edges' directions and normals and the two coordinate axes.
bool triangles_meet_by_axes(const std::int64_t a[3][2], const std::int64_t b[3][2]) {
  std::int64_t axes[14][2] = {{1, 0}, {0, 1}};
  int count = 2;
  for (const auto* t : {a, b}) {
    for (int i = 0; i < 3; ++i) {
      const std::int64_t dx = t[(i + 1) % 3][0] - t[i][0], dy = t[(i + 1) % 3][1] - t[i][1];
      axes[count][0] = dx, axes[count++][1] = dy;
      axes[count][0] = -dy, axes[count++][1] = dx;
    }
  }
  for (int k = 0; k < count; ++k) {
    std::int64_t lo[2] = {INT64_MAX, INT64_MAX}, hi[2] = {INT64_MIN, INT64_MIN};
    for (int side = 0; side < 2; ++side) {
      for (int i = 0; i < 3; ++i) {
        const auto* p = side == 0 ? a[i] : b[i];
        const std::int64_t x = axes[k][0] * p[0] + axes[k][1] * p[1];
        lo[side] = std::min(lo[side], x);
        hi[side] = std::max(hi[side], x);
      }
    }
    if (hi[0] < lo[1] || hi[1] < lo[0]) return false;
  }
  return true;
}

/// Coplanar pairs: triangles of a small integer grid (shared corners, touching edges, degenerate
/// ones) placed in three planes (z = 2; x + y + z = 0; x = y, where one axis projection flattens
/// both onto a line): every answer, in every order, is that of the separating axes in the plane.
TEST(TriangleIntersect, CoplanarPairsMeetAsTheirSeparatingAxesSay) {
  std::mt19937_64 rng(31);
  std::uniform_int_distribution<int> u(-3, 3);
  int yes = 0, no = 0;
  for (int iter = 0; iter < 4000; ++iter) {
    std::int64_t a[3][2], b[3][2];
    for (auto& p : a) p[0] = u(rng), p[1] = u(rng);
    for (auto& p : b) p[0] = u(rng), p[1] = u(rng);
    const bool want = triangles_meet_by_axes(a, b);
    const auto place = [](const std::int64_t p[2], int plane) {
      const double x = static_cast<double>(p[0]), y = static_cast<double>(p[1]);
      return plane == 0 ? Vec3(x, y, 2.0) : plane == 1 ? Vec3(x, y, -x - y) : Vec3(x, x, y);
    };
    for (int plane = 0; plane < 3; ++plane) {
      const Vec3 ta[3] = {place(a[0], plane), place(a[1], plane), place(a[2], plane)};
      const Vec3 tb[3] = {place(b[0], plane), place(b[1], plane), place(b[2], plane)};
      ASSERT_EQ(consistent_answer(ta, tb), want) << "iteration " << iter << ", plane " << plane;
    }
    (want ? yes : no) += 1;
  }
  EXPECT_GT(yes, 1000);
  EXPECT_GT(no, 1000);
}

// certainly_separated may skip triangles_intersect only where it would say false: it must never
// certify triangles that meet, for the closest points' direction or any other.
TEST(CertainlySeparated, NeverForTrianglesThatMeet) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int met = 0, certified = 0, apart = 0;
  for (int iter = 0; iter < 40000; ++iter) {
    Vec3 a[3], b[3];
    // Offsets that make meeting, grazing and apart pairs all common; scales from 1e-3 to 1e3.
    const double scale = std::pow(10.0, (iter % 7) - 3);
    const Vec3 shift = Vec3(0.5 + 0.6 * u(rng), 0.1 * u(rng), 0.1 * u(rng)) * scale;
    for (auto& v : a) v = Vec3(u(rng), u(rng), u(rng)) * scale;
    for (auto& v : b) v = Vec3(u(rng), u(rng), u(rng)) * scale + shift;
    const ClosestPoints c = closest_points_triangles(a, b);
    const bool meet = tri_tri(a, b);
    const bool sep = certainly_separated(c.on_b - c.on_a, a, b);
    met += meet;
    apart += !meet;
    certified += sep;
    if (meet) {
      ASSERT_FALSE(sep) << "iteration " << iter;
      ASSERT_FALSE(certainly_separated(Vec3(u(rng), u(rng), u(rng)), a, b)) << "iteration " << iter;
    }
  }
  EXPECT_GT(met, 5000);
  // And it does its job: most pairs that are apart get the certificate.
  EXPECT_GT(certified, apart * 9 / 10);
}

TEST(CertainlySeparated, NeverForTouchingTriangles) {
  // Sharing exactly one vertex, one on each side of a plane through it: they touch at that point
  // only, and n . v is the same number on both sides, so no allowance below zero may pass.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  for (int iter = 0; iter < 2000; ++iter) {
    const Vec3 shared(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    const Vec3 a[3] = {shared, shared + Vec3(-u(rng), u(rng) - 0.5, u(rng) - 0.5),
                       shared + Vec3(-u(rng), u(rng) - 0.5, u(rng) - 0.5)};
    const Vec3 b[3] = {shared, shared + Vec3(u(rng), u(rng) - 0.5, u(rng) - 0.5),
                       shared + Vec3(u(rng), u(rng) - 0.5, u(rng) - 0.5)};
    ASSERT_TRUE(tri_tri(a, b));
    const ClosestPoints c = closest_points_triangles(a, b);
    EXPECT_FALSE(certainly_separated(c.on_b - c.on_a, a, b)) << "iteration " << iter;
    EXPECT_FALSE(certainly_separated(Vec3(1, 0, 0), a, b)) << "iteration " << iter;
  }
  // A vertex of b on a's face, b above it.
  const Vec3 a[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Vec3 b[3] = {{1, 1, 0}, {1, 1, 2}, {2, 1, 2}};
  EXPECT_FALSE(certainly_separated(Vec3(0, 0, 1), a, b));
  const Vec3 lifted[3] = {{1, 1, 1e-6}, {1, 1, 2}, {2, 1, 2}};
  EXPECT_TRUE(certainly_separated(Vec3(0, 0, 1), a, lifted));
}

TEST(CertainlySeparated, NothingFromNaNOrInfinity) {
  const Vec3 a[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Vec3 b[3] = {{0, 0, 5}, {1, 0, 5}, {0, 1, 5}};
  EXPECT_TRUE(certainly_separated(Vec3(0, 0, 1), a, b));
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(certainly_separated(Vec3(0, 0, nan), a, b));
  EXPECT_FALSE(certainly_separated(Vec3(nan, 0, 1), a, b));
  EXPECT_FALSE(certainly_separated(Vec3(0, 0, inf), a, b));
  // Products that underflow: no certificate from rounding noise.
  EXPECT_FALSE(certainly_separated(Vec3(0, 0, 1e-320), a, a));
}

}  // namespace
}  // namespace caliber::geometry
