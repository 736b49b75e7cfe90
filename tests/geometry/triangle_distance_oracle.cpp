#include "triangle_distance_oracle.h"

#include <algorithm>
#include <cmath>

#include "geometry/triangle_intersect.h"

namespace caliber::geometry::oracle {
namespace {

#if defined(__SIZEOF_FLOAT128__)
using Real = __float128;
const Real kFar = __builtin_inff128();
#else
using Real = long double;
const Real kFar = HUGE_VALL;
#endif

struct V {
  Real x, y, z;
};

V operator-(const V& u, const V& v) { return {u.x - v.x, u.y - v.y, u.z - v.z}; }
V operator+(const V& u, const V& v) { return {u.x + v.x, u.y + v.y, u.z + v.z}; }
V operator*(Real s, const V& v) { return {s * v.x, s * v.y, s * v.z}; }
Real dot(const V& u, const V& v) { return u.x * v.x + u.y * v.y + u.z * v.z; }
V cross(const V& u, const V& v) { return {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x}; }
Real clamp01(Real t) { return t > 0 ? (t < 1 ? t : Real(1)) : Real(0); }

/// Squared distance from x to segment p + s d, s in [0, 1] (a projection: well conditioned).
Real point_segment2(const V& x, const V& p, const V& d) {
  const Real dd = dot(d, d);
  const V y = p + (dd > 0 ? clamp01(dot(x - p, d) / dd) : Real(0)) * d;
  return dot(y - x, y - x);
}

/// Squared distance between segments p1 + s d1 and p2 + t d2: the four ends projected onto the
/// other segment (the minimum on the boundary of [0, 1]^2), and the lines' nearest pair where it
/// lies inside both, s from the parts across d2 (h = d1 - (b / e) d2, u = r - (f / e) d2), which
/// cancels nothing at small angles.
Real segment_segment2(const V& p1, const V& d1, const V& p2, const V& d2) {
  Real best = std::min(
      {point_segment2(p1, p2, d2), point_segment2(p1 + d1, p2, d2), point_segment2(p2, p1, d1), point_segment2(p2 + d2, p1, d1)});
  const Real e = dot(d2, d2);
  if (!(e > 0)) return best;
  const V r = p1 - p2;
  const V h = d1 - (dot(d1, d2) / e) * d2, u = r - (dot(d2, r) / e) * d2;
  const Real hh = dot(h, h);
  if (!(hh > 0)) return best;
  const Real s = -dot(u, h) / hh;
  if (s < 0 || s > 1) return best;
  const V c1 = p1 + s * d1;
  const Real t = dot(c1 - p2, d2) / e;
  if (t < 0 || t > 1) return best;
  const V w = c1 - (p2 + t * d2);
  return std::min(best, dot(w, w));
}

/// Squared distance from x to the plane of triangle t where x projects inside it (barycentric
/// signs), else infinity: the edges cover the rest.
Real point_face2(const V& x, const V t[3]) {
  const V n = cross(t[1] - t[0], t[2] - t[0]);
  const Real nn = dot(n, n);
  if (!(nn > 0)) return kFar;
  const Real h = dot(x - t[0], n);
  const V y = x - (h / nn) * n;  // the projection onto the plane
  for (int i = 0; i < 3; ++i) {
    if (dot(cross(t[(i + 1) % 3] - t[i], y - t[i]), n) < 0) return kFar;
  }
  return h * h / nn;
}

}  // namespace

double triangles_distance(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3]) {
  if (triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2])) return 0.0;
  V ta[3], tb[3];
  for (int i = 0; i < 3; ++i) {
    ta[i] = {Real(a[i].x()), Real(a[i].y()), Real(a[i].z())};
    tb[i] = {Real(b[i].x()), Real(b[i].y()), Real(b[i].z())};
  }
  Real best = kFar;
  for (int i = 0; i < 3; ++i) {
    best = std::min({best, point_face2(ta[i], tb), point_face2(tb[i], ta)});
    for (int j = 0; j < 3; ++j) {
      best = std::min(best, segment_segment2(ta[i], ta[(i + 1) % 3] - ta[i], tb[j], tb[(j + 1) % 3] - tb[j]));
    }
  }
  return double(std::sqrt(static_cast<long double>(best)));
}

}  // namespace caliber::geometry::oracle
