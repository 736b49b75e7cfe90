// The wide node test (narrow/wide_test.h): its scalar and AVX2 forms decide alike on the inputs
// that stretch it (a mesh far from its own origin, slivers without a normal, a tolerance larger
// than the meshes, tiny and huge scales), and it never refuses a slot below which some triangle
// pair is kept by the leaf test.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/cd_tree.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"
#include "narrow/visit.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

/// m scaled by 2^e, then moved by offset.
Mesh moved(Mesh m, int e, const Eigen::Vector3d& offset) {
  for (Eigen::Vector3d& v : m.vertices) v = std::ldexp(1.0, e) * v + offset;
  return m;
}

/// A sphere with `slivers` zero-area triangles more (a corner repeated: leaves without a slab).
Mesh sphere_with_slivers(int slivers) {
  Mesh m = make_sphere(0.6, 10, 14);
  for (int i = 0; i < slivers; ++i) {
    const auto t = m.triangles[static_cast<std::size_t>(i) * 5];
    m.triangles.push_back({t[0], t[1], t[0]});
  }
  return m;
}

/// Calls visit(n, v) at each node of the wide CD tree that passes its test, breadth first, up to
/// `most` visits (the children the scalar form passes).
template <class Visit>
void walk(const PairContext& ctx, const detail::WideLanes& lanes, std::size_t most, Visit&& visit) {
  std::vector<NodePair> work{{0, 0}};
  for (std::size_t w = 0; w < work.size() && w < most; ++w) {
    const NodePair n = work[w];
    const BvhNode& a = ctx.a().nodes[n.a];
    const BvhNode& b = ctx.b().nodes[n.b];
    if (a.is_leaf() && b.is_leaf()) continue;
    const WideVisit v = wide_visit(ctx, n, a, b);
    const unsigned pass =
        detail::wide_test_scalar(ctx.node_test_frame(), lanes, v.a_descends, v.stay, *v.staying, *v.node, nullptr);
    visit(n, v, pass);
    for (int k = 0; k < v.node->count(); ++k) {
      if ((pass >> k & 1u) != 0) work.push_back(v.child(k, n));
    }
  }
}

TEST(WideTest, ScalarAndAvx2FormsDecideAlike) {
  // The AVX2 form and its AVX-512VL build (where the CPU has it) against the scalar one.
  const detail::WideTest avx2 = detail::wide_test_form(false), wide = detail::wide_test_form(true);
  if (avx2 == nullptr) GTEST_SKIP() << "no AVX2, FMA and F16C on this CPU";
  const Mesh torus = make_torus(1.0, 0.35, 40, 24);
  const Eigen::Vector3d far(3e6, -2e6, 1e6);
  struct Case {
    Mesh a, b;
    QueryKind kind;
    double tolerance, spread;
  };
  const std::vector<Case> cases = {
      {torus, make_box(0.4, 0.3, 0.2, 3), QueryKind::interference, 0.0, 0.6},
      {moved(torus, 0, far), moved(torus, 0, far), QueryKind::interference, 0.0, 0.6},
      {torus, sphere_with_slivers(60), QueryKind::contact, 0.05, 0.8},
      {torus, make_sphere(0.3, 8, 10), QueryKind::proximity, 5.0, 0.8},
      {moved(torus, -40, {0, 0, 0}), moved(torus, -40, {0, 0, 0}), QueryKind::interference, 0.0, std::ldexp(0.6, -40)},
      {moved(torus, 40, {0, 0, 0}), moved(torus, 40, {0, 0, 0}), QueryKind::proximity, std::ldexp(0.01, 40), std::ldexp(0.6, 40)},
  };
  std::mt19937_64 rng(20261202);
  long visits = 0, differing = 0, by_floats = 0;
  for (const Case& c : cases) {
    const auto a = build_model(c.a), b = build_model(c.b);
    QueryRequest request;
    request.kind = c.kind;
    request.tolerance = c.tolerance;
    for (int p = 0; p < 6; ++p) {
      // B turned about the meshes' place (far from the origin in the second case) and moved a little.
      Pose pose_b = test::random_pose(rng, c.spread);
      const Eigen::Vector3d place = &c == &cases[1] ? far : Eigen::Vector3d::Zero();
      pose_b.translation += place - pose_b.rotation * place;
      const PairContext ctx(*a, Pose{}, *b, pose_b, request);
      const detail::WideLanes lanes = wide_lanes(ctx);
      ASSERT_TRUE(lanes.floats);
      detail::WideLanes boxes_only = lanes;
      boxes_only.floats = false;
      walk(ctx, lanes, 20000, [&](NodePair, const WideVisit& v, unsigned pass) {
        ++visits;
        if (avx2(ctx.node_test_frame(), lanes, v.a_descends, v.stay, *v.staying, *v.node, nullptr) != pass) ++differing;
        if (wide != nullptr && wide(ctx.node_test_frame(), lanes, v.a_descends, v.stay, *v.staying, *v.node, nullptr) != pass) {
          ++differing;
        }
        const unsigned boxes =
            detail::wide_test_scalar(ctx.node_test_frame(), boxes_only, v.a_descends, v.stay, *v.staying, *v.node, nullptr);
        EXPECT_EQ(pass & ~boxes, 0u) << "the float stage only refuses";
        by_floats += __builtin_popcount(boxes & ~pass);
      });
    }
  }
  EXPECT_EQ(differing, 0) << "of " << visits << " visits";
  EXPECT_GT(visits, 5000);
  EXPECT_GT(by_floats, 1000) << "the float stage refuses slots the boxes let through";
}

