#include "tasks/calibration.h"

#include <algorithm>
#include <queue>

#include "tasks/weights.h"

namespace caliber::tasks {

Verdict classify(double weight, double omega, double eps) {
  if (weight > omega + eps) return Verdict::split;
  if (weight < omega - eps) return Verdict::cart;
  return Verdict::keep;
}

double caliber_threshold(double total, double beta, int threads) {
  const double omega = total / (beta * static_cast<double>(threads));
  return omega > 0.0 ? omega : 1e-300;
}

std::vector<RunTask> merge_cart(std::vector<Root> cart, double omega) {
  std::sort(cart.begin(), cart.end(), [](const Root& x, const Root& y) {
    if (x.weight != y.weight) return x.weight < y.weight;
    if (x.pair != y.pair) return x.pair < y.pair;
    if (x.node.a != y.node.a) return x.node.a < y.node.a;
    return x.node.b < y.node.b;
  });
  std::vector<RunTask> tasks;
  std::size_t light = 0, heavy = cart.size();
  while (light < heavy) {
    RunTask task;
    task.roots.push_back(cart[--heavy]);
    task.weight = cart[heavy].weight;
    while (task.weight < omega && light < heavy) {
      task.roots.push_back(cart[light]);
      task.weight += cart[light++].weight;
    }
    tasks.push_back(std::move(task));
  }
  return tasks;
}

SplitResult split_task(const narrow::PairContext& ctx, std::uint32_t pair, double root_weight, double scale,
                       double omega, double eps) {
  struct Entry {
    double weight;
    narrow::NodePair node;
    bool operator<(const Entry& o) const {  // max-heap on weight; ties: lower node ids first
      if (weight != o.weight) return weight < o.weight;
      if (node.a != o.node.a) return node.a > o.node.a;
      return node.b > o.node.b;
    }
  };
  SplitResult out;
  std::priority_queue<Entry> queue;
  queue.push(Entry{root_weight, narrow::NodePair{0, 0}});
  narrow::NodePair kids[4];
  while (!queue.empty()) {
    out.queue_peak = std::max(out.queue_peak, queue.size());
    const Entry e = queue.top();
    queue.pop();
    ++out.stats.node_tests;
    if (!ctx.node_test(e.node.a, e.node.b)) continue;
    const BvhNode& a = ctx.a().nodes[e.node.a];
    const BvhNode& b = ctx.b().nodes[e.node.b];
    if (a.is_leaf() && b.is_leaf()) {
      ++out.stats.leaf_tests;
      ctx.leaf_test(a.index, b.index, out.candidates);
      continue;
    }
    switch (classify(e.weight, omega, eps)) {
      case Verdict::split: {
        const int count = narrow::cd_children(ctx.a(), ctx.b(), e.node, kids);
        for (int i = 0; i < count; ++i) queue.push(Entry{scale * apriori_weight(ctx, kids[i]), kids[i]});
        break;
      }
      case Verdict::keep:
        out.roots.push_back(Root{pair, e.node, true, e.weight});
        break;
      case Verdict::cart:
        out.cart.push_back(Root{pair, e.node, true, e.weight});
        break;
    }
  }
  return out;
}

}  // namespace caliber::tasks
