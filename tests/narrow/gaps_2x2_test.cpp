// PairContext::gaps_2x2 (the distance bound of a visit's four child pairs at once, AVX2 where the
// CPU has it) against PairContext::gap on each pair: the same value, bit for bit, wherever gap's
// is within the reach, and beyond the reach wherever gap's is; on nearby and far poses, with and
// without groups.

#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/distance_bound_avx2.h"
#include "narrow/pair_context.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

/// Node i of A (Near = NearA) or of B (NearB) prepared for the distance bound, as a value.
template <class Near>
Near near_of(const PairContext& ctx, std::uint32_t i) {
  Near s;
  ctx.near(i, s);
  return s;
}

TEST(Gaps2x2, SameBoundsAsGap) {
  const auto a = build_model(make_torus(1.0, 0.35, 40, 24));
  Mesh box = make_box(0.6, 0.4, 0.3, 12);
  // Groups: A all in 0; B's triangles in 1 or 2 by halves of the list (whole subtrees of one
  // group), 0 touching only 2, so that groups rule out some node pairs.
  box.groups.assign(box.triangles.size(), 1);
  for (std::size_t t = box.groups.size() / 2; t < box.groups.size(); ++t) box.groups[t] = 2;
  const auto b = build_model(box);
  GroupCompatibility groups;
  groups.compatible[0] = 1u << 2;
  groups.compatible[1] = 0;
  groups.compatible[2] = 1u;
  std::mt19937_64 rng(20261125);
  long within = 0, beyond = 0, differing = 0, forbidden = 0;
  QueryRequest request;
  request.kind = QueryKind::distance;
  for (int p = 0; p < 48; ++p) {
    request.groups = p % 3 == 0 ? &groups : nullptr;
    const PairContext ctx(*a, test::random_pose(rng, 0.3), *b, test::random_pose(rng, p % 2 == 0 ? 1.2 : 3.0), request);
    // A reach about the pair's distance scale, so that both outcomes are common.
    const double reach = ctx.reach_for(0.05 + 0.1 * (p % 5));
    std::vector<std::pair<std::uint32_t, std::uint32_t>> work{{0, 0}};
    for (std::size_t w = 0; w < work.size() && w < 4000; ++w) {
      const BvhNode& na = data(*a).nodes[work[w].first];
      const BvhNode& nb = data(*b).nodes[work[w].second];
      if (na.is_leaf() || nb.is_leaf()) continue;
      const PairContext::NearA sa[2] = {near_of<PairContext::NearA>(ctx, na.index),
                                        near_of<PairContext::NearA>(ctx, na.index + 1)};
      const PairContext::NearB sb[2] = {near_of<PairContext::NearB>(ctx, nb.index),
                                        near_of<PairContext::NearB>(ctx, nb.index + 1)};
      double gaps[4];
      ctx.gaps_2x2(sa[0], sa[1], sb[0], sb[1], reach, gaps);
      for (std::uint32_t k = 0; k < 4; ++k) {
        const double want = ctx.gap(sa[k / 2], sb[k % 2], reach);
        const bool ok = want <= reach ? same_bits(want, gaps[k]) : gaps[k] > reach;
        (want <= reach ? within : beyond) += 1;
        forbidden += want == std::numeric_limits<double>::infinity();
        // Descend into the pairs within twice the reach, where the bounds are close to it.
        if (want <= 2.0 * reach) work.emplace_back(na.index + k / 2, nb.index + k % 2);
        if (!ok && ++differing <= 5) {
          ADD_FAILURE() << "pose " << p << " pair " << k << ": gap " << want << ", four at once " << gaps[k] << ", reach "
                        << reach;
        }
      }
    }
  }
  EXPECT_EQ(differing, 0);
  EXPECT_GT(within, 5000);
  EXPECT_GT(beyond, 5000);
  EXPECT_GT(forbidden, 100);
}

TEST(Gaps2x2, TheAvx512FormGivesTheAvx2FormsBits) {
  // Both builds of the four-lane bound make the same operations: the same four values, bit for
  // bit, within the reach and beyond it.
  const detail::Gaps2x2 avx2 = detail::gaps_2x2_form(false), wide = detail::gaps_2x2_form(true);
  if (avx2 == nullptr || wide == nullptr) GTEST_SKIP() << "no AVX2 or no AVX-512VL on this CPU";
  const auto a = build_model(make_torus(1.0, 0.35, 40, 24));
  const auto b = build_model(make_box(0.6, 0.4, 0.3, 12));
  std::mt19937_64 rng(20261206);
  QueryRequest request;
  request.kind = QueryKind::distance;
  const detail::BoundConstants constants{1e-12, 1.0 - 1e-12};
  long compared = 0;
  for (int p = 0; p < 24; ++p) {
    const PairContext ctx(*a, test::random_pose(rng, 0.3), *b, test::random_pose(rng, p % 2 == 0 ? 1.2 : 3.0), request);
    const double reach = ctx.reach_for(0.05 + 0.1 * (p % 5));
    for (std::uint32_t i = 0; i + 1 < data(*a).nodes.size(); i += 7) {
      for (std::uint32_t j = 0; j + 1 < data(*b).nodes.size(); j += 5) {
        double x[4], y[4];
        avx2(constants, near_of<PairContext::NearA>(ctx, i), near_of<PairContext::NearA>(ctx, i + 1),
             near_of<PairContext::NearB>(ctx, j), near_of<PairContext::NearB>(ctx, j + 1), reach, x);
        wide(constants, near_of<PairContext::NearA>(ctx, i), near_of<PairContext::NearA>(ctx, i + 1),
             near_of<PairContext::NearB>(ctx, j), near_of<PairContext::NearB>(ctx, j + 1), reach, y);
        for (int k = 0; k < 4; ++k) EXPECT_TRUE(same_bits(x[k], y[k])) << "pose " << p << " nodes " << i << ", " << j;
        compared += 4;
      }
    }
  }
  EXPECT_GT(compared, 10000);
}

}  // namespace
}  // namespace caliber::narrow