TEST(WideTest, AKeptStayingNodeDecidesAsAFreshOne) {
  // Depth first, as the traversal walks: each form keeps its staying nodes from visit to visit
  // (self-pairs, where a node of A and one of B share an index, and a pair of different meshes;
  // near the origin, far from it, and with the float stage off). Each vector form this CPU has
  // (AVX2, and its AVX-512VL build) against the scalar one.
  std::vector<detail::WideTest> forms;
  for (const bool wide_registers : {false, true}) {
    if (const detail::WideTest form = detail::wide_test_form(wide_registers)) forms.push_back(form);
  }
  if (forms.empty()) forms.push_back(nullptr);  // the scalar form's own checks alone
  const Eigen::Vector3d far(3e6, -2e6, 1e6);
  const auto torus = build_model(make_torus(1.0, 0.35, 40, 24));
  const auto sphere = build_model(sphere_with_slivers(30));
  const auto far_torus = build_model(moved(make_torus(1.0, 0.35, 40, 24), 0, far));
  long differing = 0, differing_kept = 0, compared_floats = 0;
  for (const detail::WideTest avx2 : forms) {
    std::mt19937_64 rng(12);
    for (int c = 0; c < 6; ++c) {
      const bool far_case = c >= 4;
      const Model& a = far_case ? *far_torus : *torus;
      const Model& b = far_case ? *far_torus : c % 2 == 0 ? *torus : *sphere;
      QueryRequest request;
      request.kind = c % 2 == 0 ? QueryKind::interference : QueryKind::proximity;
      request.tolerance = c % 2 == 0 ? 0.0 : 0.02;
      Pose pose_b = test::random_pose(rng, 0.5);
      if (far_case) pose_b.translation += far - pose_b.rotation * far;
      const PairContext ctx(a, Pose{}, b, pose_b, request);
      detail::WideLanes lanes = wide_lanes(ctx);
      lanes.floats = c != 2;  // one case with the float stage off
      detail::StayingCache scalar_cache, avx2_cache;
      long visits = 0, kept[2] = {0, 0}, floats_kept = 0;
      std::vector<NodePair> stack{{0, 0}};
      while (!stack.empty() && visits < 20000) {
        const NodePair n = stack.back();
        stack.pop_back();
        const BvhNode& na = ctx.a().nodes[n.a];
        const BvhNode& nb = ctx.b().nodes[n.b];
        if (na.is_leaf() && nb.is_leaf()) continue;
        const WideVisit v = wide_visit(ctx, n, na, nb);
        ++visits;
        bool held = false;
        const detail::StayingCache::Entry& e = scalar_cache.find(v.stay, v.a_descends, held);
        kept[v.a_descends ? 0 : 1] += held ? 1 : 0;
        floats_kept += held && e.has_floats ? 1 : 0;
        const unsigned pass =
            detail::wide_test_scalar(ctx.node_test_frame(), lanes, v.a_descends, v.stay, *v.staying, *v.node, nullptr);
        if (detail::wide_test_scalar(ctx.node_test_frame(), lanes, v.a_descends, v.stay, *v.staying, *v.node, &scalar_cache) !=
            pass) {
          ++differing;
        }
        if (avx2 != nullptr &&
            avx2(ctx.node_test_frame(), lanes, v.a_descends, v.stay, *v.staying, *v.node, &avx2_cache) != pass) {
          ++differing;
        }
        if (avx2 != nullptr) {
          // Both forms kept the same values of the node, bit for bit (the float stage's where made).
          bool in_scalar = false, in_avx2 = false;
          const detail::StayingCache::Entry& s = scalar_cache.find(v.stay, v.a_descends, in_scalar);
          const detail::StayingCache::Entry& x = avx2_cache.find(v.stay, v.a_descends, in_avx2);
          const bool same_box = std::memcmp(s.lo, x.lo, sizeof s.lo) == 0 && std::memcmp(s.hi, x.hi, sizeof s.hi) == 0 &&
                                std::memcmp(s.moved, x.moved, sizeof s.moved) == 0;
          const bool same_floats =
              s.has_floats == x.has_floats && (!s.has_floats || std::memcmp(&s.floats, &x.floats, sizeof s.floats) == 0);
          if (!in_scalar || !in_avx2 || !same_box || !same_floats) ++differing_kept;
          compared_floats += s.has_floats ? 1 : 0;
        }
        for (int k = v.node->count() - 1; k >= 0; --k) {
          if ((pass >> k & 1u) != 0) stack.push_back(v.child(k, n));
        }
      }
      EXPECT_GT(visits, 200) << "case " << c;
      EXPECT_GT(kept[0], visits / 10) << "case " << c << ": visits descending on A find B's node kept";
      EXPECT_GT(kept[1], visits / 10) << "case " << c << ": visits descending on B find A's node kept";
      if (lanes.floats) EXPECT_GT(floats_kept, visits / 10) << "case " << c << ": the float stage's values are kept too";
    }
  }
  EXPECT_EQ(differing, 0);
  EXPECT_EQ(differing_kept, 0);
  if (forms.front() != nullptr) EXPECT_GT(compared_floats, 1000 * static_cast<long>(forms.size()));
}

