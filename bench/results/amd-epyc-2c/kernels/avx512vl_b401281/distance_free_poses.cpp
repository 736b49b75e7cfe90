// Distance (unbounded) over the free poses of bench_batch's path (those whose first hit finds
// nothing), oriented boxes kept as bench_batch keeps them. Prints the free poses, a hash of every
// answer, node and leaf tests a query, and the median of R passes in microseconds a query.
// Usage (from the repository root): PROGRAM N R
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <vector>
#include <cstring>
#include <algorithm>
#include <Eigen/Geometry>
#include <valgrind/callgrind.h>
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
using namespace caliber;
static void bc(const Mesh& m, Eigen::Vector3d& c, double& d) {
  Eigen::Vector3d lo = m.vertices[0], hi = lo;
  for (auto& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  c = 0.5 * (lo + hi);
  d = (hi - lo).norm();
}
int main(int argc, char** argv) {
  int n = argc > 1 ? atoi(argv[1]) : 2000;
  int reps = argc > 2 ? atoi(argv[2]) : 3;
  int every = argc > 3 ? atoi(argv[3]) : 1;
  Mesh a = load_mesh("data/meshes/bunny00.off"), b = load_mesh("data/meshes/turbine.off");
  scale_mesh(b, 0.3);
  BuildOptions bo;
  bo.oriented_boxes = true;
  auto A = build_model(a, bo), B = build_model(b, bo);
  Eigen::Vector3d ca, cb;
  double da, db;
  bc(a, ca, da);
  bc(b, cb, db);
  Eigen::Vector3d from = ca + Eigen::Vector3d(-0.45, -0.1, 0.05) * da, to = ca + Eigen::Vector3d(0.45, 0.1, -0.05) * da;
  Eigen::Vector3d axis = Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  std::vector<Pose> all, fr;
  for (int i = 0; i < n; ++i) {
    double s = n > 1 ? double(i) / (n - 1) : 0;
    Eigen::Quaterniond q(Eigen::AngleAxisd(3.0 * std::numbers::pi * s, axis));
    Eigen::Vector3d t = from + s * (to - from) - q * cb;
    all.push_back(Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z()));
  }
  QueryRequest first;
  first.max_pairs = 1;
  for (auto& p : all)
    if (query(*A, Pose{}, *B, p, first).contacts.empty()) fr.push_back(p);
  std::vector<Pose> use;
  for (size_t i = 0; i < fr.size(); i += every) use.push_back(fr[i]);
  QueryRequest d;
  d.kind = QueryKind::distance;
  d.tolerance = kUnbounded;
  double sum = 0;
  unsigned long long h = 0, nodes = 0, leaves = 0;
  std::vector<double> ts;
  for (int r = 0; r < reps; ++r) {
    if (r == reps - 1) CALLGRIND_START_INSTRUMENTATION;
    auto t0 = std::chrono::steady_clock::now();
    for (auto& p : use) {
      auto res = query(*A, Pose{}, *B, p, d);
      if (r == 0) {
        auto& c = res.contacts.front();
        sum += c.distance;
        h = h * 1000003 + c.tri_a * 7 + c.tri_b;
        double x[6] = {c.point_a.x(), c.point_a.y(), c.point_a.z(), c.point_b.x(), c.point_b.y(), c.point_b.z()};
        for (double v : x) {
          unsigned long long u;
          memcpy(&u, &v, 8);
          h ^= u + 0x9e3779b97f4a7c15ull + (h << 6);
        }
        nodes += res.stats.node_tests;
        leaves += res.stats.leaf_tests;
      }
    }
    if (r == reps - 1) CALLGRIND_STOP_INSTRUMENTATION;
    ts.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / use.size());
  }
  std::sort(ts.begin(), ts.end());
  printf("free %zu used %zu sum %.17g hash %llx node/q %.1f leaf/q %.1f  median %.2f us/q\n", fr.size(), use.size(), sum, h,
         double(nodes) / use.size(), double(leaves) / use.size(), ts[ts.size() / 2]);
}
