// PairContext::node_tests_2x2 (the four child pairs of a visit prepared and tested at once, AVX2
// where the CPU has it) against prepare_a, prepare_b (with their disks) and node_test_2x2_lane on each pair: the same decision for every pair, on overlapping and nearby
// objects, for every depth-first kind.

#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/pair_context.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

TEST(NodeTests2x2, SameDecisionsAsNodeTest) {
  const auto a = build_model(make_torus(1.0, 0.35, 40, 24));
  const auto b = build_model(make_box(0.6, 0.4, 0.3, 12));
  std::mt19937_64 rng(20261125);
  long passed = 0, failed = 0, differing = 0, by_disks = 0, forms_checked = 0;
  for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity, QueryKind::contact}) {
    QueryRequest request;
    request.kind = kind;
    request.tolerance = kind == QueryKind::interference ? 0.0 : 0.05;
    for (int p = 0; p < 24; ++p) {
      const PairContext ctx(*a, test::random_pose(rng, 0.3), *b, test::random_pose(rng, 1.2), request);
      // Visit the CD tree as far as both sides have children: below the roots, every pair whose
      // four children are tested, descending into those that pass (where the decisions are close).
      std::vector<std::pair<std::uint32_t, std::uint32_t>> work{{0, 0}};
      for (std::size_t w = 0; w < work.size() && w < 20000; ++w) {
        const BvhNode& na = data(*a).nodes[work[w].first];
        const BvhNode& nb = data(*b).nodes[work[w].second];
        if (na.is_leaf() || nb.is_leaf()) continue;
        // Both sides descend, then only A's, then only B's (the other side's node given twice).
        const std::uint32_t wa = work[w].first, wb = work[w].second;
        const std::uint32_t cases[3][4] = {
            {na.index, na.index + 1, nb.index, nb.index + 1}, {na.index, na.index + 1, wb, wb}, {wa, wa, nb.index, nb.index + 1}};
        for (int c = 0; c < 3; ++c) {
          const auto& [a0, a1, b0, b1] = cases[c];
          PairContext::SideA sa[2] = {ctx.prepare_a(a0), ctx.prepare_a(a1)};
          PairContext::SideB sb[2] = {ctx.prepare_b(b0), ctx.prepare_b(b1)};
          for (int i = 0; i < 2; ++i) {
            ctx.prepare_disk_a(sa[i]);
            ctx.prepare_disk_b(sb[i]);
          }
          const int mask = ctx.node_tests_2x2(a0, a1, b0, b1);
          // Both four-lane forms (AVX2, AVX-512VL registers) where this CPU has them: their
          // geometric mask is the node test's, less groups and cones (none here but contact's).
          for (const bool wide : {false, true}) {
            if (const auto form = detail::node_within_2x2_form(wide)) {
              const int geometric = form(ctx.node_test_frame(), a0, a1, b0, b1);
              ++forms_checked;
              if ((kind == QueryKind::contact ? (geometric & mask) != mask : geometric != mask) && ++differing <= 5) {
                ADD_FAILURE() << "form " << wide << " kind " << static_cast<int>(kind) << " pose " << p << " case " << c;
              }
            }
          }
          if (ctx.node_tests_2x2_scalar(a0, a1, b0, b1) != mask && ++differing <= 5) {
            ADD_FAILURE() << "kind " << static_cast<int>(kind) << " pose " << p << " case " << c << ": the scalar form differs";
          }
          for (std::uint32_t k = 0; k < 4; ++k) {
            const bool want = ctx.node_test_2x2_lane(sa[k / 2], sb[k % 2]);
            if (want && !ctx.node_test(sa[k / 2], sb[k % 2])) ++differing;  // the disks only add refusals
            if (!want && ctx.node_test(sa[k / 2], sb[k % 2])) ++by_disks;
            (want ? passed : failed) += 1;
            if (want && c == 0) work.emplace_back(na.index + k / 2, nb.index + k % 2);
            if (want != (((mask >> k) & 1) != 0) && ++differing <= 5) {
              ADD_FAILURE() << "kind " << static_cast<int>(kind) << " pose " << p << " case " << c << " pair " << k << ": scalar "
                            << want;
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(differing, 0);
  // Both outcomes occur often, so the comparison says something.
  EXPECT_GT(passed, 10000);
  EXPECT_GT(failed, 10000);
  EXPECT_GT(by_disks, 1000) << "the disks refuse some pairs the rest of the test lets through";
  if (detail::node_within_2x2_form(false) != nullptr) EXPECT_GT(forms_checked, 10000);
}

}  // namespace
}  // namespace caliber::narrow
