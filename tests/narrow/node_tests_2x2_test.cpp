// PairContext::node_tests_2x2 (the four child pairs of a visit prepared and tested at once, AVX2
// where the CPU has it) against prepare_a, prepare_b (with their disks) and node_test_2x2_lane on
// each pair, and node_tests_one_side (a visit where one side descends) against node_test: the
// same decision for every pair, on overlapping and nearby objects, for every depth-first kind.

#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/cd_tree.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

TEST(NodeTests2x2, SameDecisionsAsNodeTest) {
  const auto a = build_model(make_torus(1.0, 0.35, 40, 24));
  const auto b = build_model(make_box(0.6, 0.4, 0.3, 12));
  std::mt19937_64 rng(20261125);
  long passed = 0, failed = 0, differing = 0, by_disks = 0, forms_checked = 0, one_side_passed = 0;
  long float_sure = 0, float_unsure = 0;
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
          // With the lanes a traversal makes once (the call without groups or cones goes straight
          // to the form): the same bits.
          const detail::NodeLanes lanes = ctx.node_lanes();
          if (ctx.node_tests_2x2(a0, a1, b0, b1, &lanes) != mask && ++differing <= 5) {
            ADD_FAILURE() << "kind " << static_cast<int>(kind) << " pose " << p << " case " << c << ": with lanes";
          }
          // Both four-lane forms (AVX2, AVX-512VL registers) where this CPU has them: their
          // geometric mask is the node test's, less groups and cones (none here but contact's).
          for (const bool wide : {false, true}) {
            if (const auto form = detail::node_within_2x2_form(wide)) {
              const int geometric = form(ctx.node_test_frame(), ctx.node_lanes(), a0, a1, b0, b1);
              ++forms_checked;
              if ((kind == QueryKind::contact ? (geometric & mask) != mask : geometric != mask) && ++differing <= 5) {
                ADD_FAILURE() << "form " << wide << " kind " << static_cast<int>(kind) << " pose " << p << " case " << c;
              }
            }
          }
          // The float pre-decision: where it is sure, the double form's bits.
          if (c == 0 && lanes.floats && detail::node_within_2x2_float_form() != nullptr) {
            int pass = 0, unsure = 0;
            detail::node_within_2x2_float_bits(ctx.node_test_frame(), lanes, a0, a1, b0, b1, pass, unsure);
            const int geometric = detail::node_within_2x2_double(ctx.node_test_frame(), lanes, a0, a1, b0, b1);
            float_unsure += unsure != 0;
            float_sure += 4 - __builtin_popcount(static_cast<unsigned>(unsure));
            if ((pass & ~unsure) != (geometric & ~unsure) && ++differing <= 5) {
              ADD_FAILURE() << "float pre-decision, kind " << static_cast<int>(kind) << " pose " << p;
            }
          }
          if (c != 0) {
            // One side descends: node_tests_one_side's bits 0 and 3 are node_test's on the two
            // children, and so are the forms' without the disks (those two bits alone).
            const int want = (ctx.node_test(sa[0], sb[0]) ? 1 : 0) | (ctx.node_test(sa[1], sb[1]) ? 8 : 0);
            one_side_passed += want != 0;
            if ((ctx.node_tests_one_side(a0, a1, b0, b1) != want || ctx.node_tests_one_side(a0, a1, b0, b1, &lanes) != want) &&
                ++differing <= 5) {
              ADD_FAILURE() << "kind " << static_cast<int>(kind) << " pose " << p << " case " << c << ": one side";
            }
            for (const bool wide : {false, true}) {
              if (const auto form = detail::node_within_2x2_form(wide, false)) {
                const int geometric = form(ctx.node_test_frame(), ctx.node_lanes(), a0, a1, b0, b1);
                ++forms_checked;
                if ((kind == QueryKind::contact ? (geometric & want) != want : geometric != want) && ++differing <= 5) {
                  ADD_FAILURE() << "form " << wide << " without disks, kind " << static_cast<int>(kind) << " pose " << p
                                << " case " << c;
                }
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
  EXPECT_GT(one_side_passed, 1000) << "visits where one side descends pass some children";
  if (detail::node_within_2x2_form(false) != nullptr) EXPECT_GT(forms_checked, 10000);
  if (detail::node_within_2x2_float_form() != nullptr) {
    // The float test decides most pairs, and leaves some visits to the double form.
    EXPECT_GT(float_sure, 10000);
    EXPECT_GT(float_unsure, 0);
  }
}

// Beyond the scales float's range covers, the lanes leave every visit to the double form, whose
// decisions the traversal then gets (pairs 1e13 apart in a scene of 1e13: the same bits as the
// scalar test).
TEST(NodeTests2x2, FarScalesUseTheDoubleForm) {
  const auto a = build_model(make_torus(1.0, 0.35, 16, 12));
  QueryRequest request;
  const PairContext near(*a, Pose{}, *a, Pose::from_values(0.5, 0, 0, 1, 0, 0, 0), request);
  EXPECT_TRUE(near.node_lanes().floats);
  const PairContext far(*a, Pose{}, *a, Pose::from_values(1e13, 0, 0, 1, 0, 0, 0), request);
  const detail::NodeLanes lanes = far.node_lanes();
  EXPECT_FALSE(lanes.floats);
  const BvhNode& root = data(*a).nodes[0];
  const std::uint32_t c = root.index;
  EXPECT_EQ(far.node_tests_2x2(c, c + 1, c, c + 1, &lanes), far.node_tests_2x2_scalar(c, c + 1, c, c + 1));
}

// narrow::visit takes a node's children that pass in cd_children order, each decided as child_test
// decides it and counted once: with no taboo list and with one, in the wide CD tree (interference,
// contact: either side descending, child_test making its slot's test alone) and in the binary one
// (distance: the lanes, one side or both descending, and pair by pair where one side descends), on
// models whose spheres differ in size, so that many visits descend on one side, a leaf against an
// inner node among them.
TEST(NodeTests2x2, VisitTakesThePassingChildrenInTreeOrder) {
  const auto a = build_model(make_torus(1.0, 0.35, 48, 24));
  const auto b = build_model(make_box(0.3, 0.2, 0.15, 3));
  std::mt19937_64 rng(20261201);
  long one_side = 0, both = 0, down_a = 0, down_b = 0, taken = 0;
  for (const QueryKind kind : {QueryKind::interference, QueryKind::contact, QueryKind::distance}) {
    QueryRequest request;
    request.kind = kind;
    request.tolerance = kind == QueryKind::interference ? 0.0 : 0.05;
    for (int p = 0; p < 12; ++p) {
      const PairContext ctx(*a, test::random_pose(rng, 0.3), *b, test::random_pose(rng, 1.0), request);
      // A taboo list that names no node of this tree: the taboo path, skipping nothing.
      const Taboo elsewhere{{NodePair{0xFFFFFFF0u, 0xFFFFFFF0u}}};
      char reached[1] = {0};
      std::vector<NodePair> work{{0, 0}};
      for (std::size_t w = 0; w < work.size() && w < 50000; ++w) {
        const NodePair n = work[w];
        if (ctx.a().nodes[n.a].is_leaf() && ctx.b().nodes[n.b].is_leaf()) continue;
        NodePair kids[kMaxChildren], want[kMaxChildren];
        const int count = cd_children(ctx, n, kids);
        int wanted = 0;
        for (int k = 0; k < count; ++k) {
          if (child_test(ctx, n, kids[k])) want[wanted++] = kids[k];
        }
        if (kind == QueryKind::distance) {
          (count == 2 ? one_side : both) += 1;
        } else {
          (kids[0].a != n.a ? down_a : down_b) += 1;
        }
        for (const bool with_taboo : {false, true}) {
          std::vector<Candidate> out;
          QueryStats stats;
          NodePair passed[kMaxChildren];
          const TabooView taboo = with_taboo ? TabooView{&elsewhere, reached} : TabooView{};
          const int got = visit(ctx, n, out, stats, passed, taboo);
          ASSERT_EQ(got, wanted) << "kind " << static_cast<int>(kind) << " pose " << p << " taboo " << with_taboo;
          EXPECT_EQ(stats.node_tests, static_cast<std::uint64_t>(count));
          for (int k = 0; k < wanted; ++k) EXPECT_EQ(passed[k], want[k]) << "child " << k << " taboo " << with_taboo;
        }
        taken += wanted;
        work.insert(work.end(), want, want + wanted);
      }
    }
  }
  EXPECT_GT(one_side, 500) << "many binary visits descend on one side";
  EXPECT_GT(both, 1000);
  EXPECT_GT(down_a, 500) << "wide visits descend on either side";
  EXPECT_GT(down_b, 500);
  EXPECT_GT(taken, 2000);
}

}  // namespace
}  // namespace caliber::narrow