TEST(WideTest, ARenewedCacheHoldsNothingKeptBefore) {
  detail::StayingCache cache;
  bool held = true;
  cache.find(7, true, held);
  EXPECT_FALSE(held) << "a new cache holds nothing";
  cache.claim(7, true, held);
  EXPECT_FALSE(held) << "the find before claimed nothing";
  cache.claim(7, true, held);
  EXPECT_TRUE(held) << "a claimed place holds its node";
  cache.find(7, true, held);
  EXPECT_TRUE(held);
  cache.find(7, false, held);
  EXPECT_FALSE(held) << "the other side's node of the same id";
  cache.renew();
  cache.find(7, true, held);
  EXPECT_FALSE(held) << "a renewed cache forgets";
  // At the last generation: renew clears the keys and starts again at 1.
  cache.generation = detail::StayingCache::kGenerations - 1;
  cache.claim(9, false, held);
  cache.renew();
  EXPECT_EQ(cache.generation, 1u);
  for (const std::uint64_t k : cache.key) EXPECT_EQ(k, 0u);
  cache.find(9, false, held);
  EXPECT_FALSE(held);
  EXPECT_NE(cache.key_of(0, false), 0u) << "no key is an empty place's";
}

TEST(WideTest, TraversalsWithAndWithoutKeptNodesFindTheSamePairs) {
  // The depth-first traversal (which keeps its staying nodes) against visits that each move their
  // own (narrow::visit without the traversal's lanes), node tests and leaf tests counted alike.
  const auto a = build_model(make_torus(1.0, 0.35, 30, 18));
  const auto b = build_model(sphere_with_slivers(20));
  std::mt19937_64 rng(5);
  TraversalScratch scratch;  // one for every pose: each traversal forgets the last one's nodes
  for (int p = 0; p < 6; ++p) {
    QueryRequest request;
    request.kind = p % 2 == 0 ? QueryKind::interference : QueryKind::proximity;
    request.tolerance = p % 2 == 0 ? 0.0 : 0.02;
    const PairContext ctx(*a, Pose{}, *b, test::random_pose(rng, 0.7), request);
    std::vector<Candidate> kept_out, alone_out;
    QueryStats kept_stats, alone_stats;
    traverse_depth_first(ctx, NodePair{0, 0}, scratch, kept_out, kept_stats);
    std::vector<NodePair> stack;
    if (test_root(ctx, NodePair{0, 0}, alone_stats)) stack.push_back(NodePair{0, 0});
    while (!stack.empty()) {
      const NodePair n = stack.back();
      stack.pop_back();
      NodePair passed[kMaxChildren];
      const int count = visit(ctx, n, alone_out, alone_stats, passed);
      for (int k = count - 1; k >= 0; --k) stack.push_back(passed[k]);
    }
    const auto ids = [](std::vector<Candidate> c) {
      std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
      for (const Candidate& x : c) out.emplace_back(x.tri_a, x.tri_b);
      std::sort(out.begin(), out.end());
      return out;
    };
    EXPECT_EQ(ids(kept_out), ids(alone_out)) << "pose " << p;
    EXPECT_EQ(kept_stats.node_tests, alone_stats.node_tests);
    EXPECT_EQ(kept_stats.leaf_tests, alone_stats.leaf_tests);
    EXPECT_GT(kept_stats.leaf_tests, 0u) << "pose " << p << ": the meshes meet";
  }
}

