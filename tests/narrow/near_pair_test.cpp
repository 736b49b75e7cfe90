// PairContext::near_a_pair and near_b_pair (a node's two children prepared for the distance bound
// in two SSE2 lanes) against near_a and near_b on each child: the same values, bit for bit, on
// every internal node of models with sloped nodes (a normal cone), nodes without one (degenerate
// triangles only), and turned and unturned lateral axes, under random poses.

#include <cstring>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/pair_context.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

/// Every field of two prepared nodes (NearA or NearB) with the same bits.
template <class Near>
bool same(const Near& x, const Near& y) {
  static_assert(sizeof(x.box) == 3 * sizeof(double));
  bool ok = x.index == y.index;
  for (int i = 0; i < 3; ++i) {
    ok &= same_bits(x.box[i], y.box[i]) && same_bits(x.half[i], y.half[i]) && same_bits(x.frame.center[i], y.frame.center[i]) &&
          same_bits(x.frame.half[i], y.frame.half[i]);
    for (int k = 0; k < 3; ++k) ok &= same_bits(x.frame.axis[i][k], y.frame.axis[i][k]);
  }
  return ok;
}
bool other_side_same(const PairContext::NearA& x, const PairContext::NearA& y) {
  bool ok = true;
  for (int i = 0; i < 3; ++i) ok &= same_bits(x.box_in_b[i], y.box_in_b[i]) && same_bits(x.reach_on_b[i], y.reach_on_b[i]);
  return ok;
}
bool other_side_same(const PairContext::NearB& x, const PairContext::NearB& y) {
  bool ok = true;
  for (int i = 0; i < 3; ++i) ok &= same_bits(x.box_in_a[i], y.box_in_a[i]) && same_bits(x.reach_on_a[i], y.reach_on_a[i]);
  return ok;
}

/// A torus with a cluster of degenerate triangles (collinear corners) of its own, far enough that
/// whole subtrees hold nothing else: nodes without a normal cone.
Mesh torus_with_slivers() {
  Mesh m = make_torus(1.0, 0.35, 24, 16);
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (int i = 0; i < 40; ++i) {
    const double x = 3.0 + 0.05 * i;
    m.vertices.emplace_back(x, 0.0, 0.0);
    m.vertices.emplace_back(x + 0.02, 0.01, 0.0);
    m.vertices.emplace_back(x + 0.04, 0.02, 0.0);
    const std::uint32_t v = base + 3 * static_cast<std::uint32_t>(i);
    m.triangles.push_back({v, v + 1, v + 2});
  }
  return m;
}

TEST(NearPair, SameAsOneNodeAtATime) {
  // A's model with every third node's turn zeroed (the build turns nearly every node; the two
  // forms must agree on a zero turn too, which leaves the axes as they are: no longer the
  // build's frame, but the same computation).
  auto turned_off = std::make_shared<Model>(*build_model(torus_with_slivers()));
  for (std::size_t k = 0; k < turned_off->laterals.size(); k += 3) turned_off->laterals[k].turn[0] = turned_off->laterals[k].turn[1] = 0;
  const std::shared_ptr<const Model> a = turned_off;
  const auto b = build_model(make_box(0.6, 0.4, 0.3, 10));
  std::mt19937_64 rng(20261125);
  QueryRequest request;
  request.kind = QueryKind::distance;
  long compared = 0, differing = 0, flat = 0, turned = 0, unturned = 0;
  for (int p = 0; p < 6; ++p) {
    const PairContext ctx(*a, test::random_pose(rng, 0.5), *b, test::random_pose(rng, 2.0), request);
    // A's nodes through near_a_pair, then B's through near_b_pair.
    for (const Model* m : {a.get(), b.get()}) {
      const PairContext& c = ctx;
      for (const BvhNode& n : m->nodes) {
        if (n.is_leaf()) continue;
        for (int i = 0; i < 2; ++i) {
          const std::uint32_t child = n.index + static_cast<std::uint32_t>(i);
          const float* axis = m->filters[child].cone_axis;
          flat += axis[0] == 0.0f && axis[1] == 0.0f && axis[2] == 0.0f;
          const auto* turn = m->laterals[child].turn;
          (turn[0] == 0 && turn[1] == 0 ? unturned : turned) += 1;
        }
        bool ok = true;
        if (m == a.get()) {
          PairContext::NearA x0, x1;
          c.near_a_pair(n.index, x0, x1);
          ok = same(x0, c.near_a(n.index)) && same(x1, c.near_a(n.index + 1)) && other_side_same(x0, c.near_a(n.index)) &&
               other_side_same(x1, c.near_a(n.index + 1));
        } else {
          PairContext::NearB x0, x1;
          c.near_b_pair(n.index, x0, x1);
          ok = same(x0, c.near_b(n.index)) && same(x1, c.near_b(n.index + 1)) && other_side_same(x0, c.near_b(n.index)) &&
               other_side_same(x1, c.near_b(n.index + 1));
        }
        ++compared;
        if (!ok && ++differing <= 5) ADD_FAILURE() << "pose " << p << ": the children of node " << &n - m->nodes.data() << " differ";
      }
    }
  }
  EXPECT_EQ(differing, 0);
  EXPECT_GT(compared, 1000);
  EXPECT_GT(flat, 10) << "nodes without a normal cone take the box's frame";
  EXPECT_GT(turned, 100);
  EXPECT_GT(unturned, 100);
}

}  // namespace
}  // namespace caliber::narrow
