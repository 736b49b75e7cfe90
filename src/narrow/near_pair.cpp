// The distance bound's prepared nodes two at a time: PairContext::near_a and near_b on a node's two
// children, one child per SSE2 lane (x86-64's baseline, so no dispatch). Each lane makes exactly
// the scalar's operations in its order (this file is built with -ffp-contract=off, like the rest;
// SSE2 division and square root are IEEE's, as the scalar's), and where the scalar branches both
// ways are computed and the lane's taken, so both forms give the same bits
// (tests/narrow/near_pair_test.cpp). Measured on an Intel Xeon VM: preparing every node twice
// made the armadillo's distance query 8-23 % slower, so preparation weighs; in lanes (eight
// divisions and two square roots a node, half the instructions) the 25 cases of
// bench_fcl_distance took 0.966-0.995 of the scalar's total time in six alternating runs: the
// preparation is mostly latency on the traversal's path (the bound waits for it), which lanes do
// not shorten.

#include "narrow/pair_context.h"

#if defined(__SSE2__)
#include <emmintrin.h>

namespace caliber::narrow {
namespace {

using D = __m128d;

inline D lanes(double x0, double x1) { return _mm_setr_pd(x0, x1); }
inline double lane(D x, int i) { return i == 0 ? _mm_cvtsd_f64(x) : _mm_cvtsd_f64(_mm_unpackhi_pd(x, x)); }
/// m ? x : y, lane by lane (m all ones or all zeros).
inline D pick(D m, D x, D y) { return _mm_or_pd(_mm_and_pd(m, x), _mm_andnot_pd(m, y)); }

/// Two nodes' Frames (PairContext::own_frame in lanes): lane i is node first + i.
struct Frame2 {
  D axis[3][3], center[3], half[3];
};

Frame2 own_frames(const Model& m, std::uint32_t first) {
  const BvhNode* n = &m.nodes[first];
  const BvhNodeFilter* f = &m.filters[first];
  const BvhNodeLateral* l = &m.laterals[first];
  const D x = lanes(f[0].cone_axis[0], f[1].cone_axis[0]), y = lanes(f[0].cone_axis[1], f[1].cone_axis[1]),
          z = lanes(f[0].cone_axis[2], f[1].cone_axis[2]);
  const D len = _mm_sqrt_pd(x * x + y * y + z * z);
  const D zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
  const D sloped = _mm_cmpgt_pd(len, zero);
  // Both lanes divide (a lane without an axis gets NaN or infinity here, and the box below).
  const D ax = x / len, ay = y / len, az = z / len;
  // lateral_axes_of_unit(ax, ay, az, u, v).
  const D sign = _mm_or_pd(_mm_and_pd(az, _mm_set1_pd(-0.0)), one);
  const D a = -one / (sign + az);
  const D b = ax * ay * a;
  D u[3] = {one + sign * ax * ax * a, sign * b, -sign * ax};
  D v[3] = {b, sign + ay * ay * a, -ay};
  // turn_lateral_axes(l.turn, u, v): a lane whose turn is zero keeps u and v.
  {
    const D c = lanes(l[0].turn[0], l[1].turn[0]), s = lanes(l[0].turn[1], l[1].turn[1]);
    const D r = _mm_sqrt_pd(c * c + s * s);
    const D turned = _mm_cmpgt_pd(r, zero);
    const D cr = c / r, sr = s / r;
    for (int k = 0; k < 3; ++k) {
      const D uk = u[k], vk = v[k];
      u[k] = pick(turned, cr * uk + sr * vk, uk);
      v[k] = pick(turned, cr * vk - sr * uk, vk);
    }
  }
  const D lo[3] = {lanes(f[0].slab_lo, f[1].slab_lo) / len, lanes(l[0].lateral_lo[0], l[1].lateral_lo[0]),
                   lanes(l[0].lateral_lo[1], l[1].lateral_lo[1])};
  const D hi[3] = {lanes(f[0].slab_hi, f[1].slab_hi) / len, lanes(l[0].lateral_hi[0], l[1].lateral_hi[0]),
                   lanes(l[0].lateral_hi[1], l[1].lateral_hi[1])};
  const D half = _mm_set1_pd(0.5), grow = _mm_set1_pd(1.0 + 1e-12);
  D mid[3];
  Frame2 out;
  for (int k = 0; k < 3; ++k) {
    mid[k] = half * (lo[k] + hi[k]);
    out.half[k] = pick(sloped, half * (hi[k] - lo[k]) * grow, lanes(n[0].box_half[k], n[1].box_half[k]));
  }
  const D own[3] = {ax, ay, az};
  for (int i = 0; i < 3; ++i) {
    const D unit = _mm_set1_pd(1.0), none = zero;
    out.axis[0][i] = pick(sloped, own[i], i == 0 ? unit : none);
    out.axis[1][i] = pick(sloped, u[i], i == 1 ? unit : none);
    out.axis[2][i] = pick(sloped, v[i], i == 2 ? unit : none);
    out.center[i] = pick(sloped, mid[0] * own[i] + mid[1] * u[i] + mid[2] * v[i], lanes(n[0].box_center[i], n[1].box_center[i]));
  }
  return out;
}

}  // namespace

void PairContext::near_a_pair(std::uint32_t first, NearA& a0, NearA& a1) const {
  NearA* out[2] = {&a0, &a1};
  for (int i = 0; i < 2; ++i) fill_box_a(first + static_cast<std::uint32_t>(i), *out[i]);
  const Frame2 f = own_frames(mA, first);
  for (int i = 0; i < 2; ++i) {
    Frame& to = out[i]->frame;
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) to.axis[k][c] = lane(f.axis[k][c], i);
      to.center[k] = lane(f.center[k], i);
      to.half[k] = lane(f.half[k], i);
    }
  }
}

void PairContext::near_b_pair(std::uint32_t first, NearB& b0, NearB& b1) const {
  NearB* out[2] = {&b0, &b1};
  for (int i = 0; i < 2; ++i) fill_box_b(first + static_cast<std::uint32_t>(i), *out[i]);
  const Frame2 f = own_frames(mB, first);
  // Brought into A's frame: R x (+ T for the center), as near_b.
  D center[3], axis[3][3];
  for (int i = 0; i < 3; ++i) {
    const D r0 = _mm_set1_pd(mRot(i, 0)), r1 = _mm_set1_pd(mRot(i, 1)), r2 = _mm_set1_pd(mRot(i, 2));
    center[i] = r0 * f.center[0] + r1 * f.center[1] + r2 * f.center[2] + _mm_set1_pd(mTrans[i]);
    for (int k = 0; k < 3; ++k) axis[k][i] = r0 * f.axis[k][0] + r1 * f.axis[k][1] + r2 * f.axis[k][2];
  }
  for (int i = 0; i < 2; ++i) {
    Frame& to = out[i]->frame;
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) to.axis[k][c] = lane(axis[k][c], i);
      to.center[k] = lane(center[k], i);
      to.half[k] = lane(f.half[k], i);
    }
  }
}

}  // namespace caliber::narrow

#else

namespace caliber::narrow {

void PairContext::near_a_pair(std::uint32_t first, NearA& a0, NearA& a1) const {
  a0 = near_a(first);
  a1 = near_a(first + 1);
}

void PairContext::near_b_pair(std::uint32_t first, NearB& b0, NearB& b1) const {
  b0 = near_b(first);
  b1 = near_b(first + 1);
}

}  // namespace caliber::narrow

#endif