/// The scalar form of the wide test, named as a visit's Test.
struct ScalarWideTest {
  unsigned operator()(const detail::NodeTestFrame& f, const detail::WideLanes& l, bool a_descends, std::uint32_t stay,
                      const BvhNode& sn, const WideNode& w, detail::StayingCache* cache) const {
    return detail::wide_test_scalar(f, l, a_descends, stay, sn, w, cache);
  }
};

TEST(WideTest, TheAvx2LoopsVisitAsTheScalarOne) {
  // The traversal's loop built for AVX2 and for AVX-512VL (its wide test inlined), as
  // traverse_depth_first runs it, against the same loop visiting with the scalar test: the same
  // candidates in the same order, the same counts.
  if (kWideLoop == nullptr) GTEST_SKIP() << "no AVX2, FMA and F16C on this CPU";
  // The library runs the AVX-512VL build where the CPU has it, else the AVX2 one.
  EXPECT_EQ(kWideLoop, detail::wide_loop_form(true) != nullptr ? detail::wide_loop_form(true) : detail::wide_loop_form(false));
  for (const bool wide_registers : {false, true}) {
    const WideLoop form = detail::wide_loop_form(wide_registers);
    if (form == nullptr) continue;
    const auto a = build_model(make_torus(1.0, 0.35, 30, 18));
    const auto b = build_model(sphere_with_slivers(20));
    std::mt19937_64 rng(9);
    for (int p = 0; p < 6; ++p) {
      QueryRequest request;
      request.kind = p % 3 == 0 ? QueryKind::interference : p % 3 == 1 ? QueryKind::proximity : QueryKind::contact;
      request.tolerance = p % 3 == 0 ? 0.0 : 0.02;
      const PairContext ctx(*a, Pose{}, *b, test::random_pose(rng, 0.7), request);
      std::vector<Candidate> loop_out;
      QueryStats loop_stats, scalar_stats;
      const detail::WideLanes lanes = wide_lanes(ctx);
      detail::StayingCache staying;
      std::vector<NodePair> loop_stack;
      LeafBuffer loop_buffer;
      if (test_root(ctx, NodePair{0, 0}, loop_stats)) loop_stack.push_back(NodePair{0, 0});
      form(ctx, loop_stack, loop_stack.size(), loop_out, loop_stats, {}, loop_buffer, VisitLanes{nullptr, &lanes, &staying});
      ctx.flush_leaves(loop_buffer, loop_out);
      staying.renew();
      // As traverse_depth_first runs the loop the library chose: the same pairs in the same order.
      TraversalScratch scratch;
      std::vector<Candidate> traversal_out;
      QueryStats traversal_stats;
      traverse_depth_first(ctx, NodePair{0, 0}, scratch, traversal_out, traversal_stats);
      // From a stack that holds the root alone: the loop grows it as it pushes.
      std::vector<NodePair> stack;
      std::vector<Candidate> scalar_out;
      LeafBuffer buffer;
      if (test_root(ctx, NodePair{0, 0}, scalar_stats)) stack.push_back(NodePair{0, 0});
      visit_until_empty(ctx, stack, stack.size(), scalar_out, scalar_stats, {}, buffer, VisitLanes{nullptr, &lanes, &staying},
                        ScalarWideTest{});
      EXPECT_GT(stack.size(), std::size_t{1} + kMaxChildren)
          << "pose " << p << ": the stack grew past the room made for one visit";
      ctx.flush_leaves(buffer, scalar_out);
      const auto ids = [](const std::vector<Candidate>& c) {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
        for (const Candidate& x : c) out.emplace_back(x.tri_a, x.tri_b);
        return out;
      };
      EXPECT_EQ(ids(loop_out), ids(scalar_out)) << "pose " << p;
      EXPECT_EQ(ids(traversal_out), ids(scalar_out)) << "pose " << p;
      EXPECT_EQ(traversal_stats.node_tests, scalar_stats.node_tests);
      EXPECT_EQ(loop_stats.node_tests, scalar_stats.node_tests);
      EXPECT_EQ(loop_stats.leaf_tests, scalar_stats.leaf_tests);
      EXPECT_GT(loop_stats.leaf_tests, 0u) << "pose " << p << ": the meshes meet";
    }
  }
}

