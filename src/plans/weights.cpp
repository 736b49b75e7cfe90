#include "plans/weights.h"

#include <algorithm>
#include <cmath>

#include "parallel/executor.h"

namespace caliber::plans {

namespace {

/// The share of one node's box, along one axis, inside the other node's box grown by d: `own` is
/// its half-extent along the axis, `other` the other's (grown), `pen` how far the two intervals
/// overlap past touching (own + other - |distance of the centres|). A flat box (own 0) is in or out.
double axis_share(double pen, double own, double other) {
  if (pen <= 0.0) return 0.0;
  if (own <= 0.0) return 1.0;
  return std::min(1.0, std::min(pen, 2.0 * other) / (2.0 * own));
}

/// The share of a node (sphere radius r) inside a depth o of the other: o / 2r, at most 1.
double depth_share(double o, double r) { return r > 0.0 ? std::min(1.0, o / (2.0 * r)) : (o > 0.0 ? 1.0 : 0.0); }

}  // namespace

double apriori_weight(const narrow::PairContext& ctx, narrow::NodePair n) {
  const narrow::PairContext::SideA a = ctx.prepare_a(n.a);
  const narrow::PairContext::SideB b = ctx.prepare_b(n.b);
  double dist2 = 0.0;
  for (int i = 0; i < 3; ++i) dist2 += (a.center[i] - b.center[i]) * (a.center[i] - b.center[i]);
  const double d = reach(ctx.request());
  const double lens = std::max(0.0, a.radius + b.radius + d - std::sqrt(dist2));
  double depth = lens;  // least penetration, spheres and six box axes
  double axes_a = depth_share(lens, a.radius), axes_b = depth_share(lens, b.radius);  // least share per axis
  for (int i = 0; i < 3; ++i) {
    const double pen_a = a.half[i] + b.reach_on_a[i] + d - std::abs(b.box_in_a[i] - a.box[i]);  // A's axis i
    const double pen_b = b.half[i] + a.reach_on_b[i] + d - std::abs(b.box[i] - a.box_in_b[i]);  // B's axis i
    depth = std::min({depth, std::max(0.0, pen_a), std::max(0.0, pen_b)});
    axes_a =
        std::min({axes_a, axis_share(pen_a, a.half[i], b.reach_on_a[i] + d), axis_share(pen_b, a.reach_on_b[i], b.half[i] + d)});
    axes_b =
        std::min({axes_b, axis_share(pen_b, b.half[i], a.reach_on_b[i] + d), axis_share(pen_a, b.reach_on_a[i], a.half[i] + d)});
  }
  const double share_a = std::sqrt(depth_share(depth, a.radius) * axes_a);
  const double share_b = std::sqrt(depth_share(depth, b.radius) * axes_b);
  const double pa = ctx.a().nodes[n.a].count, pb = ctx.b().nodes[n.b].count;
  return 1.0 + 2.0 * (pa * share_a + pb * share_b);
}

std::vector<double> root_weights(narrow::PairContexts contexts) {
  std::vector<double> root(contexts.size());
  parallel::parallel_for_each(0, contexts.size(), [&](std::size_t i) { root[i] = apriori_weight(contexts[i], {0, 0}); });
  return root;
}

}  // namespace caliber::plans
