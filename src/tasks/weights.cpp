#include "tasks/weights.h"

#include <algorithm>
#include <cmath>

namespace caliber::tasks {

double apriori_weight(const narrow::PairContext& ctx, narrow::NodePair n) {
  const narrow::PairContext::SideA a = ctx.prepare_a(n.a);
  const narrow::PairContext::SideB b = ctx.prepare_b(n.b);
  double dist2 = 0.0;
  for (int i = 0; i < 3; ++i) dist2 += (a.center[i] - b.center[i]) * (a.center[i] - b.center[i]);
  const double d = reach(ctx.request());
  // Overlap depth: the smaller of the spheres' and the boxes' (on the six face axes, the least
  // penetration); thin parts have loose spheres but tight boxes.
  double overlap = std::max(0.0, a.radius + b.radius + d - std::sqrt(dist2));
  for (int i = 0; i < 3; ++i) {
    overlap = std::min(overlap, std::max(0.0, a.half[i] + b.reach_on_a[i] + d - std::abs(b.box_in_a[i] - a.box[i])));
    overlap = std::min(overlap, std::max(0.0, b.half[i] + a.reach_on_b[i] + d - std::abs(b.box[i] - a.box_in_b[i])));
  }
  const double pa = ctx.a().nodes[n.a].count, pb = ctx.b().nodes[n.b].count;
  const double na = a.radius > 0.0 ? pa * std::min(1.0, overlap / (2.0 * a.radius)) : pa;
  const double nb = b.radius > 0.0 ? pb * std::min(1.0, overlap / (2.0 * b.radius)) : pb;
  return 1.0 + 2.0 * (na + nb);
}

}  // namespace caliber::tasks