TEST(WideTest, AStayingLeafMeetsTheSlotsSlabsWithItsCornersNotItsBox) {
  // A flat grid in the plane x + y + z = 0 and one triangle standing square to it, its lowest
  // edge 0.1 above it: the triangle's box reaches through the plane, its corners do not, and its
  // own plane (square to the grid's) refuses nothing. No pair meets; the wide test refuses each
  // pair of the triangle with a grid triangle before any leaf test.
  const Eigen::Vector3d n = Eigen::Vector3d(1, 1, 1).normalized();
  const Eigen::Vector3d u = Eigen::Vector3d(1, -1, 0).normalized(), w = n.cross(u);
  Mesh grid;
  grid.source = "grid";
  constexpr int kCells = 8;
  for (int i = 0; i <= kCells; ++i) {
    for (int j = 0; j <= kCells; ++j) grid.vertices.push_back((i - kCells / 2) * 0.5 * u + (j - kCells / 2) * 0.5 * w);
  }
  for (std::uint32_t i = 0; i < kCells; ++i) {
    for (std::uint32_t j = 0; j < kCells; ++j) {
      const std::uint32_t c = i * (kCells + 1) + j;
      grid.triangles.push_back({c, c + kCells + 1, c + 1});
      grid.triangles.push_back({c + 1, c + kCells + 1, c + kCells + 2});
    }
  }
  Mesh standing;
  standing.source = "standing";
  const Eigen::Vector3d a(1, -0.45, -0.45), b(-0.45, 1, -0.45);  // each 0.1 / sqrt(3) above the plane
  standing.vertices = {a, b, 0.5 * (a + b) + 2.0 * n};
  standing.triangles = {{0, 1, 2}};
  const auto box_lo = a.cwiseMin(b);
  ASSERT_LT(box_lo.sum(), 0.0) << "the triangle's box reaches below the grid's plane";
  QueryRequest request;  // interference
  const QueryResult r = query(*build_model(grid), Pose{}, *build_model(standing), Pose{}, request);
  EXPECT_TRUE(r.contacts.empty());
  EXPECT_EQ(r.stats.leaf_tests, 0u) << "the corners refused every pair of leaves";
}

