// The swept query's local advancement: how far a pair can move from its poses at a query without
// coming within the margin, bounded pair of triangles by pair of triangles along the direction
// that separates them, instead of by the models' fastest point against their closest distance.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "narrow/cd_tree.h"
#include "narrow/sweep_bounds.h"

namespace caliber::narrow {
namespace {

/// Rounding up: a speed a hair too high costs a step, a hair too low a miss.
constexpr double kUp = 1.0 + 1e-12;

/// The largest distance of a node's sphere from its model's origin (its object frame).
double node_reach(const ModelData& m, std::uint32_t i) {
  const BvhNode& n = m.nodes[i];
  const Eigen::Vector3d c = m.origin + Eigen::Vector3d(n.center[0], n.center[1], n.center[2]);
  return (c.norm() + n.radius) * kUp;
}

/// The largest distance of a triangle's vertex from its model's origin.
double triangle_reach(const Mesh& mesh, std::uint32_t t) {
  double r2 = 0.0;
  for (const std::uint32_t v : mesh.triangles[t]) r2 = std::max(r2, mesh.vertices[v].squaredNorm());
  return std::sqrt(r2) * kUp;
}

/// A lower bound on the time any pair of triangles below nodes ia and ib needs to come within the
/// margin: the largest of, along each of the seven directions (the six box axes and any), the
/// nodes' separation there over the speed at which it can shrink (the translation along it, or
/// whole, and each node's turn about its model's origin). The boxes hold the triangles, so what
/// separates the boxes separates every pair below; infinity when groups forbid every pair.
double node_advance(const PairContext& ctx, const LocalMotion& m, const Eigen::Vector3d& along_b, std::uint32_t ia,
                    std::uint32_t ib) {
  PairContext::NearA a;
  PairContext::NearB b;
  ctx.near(ia, a);
  ctx.near(ib, b);
  const double gap = ctx.gap(a, b, kUnbounded);
  if (gap == kUnbounded) return gap;
  const double turns = m.turn_a * node_reach(ctx.a(), ia) + m.turn_b * node_reach(ctx.b(), ib);
  double best = 0.0;
  const auto consider = [&](double separation, double rate) {
    const double apart = separation - (ctx.reach_for(std::abs(separation)) - std::abs(separation)) - m.margin;
    if (!(apart > 0.0)) return;
    const double speed = (rate + turns) * kUp;
    best = std::max(best, speed > 0.0 ? apart / speed : kUnbounded);
  };
  consider(gap, m.translation.norm());
  for (int k = 0; k < 3; ++k) {
    consider(std::abs(b.box_in_a[k] - a.box[k]) - a.half[k] - b.reach_on_a[k], std::abs(m.translation[k]));
    consider(std::abs(b.box[k] - a.box_in_b[k]) - b.half[k] - a.reach_on_b[k], std::abs(along_b[k]));
  }
  return best;
}

}  // namespace

/// The time a pair of triangles needs to come within the margin: their separation along the
/// direction between their closest points (every vertex of B's beyond every vertex of A's by at
/// least that much, computed from the vertices themselves, so the direction need not be exact)
/// over the speed at which that separation can shrink.
double pair_advance(const PairContext& ctx, const LocalMotion& m, std::uint32_t ta, std::uint32_t tb) {
  Candidate c;
  if (!ctx.leaf_distance(ta, tb, kUnbounded, c)) return std::numeric_limits<double>::infinity();  // groups
  const Eigen::Vector3d between = c.point_b - c.point_a;
  const double length = between.norm();
  if (!(length > 0.0)) return 0.0;
  const Eigen::Vector3d n = between / length;
  double low_b = std::numeric_limits<double>::infinity(), high_a = -std::numeric_limits<double>::infinity();
  const Mesh& mesh_a = ctx.a().mesh;
  for (int k = 0; k < 3; ++k) {
    low_b = std::min(low_b, n.dot(ctx.b_vertex(tb, k)));
    high_a = std::max(high_a, n.dot(mesh_a.vertices[mesh_a.triangles[ta][k]]));
  }
  const double apart = low_b - high_a - m.margin;
  if (!(apart > 0.0)) return 0.0;
  // |n| is 1 within a few ulps: kUp covers it on every term.
  const double speed =
      (std::abs(n.dot(m.translation)) + m.turn_a * triangle_reach(mesh_a, ta) + m.turn_b * triangle_reach(ctx.b().mesh, tb)) *
      kUp;
  return speed > 0.0 ? apart / speed : std::numeric_limits<double>::infinity();
}

double local_advance(const PairContext& ctx, const LocalMotion& m, double cap, std::uint64_t budget) {
  double best = cap;
  const ModelData& a = ctx.a();
  const ModelData& b = ctx.b();
  const Eigen::Vector3d along_b = ctx.rotation_b_to_a().transpose() * m.translation;  // in B's frame
  std::vector<NodePair> stack{NodePair{0, 0}};
  while (!stack.empty() && best > 0.0) {
    if (budget-- == 0) return 0.0;  // too much work for what it may gain: no advance of its own
    const NodePair p = stack.back();
    stack.pop_back();
    const BvhNode& na = a.nodes[p.a];
    const BvhNode& nb = b.nodes[p.b];
    if (na.is_leaf() && nb.is_leaf()) {
      best = std::min(best, pair_advance(ctx, m, na.index, nb.index));
      continue;
    }
    if (node_advance(ctx, m, along_b, p.a, p.b) >= best) continue;
    bool descend_a, descend_b;
    cd_descend(na, nb, ctx.descend_alone_ratio(), descend_a, descend_b);
    for (std::uint32_t i = 0; i < (descend_a ? 2u : 1u); ++i) {
      for (std::uint32_t j = 0; j < (descend_b ? 2u : 1u); ++j) {
        stack.push_back(NodePair{descend_a ? na.index + i : p.a, descend_b ? nb.index + j : p.b});
      }
    }
  }
  return std::max(best, 0.0);
}

}  // namespace caliber::narrow
