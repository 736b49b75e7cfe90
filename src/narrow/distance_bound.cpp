// The distance query's bound on a pair context: the nodes of B prepared in A's frame, and the
// bound of a visit's four child pairs (PairContext::gap, in lanes where the CPU has them).

#include <limits>

#include "narrow/distance_bound_avx2.h"
#include "narrow/pair_context.h"

namespace caliber::narrow {

void PairContext::near(std::uint32_t ib, NearB& s) const {
  fill_box_b(ib, s);
  OrientedBox computed;
  const OrientedBox& own = own_frame(mB, ib, computed);
  for (int i = 0; i < 3; ++i) {
    s.frame.center[i] =
        mRot(i, 0) * own.center[0] + mRot(i, 1) * own.center[1] + mRot(i, 2) * own.center[2] + mNodeFrame.trans[i];
  }
  for (int k = 0; k < 3; ++k) {
    s.frame.half[k] = own.half[k];
    for (int i = 0; i < 3; ++i) {
      s.frame.axis[k][i] = mRot(i, 0) * own.axis[k][0] + mRot(i, 1) * own.axis[k][1] + mRot(i, 2) * own.axis[k][2];
    }
  }
}

void PairContext::gaps_2x2(const NearA& a0, const NearA& a1, const NearB& b0, const NearB& b1, double reach,
                           double out[4]) const {
  static const detail::Gaps2x2 lanes =
      detail::gaps_2x2_form(true) != nullptr ? detail::gaps_2x2_form(true) : detail::gaps_2x2_form(false);
  const NearA* as[2] = {&a0, &a1};
  const NearB* bs[2] = {&b0, &b1};
  if (lanes == nullptr) {
    for (int k = 0; k < 4; ++k) out[k] = gap(*as[k / 2], *bs[k % 2], reach);
    return;
  }
  lanes(detail::BoundConstants{kRotationHair, kApartShrink}, a0, a1, b0, b1, reach, out);
  // What gap adds to the geometry: groups that forbid every pair below.
  if (mGroups == nullptr) return;
  for (int k = 0; k < 4; ++k) {
    if (out[k] <= reach && !groups_can_touch(mA.group_mask(as[k / 2]->index), mB.group_mask(bs[k % 2]->index))) {
      out[k] = std::numeric_limits<double>::infinity();
    }
  }
}

}  // namespace caliber::narrow