/// The leaves (triangle ids) below BVH node i.
std::vector<std::uint32_t> triangles_below(const ModelData& m, std::uint32_t i) {
  std::vector<std::uint32_t> out, todo{i};
  while (!todo.empty()) {
    const BvhNode& n = m.nodes[todo.back()];
    todo.pop_back();
    if (n.is_leaf()) {
      out.push_back(n.index);
    } else {
      todo.push_back(n.index);
      todo.push_back(n.index + 1);
    }
  }
  return out;
}

TEST(WideTest, NeverRefusesASlotAboveAKeptPair) {
  const auto a = build_model(make_torus(1.0, 0.35, 16, 10));
  const auto b = build_model(sphere_with_slivers(20));
  std::mt19937_64 rng(7);
  long checked = 0, refused = 0;
  for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity}) {
    QueryRequest request;
    request.kind = kind;
    request.tolerance = kind == QueryKind::proximity ? 0.03 : 0.0;
    for (int p = 0; p < 12; ++p) {
      const PairContext ctx(*a, Pose{}, *b, test::random_pose(rng, 0.9), request);
      walk(ctx, wide_lanes(ctx), 5000, [&](NodePair n, const WideVisit& v, unsigned pass) {
        for (int k = 0; k < v.node->count(); ++k) {
          if ((pass >> k & 1u) != 0) continue;
          const NodePair child = v.child(k, n);
          const std::vector<std::uint32_t> ta = triangles_below(ctx.a(), child.a), tb = triangles_below(ctx.b(), child.b);
          if (ta.size() * tb.size() > 4000) continue;
          ++refused;
          std::vector<Candidate> out;
          for (const std::uint32_t i : ta) {
            for (const std::uint32_t j : tb) ctx.leaf_test(i, j, out);
          }
          checked += static_cast<long>(ta.size() * tb.size());
          EXPECT_TRUE(out.empty()) << "a refused slot holds a kept pair: " << out.front().tri_a << ", " << out.front().tri_b;
        }
      });
    }
  }
  EXPECT_GT(refused, 500);
  EXPECT_GT(checked, 50000);
}

}  // namespace
}  // namespace caliber::narrow

namespace caliber::narrow {
namespace {

// A mesh whose extent about its own volume origin is below float's range (1e-36 from the origin,
// 1e-44 across: every coordinate accepted): the float stage is off, the boxes alone prune, and the
// query is the brute force's.
TEST(WideTest, AScaleBelowFloatsRangeLeavesTheBoxesAlone) {
  Mesh grid = make_plate(1.0, 0.1, 4);
  for (Eigen::Vector3d& v : grid.vertices) v = Eigen::Vector3d::Constant(1e-36) + 1e-44 * v;
  const auto a = build_model(grid), b = build_model(grid);
  QueryRequest request;
  const Pose pose_b;  // the same place (a translation or a turn would move it by far more than it is large)
  const PairContext ctx(*a, Pose{}, *b, pose_b, request);
  const detail::WideLanes lanes = wide_lanes(ctx);
  EXPECT_FALSE(lanes.floats);
  EXPECT_TRUE(std::isfinite(lanes.unit_f)) << "no conversion out of float's range";
  const QueryResult got = query(*a, Pose{}, *b, pose_b, request);
  test::expect_identical(got, query_brute_force(*a, Pose{}, *b, pose_b, request), "below float's range");
  EXPECT_FALSE(got.contacts.empty());
}

}  // namespace
}  // namespace caliber::narrow
