// How well the a priori weight predicts the work below a CD node: for every pair of each scene at
// a few steps, a full traversal records, for each CD node whose test passed, its a priori weight
// (plans::apriori_weight) and the node tests its subtree took; prints the Pearson correlation of
// their logarithms over the nodes with at least 10, 100 and 1,000 tests. Deterministic (counts,
// not times). Calibration only compares weights, so the correlation of logs is what matters.
//   bench_weight_estimates SCENE.json... [--steps K]   (K sampled steps, 10 apart; default 3)

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "caliber/world.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"
#include "plans/weights.h"

namespace {

struct Node {
  double weight;  // a priori estimate
  double tests;   // node tests of its subtree, its own included
};

/// Node tests below CD node n (whose test passed), recording n and every passing node below it.
double below(const caliber::narrow::PairContext& ctx, caliber::narrow::NodePair n, std::vector<Node>& out) {
  const caliber::ModelData& a = ctx.a();
  const caliber::ModelData& b = ctx.b();
  if (a.nodes[n.a].is_leaf() && b.nodes[n.b].is_leaf()) return 0.0;
  caliber::narrow::NodePair kids[caliber::narrow::kMaxChildren];
  const int count = caliber::narrow::cd_children(ctx, n, kids);
  double tests = 0.0;
  for (int k = 0; k < count; ++k) {
    tests += 1.0;
    if (caliber::narrow::child_test(ctx, n, kids[k])) tests += below(ctx, kids[k], out);
  }
  out.push_back({caliber::plans::apriori_weight(ctx, n), tests + 1.0});
  return tests;
}

double log_pearson(const std::vector<Node>& nodes, double at_least, std::size_t& used) {
  double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (const Node& v : nodes) {
    if (v.tests < at_least) continue;
    const double x = std::log(v.weight), y = std::log(v.tests);
    n += 1;
    sx += x;
    sy += y;
    sxx += x * x;
    syy += y * y;
    sxy += x * y;
  }
  used = static_cast<std::size_t>(n);
  const double cov = sxy - sx * sy / n, vx = sxx - sx * sx / n, vy = syy - sy * sy / n;
  return n > 2 && vx > 0 && vy > 0 ? cov / std::sqrt(vx * vy) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenes;
  int steps = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--steps" && i + 1 < argc) {
      steps = std::atoi(argv[++i]);
    } else {
      scenes.push_back(arg);
    }
  }
  if (scenes.empty() || steps < 1) {
    std::fprintf(stderr, "usage: bench_weight_estimates SCENE.json... [--steps K]\n");
    return 2;
  }
  try {
    for (const std::string& file : scenes) {
      const caliber::World world(caliber::load_scene(file));
      std::vector<Node> nodes;
      for (int k = 0; k < steps * 10; k += 10) {
        const caliber::Frame frame = world.frame(k);
        for (const caliber::ObjectPair& t : frame.pairs) {
          const caliber::narrow::PairContext ctx(*frame.models[t.a], frame.poses[t.a], *frame.models[t.b], frame.poses[t.b],
                                                 frame.request);
          if (ctx.node_test(0, 0)) below(ctx, caliber::narrow::NodePair{0, 0}, nodes);
        }
      }
      std::printf("%s (steps 0..%d, every 10th):", world.scene().name.c_str(), (steps - 1) * 10);
      for (const double at_least : {10.0, 100.0, 1000.0}) {
        std::size_t used = 0;
        const double r = log_pearson(nodes, at_least, used);
        std::printf("  >= %g tests: r %.3f (%zu nodes)", at_least, r, used);
      }
      std::printf("\n");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_weight_estimates: %s\n", e.what());
    return 2;
  }
  return 0;
}
