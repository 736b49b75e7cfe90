// The four-pair node test's float pre-decision (node_test_float.cpp) against the double form on the
// inputs that stretch it: a mesh far from its own origin (the volumes' own origin), triangles
// without a normal (nodes without a slab), a tolerance far larger than the meshes: wherever the
// float test is sure, the double form's bits, and few visits left to the double form.

#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/cd_tree.h"
#include "narrow/pair_context.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

struct Tally {
  long visits = 0, unsure = 0, differing = 0;
};

/// Walks the CD tree of a and b (A at pose_a, B at pose_b) below the root where both sides
/// descend, into the children the double form passes, comparing the float bits with it.
void compare_forms(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request,
                   Tally& tally) {
  const PairContext ctx(a, pose_a, b, pose_b, request);
  const detail::NodeLanes lanes = ctx.node_lanes();
  ASSERT_TRUE(lanes.floats);
  std::vector<NodePair> work{{0, 0}};
  for (std::size_t w = 0; w < work.size() && w < 20000; ++w) {
    const BvhNode& na = data(a).nodes[work[w].a];
    const BvhNode& nb = data(b).nodes[work[w].b];
    if (na.is_leaf() || nb.is_leaf()) continue;
    int pass = 0, unsure = 0;
    detail::node_within_2x2_float_bits(ctx.node_test_frame(), lanes, na.index, na.index + 1, nb.index, nb.index + 1, pass,
                                       unsure);
    const int want = detail::node_within_2x2_double(ctx.node_test_frame(), lanes, na.index, na.index + 1, nb.index, nb.index + 1);
    ++tally.visits;
    tally.unsure += unsure != 0;
    if ((pass & ~unsure) != (want & ~unsure)) ++tally.differing;
    for (std::uint32_t k = 0; k < 4; ++k) {
      if ((want >> k) & 1) work.push_back(NodePair{na.index + k / 2, nb.index + k % 2});
    }
  }
}

/// A torus moved by `offset`, with `degenerate` triangles more: each a zero-area sliver on three
/// vertices of one of its triangles (a corner repeated), so that their leaves have no slab.
Mesh torus_with(const Eigen::Vector3d& offset, int degenerate) {
  Mesh m = make_torus(1.0, 0.35, 40, 24);
  for (Eigen::Vector3d& v : m.vertices) v += offset;
  const std::size_t n = m.triangles.size();
  for (int i = 0; i < degenerate; ++i) {
    const auto& t = m.triangles[(static_cast<std::size_t>(i) * 7) % n];
    m.triangles.push_back({t[0], t[1], t[0]});
  }
  return m;
}

TEST(NodeTestFloat, SureWhereverTheDoubleFormIsAndRarelyInDoubt) {
  const Eigen::Vector3d far(2.5e6, -1.5e6, 4e5);
  const auto plain = build_model(torus_with(Eigen::Vector3d::Zero(), 0));
  const auto far_away = build_model(torus_with(far, 0));
  const auto slivers = build_model(torus_with(Eigen::Vector3d::Zero(), 600));
  ASSERT_NE(data(*far_away).origin, Eigen::Vector3d::Zero()) << "the far mesh has volumes about an origin of its own";
  std::mt19937_64 rng(20261202);
  struct Case {
    const char* name;
    const Model& model;
    Eigen::Vector3d at;
    QueryKind kind;
    double tolerance;
  };
  const Case cases[] = {
      {"far from its origin", *far_away, far, QueryKind::interference, 0.0},
      {"degenerate triangles", *slivers, Eigen::Vector3d::Zero(), QueryKind::interference, 0.0},
      {"degenerate triangles, proximity", *slivers, Eigen::Vector3d::Zero(), QueryKind::proximity, 0.02},
      {"tolerance beyond the meshes", *plain, Eigen::Vector3d::Zero(), QueryKind::proximity, 30.0},
  };
  for (const Case& c : cases) {
    Tally tally;
    for (int p = 0; p < 8; ++p) {
      // Both copies about the same place, B turned and moved by a fraction of the torus's size.
      Pose pose_b = test::random_pose(rng, 0.6);
      pose_b.translation -= pose_b.rotation_matrix() * c.at - c.at;  // turned about c.at
      QueryRequest request;
      request.kind = c.kind;
      request.tolerance = c.tolerance;
      compare_forms(c.model, Pose{}, c.model, pose_b, request, tally);
    }
    EXPECT_EQ(tally.differing, 0) << c.name;
    EXPECT_GT(tally.visits, 1000) << c.name;
    // A slack sized by the absolute scale (far from the origin) or refusing nothing sure where a
    // node has no slab would leave most visits in doubt.
    EXPECT_LT(tally.unsure * 10, tally.visits) << c.name << ": " << tally.unsure << " of " << tally.visits << " in doubt";
  }
}

}  // namespace
}  // namespace caliber::narrow
