#pragma once
/// \file
/// The node test's disks (PairContext::node_test_2x2_lane): each node's sphere cut by its own
/// slab, tested against the other node's slab. Where two surfaces are nearly parallel, a node's
/// disk is nearly as thin along the other's slab axis as its own slab, whatever the tilt of its
/// box: the case the slab-against-box test misses (two tilted, nearly parallel surfaces;
/// tests/narrow/slab_test.cpp), and one that random overlaps of curved meshes meet often.

#include "narrow/prepared.h"

namespace caliber::narrow {

/// One disk against one slab: whether the disk lies beyond the slab lo <= n . x <= hi widened by
/// `slab_reach`. The disk: center at `at` along n, its own slab [disk_lo, disk_hi] about its center
/// (along its axis m), `along` = n . m, radius r, len2 = |m|^2, cross2 = |n x m|^2. Beyond when the
/// gap g past the disk's span along n is positive with g^2 |m|^2 > r^2 |n x m|^2; everything is
/// multiplied by |m|^2 (no division). The minimum and maximum as AVX2's minpd and maxpd take them.
[[nodiscard]] inline bool disk_beyond_slab(double at, double disk_lo, double disk_hi, double along, double r, double len2,
                                           double cross2, double lo, double hi, double slab_reach) {
  const double s0 = disk_lo * along, s1 = disk_hi * along;
  const double at2 = at * len2;
  const double low = at2 + (s0 < s1 ? s0 : s1), high = at2 + (s0 > s1 ? s0 : s1);
  const double rim2 = r * r * cross2 * len2;
  const double above = low - (hi + slab_reach) * len2, below = (lo - slab_reach) * len2 - high;
  return (above > 0.0 && above * above > rim2) || (below > 0.0 && below * below > rim2);
}

/// Whether either node's disk lies beyond the other node's slab by more than the reach. A node's
/// triangles lie within its sphere (center c, radius r) and its slab (lo <= m . x <= hi, m the
/// stored axis), so within the disk of points c + s u + w, u = m / |m|, s = (m . x - m . c) / |m|
/// with m . x in [lo, hi], w perpendicular to u and |w| <= r. Along the other slab's axis n, such
/// a point lies at n . c + s (n . u) + n . w, where s (n . u) = (m . x - m . c) (n . m) / |m|^2 and
/// |n . w| <= r |n x u| = r |n x m| / |m|. Both tests are in A's frame (B's slab there:
/// (R m_b) . (x - T) in [lo, hi]). A node without a slab (axis 0) refuses nothing: its terms and
/// the other's along it are all 0. The rounding of every term (a few ulps of quantities at most
/// the extents) is far below the reach's safety margin, as for the other bounds.
[[nodiscard]] inline bool disks_beyond_slabs(const SideA& a, const SideB& b, double slab_reach) {
  const double* m = a.slab_axis;
  const double* n = b.axis_in_a;
  const double along = m[0] * n[0] + m[1] * n[1] + m[2] * n[2];
  const double x = m[1] * n[2] - m[2] * n[1], y = m[2] * n[0] - m[0] * n[2], z = m[0] * n[1] - m[1] * n[0];
  const double cross2 = x * x + y * y + z * z;
  const double b_at = m[0] * b.center[0] + m[1] * b.center[1] + m[2] * b.center[2];
  const double a_at = n[0] * a.center_from_b[0] + n[1] * a.center_from_b[1] + n[2] * a.center_from_b[2];
  return disk_beyond_slab(b_at, b.disk_lo, b.disk_hi, along, b.radius, b.axis_len2, cross2, a.slab_lo, a.slab_hi, slab_reach) ||
         disk_beyond_slab(a_at, a.disk_lo, a.disk_hi, along, a.radius, a.axis_len2, cross2, b.slab_lo, b.slab_hi, slab_reach);
}

}  // namespace caliber::narrow
