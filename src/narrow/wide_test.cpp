// The wide node test's lanes and its scalar form (wide_test.h); the AVX2 form in
// wide_test_avx2.cpp makes each lane's operations in this order, its multiply-adds fused as
// std::fma fuses them here.
//
// Why the float stage's slack holds: every value it compares is a short sum of products of stored
// floats (bounds, axes: exact), pose entries (|M| <= 1, rounded once to float) and coordinates of
// at most a few times the scale (the λ test's sums reach about 5.5 scales: the offset between the
// origins, the slot's center along the rest of the axis, λ times the slot's slab), each product
// and sum rounded once: a slot's center and half-extent from its bounds within 1 unit roundoff of
// the scale, a projection on a staying axis within about 12, the slabs' positions and reaches
// within about 20 (the staying slab's offset, computed in double, within 1). The slack is 512 unit
// roundoffs of the scale (2^-15). A staying leaf's corners, decoded from its node (leaf_corners),
// stand within their stated error (added to the comparison) plus its box's rounding, a few unit
// roundoffs of the scale, of the true ones.

#include "narrow/wide_test.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace caliber::narrow::detail {

namespace {
/// The float stage's slack, as a share of the scale.
constexpr double kShare = 0x1p-15;
/// Stage 1's growth before rounding to float: a share of the magnitude, and a least growth of a
/// share of the scale (above float's smallest step, 2^-149, wherever that is above it).
constexpr double kRoundShare = 0x1p-22, kFloorShare = 0x1p-32, kLeastFloor = 0x1p-149;
/// The least cosine between two slab axes for the staying slab's projection to follow the slot's
/// slab (lambda).
constexpr float kParallel = 0.5f;

void fill_side(double m[3][3], double abs_m[3][3], const double t[3], WideSide& s) {
  // Four float lanes at a time (GCC's vector extension: one store each where the target has SSE).
  using F4 = float __attribute__((vector_size(16)));
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      s.col[j][i] = m[i][j];
      s.abs_col[j][i] = abs_m[i][j];
      const float x = static_cast<float>(m[j][i]), y = std::abs(x);
      const F4 lanes = {x, x, x, x}, magnitudes = {y, y, y, y};
      for (int l = 0; l < 8; l += 4) {
        std::memcpy(&s.m[j][i][l], &lanes, sizeof lanes);
        std::memcpy(&s.abs_m[j][i][l], &magnitudes, sizeof magnitudes);
      }
    }
    s.col[j][3] = s.abs_col[j][3] = 0.0;
  }
  for (int i = 0; i < 3; ++i) {
    s.t[i] = t[i];
    s.mt_t[i] = (m[0][i] * t[0] + m[1][i] * t[1]) + m[2][i] * t[2];
  }
  s.t[3] = s.mt_t[3] = 0.0;
}

}  // namespace

void make_wide_lanes(const NodeTestFrame& f, double scale, const ModelData& a, const ModelData& b, WideLanes& l) {
  l.staying_wide[0] = b.wide.data();
  l.staying_wide[1] = a.wide.data();
  double m[3][3], abs_m[3][3], t[3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m[i][j] = f.rot[i][j];
      abs_m[i][j] = f.abs_rot[i][j];
    }
  }
  fill_side(m, abs_m, f.trans, l.side[0]);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m[i][j] = f.rot[j][i];
      abs_m[i][j] = f.abs_rot[j][i];
    }
    t[i] = -((f.rot[0][i] * f.trans[0] + f.rot[1][i] * f.trans[1]) + f.rot[2][i] * f.trans[2]);
  }
  fill_side(m, abs_m, t, l.side[1]);
  l.reach = f.reach;
  l.round_floor = std::max(kFloorShare * scale, kLeastFloor);
  // The unit: 2^-k for the scale's exponent k, within float's range (else no float stage).
  const int k = scale > 0.0 && std::isfinite(scale) ? std::ilogb(scale) : 0;
  l.floats = scale > 0.0 && std::isfinite(scale) && k >= -120 && k <= 120;
  l.unit = l.floats ? std::ldexp(1.0, -k) : 1.0;  // (unused without the float stage; in float's range)
  l.unit_f = static_cast<float>(l.unit);
  l.half_unit = static_cast<float>(0.5 * l.unit);
  const double slack = kShare * scale * l.unit;
  l.reach_f = static_cast<float>(f.reach * l.unit + slack);
  l.slab_f = static_cast<float>(f.slab_reach * l.unit + slack);
}

