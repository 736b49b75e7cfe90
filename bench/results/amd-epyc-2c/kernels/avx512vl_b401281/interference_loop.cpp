// Interference on the five posed pairs of bench_embree_compare (case 0-4), warm: one call, then
// R timed calls; prints contacts, node and leaf tests, and the median in milliseconds.
// Usage (from the repository root): PROGRAM CASE R
#include <chrono>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>
#include <algorithm>
#include <Eigen/Geometry>
#include <valgrind/callgrind.h>
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
using namespace caliber;
static void box_center(const Mesh& m, Eigen::Vector3d& c, double& d) {
  Eigen::Vector3d lo = m.vertices[0], hi = lo;
  for (auto& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  c = 0.5 * (lo + hi);
  d = (hi - lo).norm();
}
struct Case {
  const char *name, *a, *b;
  double ang;
  Eigen::Vector3d axis, off;
};
int main(int argc, char** argv) {
  std::vector<Case> cs = {{"bunny", "bunny00.off", "bunny00.off", 90, {-1, 0, 1}, {0.06, -0.2, -0.1}},
                          {"armadillo", "armadillo.off", "armadillo.off", 45, {0, 1, 1}, {0.2, 0.04, 0.03}},
                          {"elephant", "refined_elephant.off", "refined_elephant.off", 120, {-1, 1, 2}, {0.12, 0.02, 0.13}},
                          {"turbine", "turbine.off", "turbine.off", 45, {1, -1, 1}, {0.03, -0.07, -0.15}},
                          {"bunnyeleph", "bunny00.off", "refined_elephant.off", 45, {-1, 1, 2}, {-0.14, 0.16, 0.12}}};
  int which = argc > 1 ? atoi(argv[1]) : 0;
  int reps = argc > 2 ? atoi(argv[2]) : 1;
  std::string dir = "data/meshes/";
  const char* md = getenv("MESHES");
  if (md) dir = md;
  auto& c = cs[which];
  Mesh ma = load_mesh(dir + c.a), mb = load_mesh(dir + c.b);
  Eigen::Vector3d ca, cb;
  double da, db;
  box_center(ma, ca, da);
  box_center(mb, cb, db);
  Eigen::Quaterniond q(Eigen::AngleAxisd(c.ang * std::numbers::pi / 180, c.axis.normalized()));
  Eigen::Vector3d t = ca + c.off * da - q * cb;
  Pose pb = Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
  auto A = build_model(ma);
  auto B = build_model(mb);
  QueryRequest req;
  Pose id;
  auto r = query(*A, id, *B, pb, req);
  std::vector<double> ts;
  CALLGRIND_START_INSTRUMENTATION;
  for (int i = 0; i < reps; ++i) {
    auto t0 = std::chrono::steady_clock::now();
    r = query(*A, id, *B, pb, req);
    ts.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  CALLGRIND_STOP_INSTRUMENTATION;
  std::sort(ts.begin(), ts.end());
  printf("%s contacts %zu node %llu leaf %llu median %.3f ms\n", c.name, r.contacts.size(),
         (unsigned long long)r.stats.node_tests, (unsigned long long)r.stats.leaf_tests, ts[ts.size() / 2]);
}
