// PairContext's group and normal-cone tests: of node pairs (the group masks, the cones) and of
// triangle pairs (their groups).

#include <numbers>

#include "narrow/pair_context.h"

namespace caliber::narrow {

bool PairContext::cones_can_face(const BvhNodeFilter& na, const BvhNodeFilter& nb) const {
  // Leaf normals n_a, n_b lie within their cones; a leaf passes when angle(n_a, -n_b) <= theta, so by
  // the triangle inequality angle(axis_a, -axis_b) <= alpha_a + alpha_b + theta for any passing leaf.
  if (na.cone_angle < 0.0f || nb.cone_angle < 0.0f) return false;  // only degenerate triangles below
  const double total = static_cast<double>(na.cone_angle) + static_cast<double>(nb.cone_angle) + mTheta;
  if (total >= std::numbers::pi) return true;
  // B's axis in A's frame and its dot product with A's, each sum left to right (as the lanes of
  // detail::cones_face_2x2 make them).
  double moved[3];
  for (int i = 0; i < 3; ++i) {
    const double* r = mNodeFrame.rot[i];
    moved[i] = (r[0] * nb.cone_axis[0] + r[1] * nb.cone_axis[1]) + r[2] * nb.cone_axis[2];
  }
  const double facing = -((na.cone_axis[0] * moved[0] + na.cone_axis[1] * moved[1]) + na.cone_axis[2] * moved[2]);
  // cos(alpha_a + alpha_b + theta) by the angle-sum formulas on the stored cosines and sines
  // (float-rounded: about 2.4e-7 of error at most, inside the 1e-6 margin).
  const double ca = na.cone_cos, sa = na.cone_sin, cb = nb.cone_cos, sb = nb.cone_sin;
  const double cos_ab = ca * cb - sa * sb, sin_ab = sa * cb + ca * sb;
  const double cos_total = cos_ab * mCosTheta - sin_ab * mSinTheta;
  return facing >= cos_total - kConeCosMargin;
}

int PairContext::groups_and_cones(int pass, std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1) const {
  const std::uint32_t ia[2] = {a0, a1}, ib[2] = {b0, b1};
  // What node_test adds to node_within's geometry, pair by pair: groups, then normal cones.
  for (int left = pass; left != 0; left &= left - 1) {
    const int k = __builtin_ctz(static_cast<unsigned>(left));
    if (!groups_and_cones_allow(ia[k / 2], ib[k % 2])) pass &= ~(1 << k);
  }
  return pass;
}

bool PairContext::groups_and_cones_allow(std::uint32_t ia, std::uint32_t ib) const {
  if (mGroups != nullptr && !groups_can_touch(mA.group_mask(ia), mB.group_mask(ib))) return false;
  return mKind != QueryKind::contact || cones_can_face(mA.filters[ia], mB.filters[ib]);
}

bool PairContext::groups_can_touch(std::uint64_t ga, std::uint64_t gb) const {
  while (ga != 0) {
    const int g = __builtin_ctzll(ga);
    if (mGroups->compatible[g] & gb) return true;
    ga &= ga - 1;
  }
  return false;
}

bool PairContext::groups_allow(std::uint32_t ta, std::uint32_t tb) const {
  if (mGroups == nullptr) return true;
  const unsigned ga = mA.mesh.groups.empty() ? 0 : mA.mesh.groups[ta];
  const unsigned gb = mB.mesh.groups.empty() ? 0 : mB.mesh.groups[tb];
  return mGroups->allows(ga, gb);
}

}  // namespace caliber::narrow