namespace {

/// Stage 1 on slot k: the slot's float box against the staying box's float bounds.
bool boxes_overlap(const WideNode& w, int k, const float lo[3], const float hi[3]) {
  bool pass = true;
  for (int i = 0; i < 3; ++i) pass = pass && w.low(i, k) <= hi[i] && w.high(i, k) >= lo[i];
  return pass;
}

/// Stage 2 on slot k (see wide_test.h), in units: the staying node as st.
bool floats_pass(const WideLanes& l, const WideSide& s, const WideNode& w, int k, const StayingFloats& st) {
  float cc[3], hh[3];
  for (int i = 0; i < 3; ++i) {
    cc[i] = (w.low(i, k) + w.high(i, k)) * l.half_unit;
    hh[i] = (w.high(i, k) - w.low(i, k)) * l.half_unit;
  }
  bool pass = true;
  for (int i = 0; i < 3; ++i) {  // the staying node's axes
    const float p = std::fmaf(s.m[2][i][0], cc[2], std::fmaf(s.m[1][i][0], cc[1], std::fmaf(s.m[0][i][0], cc[0], 0.0f)));
    const float r =
        std::fmaf(s.abs_m[2][i][0], hh[2], std::fmaf(s.abs_m[1][i][0], hh[1], std::fmaf(s.abs_m[0][i][0], hh[0], st.ho[i])));
    pass = pass && std::abs(p - st.co[i]) <= r;
  }
  const float ax[3] = {w.slab_axis(0, k), w.slab_axis(1, k), w.slab_axis(2, k)};
  const float slot_lo = w.slab_lo[k] * l.unit_f, slot_hi = w.slab_hi[k] * l.unit_f;
  {  // the staying node's slab: lambda (the slot's slab) + the rest (its box) along the axis
    const float dot = std::fmaf(ax[2], st.nf[2], std::fmaf(ax[1], st.nf[1], ax[0] * st.nf[0]));
    const float lambda = std::abs(dot) >= kParallel ? dot : 0.0f;
    float rest[3];
    for (int i = 0; i < 3; ++i) rest[i] = std::fmaf(-lambda, ax[i], st.nf[i]);
    const float at = std::fmaf(rest[2], cc[2], std::fmaf(rest[1], cc[1], std::fmaf(rest[0], cc[0], st.off)));
    const float r = std::fmaf(std::abs(rest[2]), hh[2], std::fmaf(std::abs(rest[1]), hh[1], std::abs(rest[0]) * hh[0]));
    const float e0 = lambda * slot_lo, e1 = lambda * slot_hi;
    const float low = e0 < e1 ? e0 : e1, high = e0 > e1 ? e0 : e1;
    pass = pass && (at - r) + low <= st.slab_hi && (at + r) + high >= st.slab_lo;
  }
  const float slot_hi_reach = std::fmaf(w.slab_hi[k], l.unit_f, l.slab_f);
  const float slot_lo_reach = std::fmaf(w.slab_lo[k], l.unit_f, -l.slab_f);
  if (st.triangle != 0) {  // the slot's slab against the staying triangle's corners
    float low = 0.0f, high = 0.0f;
    for (int j = 0; j < 3; ++j) {
      const float at = std::fmaf(ax[2], st.corner[j][2], std::fmaf(ax[1], st.corner[j][1], ax[0] * st.corner[j][0]));
      low = j == 0 ? at : std::min(low, at);
      high = j == 0 ? at : std::max(high, at);
    }
    return pass && low - st.corner_error <= slot_hi_reach && high + st.corner_error >= slot_lo_reach;
  }
  {  // the slot's slab against the staying box
    const float at = std::fmaf(ax[2], st.cf[2], std::fmaf(ax[1], st.cf[1], ax[0] * st.cf[0]));
    float on[3];
    for (int j = 0; j < 3; ++j) on[j] = std::fmaf(ax[2], s.m[2][j][0], std::fmaf(ax[1], s.m[1][j][0], ax[0] * s.m[0][j][0]));
    const float r = std::fmaf(std::abs(on[2]), st.sh[2], std::fmaf(std::abs(on[1]), st.sh[1], std::abs(on[0]) * st.sh[0]));
    pass = pass && at - r <= slot_hi_reach && at + r >= slot_lo_reach;
  }
  return pass;
}

}  // namespace

unsigned wide_test_scalar(const NodeTestFrame& f, const WideLanes& l, bool a_descends, std::uint32_t stay, const BvhNode& sn,
                          const WideNode& w, StayingCache* cache) {
  const WideSide& s = side_of(l, a_descends);
  bool held;
  StayingCache::Entry spare;
  StayingCache::Entry& kept = staying_entry(cache, spare, stay, a_descends, held);
  if (!held) {
    const StayingBox box = staying_box(sn);
    const double *cd = box.c, *hd = box.h;
    double c[3];
    float lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
      c[i] = std::fma(s.col[2][i], cd[2], std::fma(s.col[1][i], cd[1], std::fma(s.col[0][i], cd[0], s.t[i])));
      const double e =
          std::fma(s.abs_col[2][i], hd[2], std::fma(s.abs_col[1][i], hd[1], std::fma(s.abs_col[0][i], hd[0], l.reach)));
      const double g = std::fma(std::abs(c[i]) + e, kRoundShare, e + l.round_floor);
      lo[i] = static_cast<float>(c[i] - g);
      hi[i] = static_cast<float>(c[i] + g);
    }
    StayingCache::fill(kept, c, lo, hi);
  }
  unsigned pass = 0;
  const int count = w.count();
  for (int k = 0; k < count; ++k) {
    if (boxes_overlap(w, k, kept.lo, kept.hi)) pass |= 1u << k;
  }
  if (pass == 0 || !l.floats) return pass;
  make_staying_floats(f, l, a_descends, stay, sn, kept);
  for (int k = 0; k < WideNode::kSlots; ++k) {
    if ((pass >> k & 1u) != 0 && !floats_pass(l, s, w, k, kept.floats)) pass &= ~(1u << k);
  }
  return pass;
}

void slot_order_keys_portable(const StayingCache::Entry& kept, const WideNode& w, float keys[WideNode::kSlots]) {
  for (int k = 0; k < WideNode::kSlots; ++k) {
    float offset = 0.0f, extent = 0.0f;
    for (int i = 0; i < 3; ++i) {
      // From the grid's origin: the slot's bounds exactly.
      const float lo = static_cast<float>(w.lo[i][k]) * w.step(), hi = static_cast<float>(w.hi[i][k]) * w.step();
      offset += std::abs((lo + hi) - ((kept.lo[i] - w.origin[i]) + (kept.hi[i] - w.origin[i])));
      extent += (hi - lo) + (kept.hi[i] - kept.lo[i]);
    }
    keys[k] = offset / (extent + std::numeric_limits<float>::min());
  }
}

}  // namespace caliber::narrow::detail
