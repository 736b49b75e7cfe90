// Warm queries, timed in one process: built against a commit's libcaliber.a and public headers,
// run from the repository root.
//
//   warm_queries interference CASE R   the posed pair CASE (0-4) of bench_embree_compare: one
//                                      call, then R timed calls; contacts, node and leaf tests,
//                                      the median in ms
//   warm_queries distance N R          bench_batch's path of N poses (the scaled turbine through
//                                      the bunny), its free poses (the first hit finds nothing),
//                                      unbounded distance, oriented boxes kept as bench_batch keeps
//                                      them: R passes, the median in us a query
//   warm_queries first_hit N R         the same path, all N poses, max_pairs = 1
//
// The path's modes also print a hash of every answer (pair, distance and points) and the node and
// leaf tests a query of the first pass.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"

using namespace caliber;

namespace {

void box_center(const Mesh& m, Eigen::Vector3d& c, double& d) {
  Eigen::Vector3d lo = m.vertices[0], hi = lo;
  for (const Eigen::Vector3d& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  c = 0.5 * (lo + hi);
  d = (hi - lo).norm();
}

/// B's pose: turned by `degrees` about `axis` about its box center, which goes to A's box center
/// plus `offset` times A's box diagonal (bench_embree_compare's place(), bench_batch's path()).
Pose place(const Mesh& a, const Mesh& b, double degrees, const Eigen::Vector3d& axis, const Eigen::Vector3d& offset) {
  Eigen::Vector3d ca, cb;
  double da, db;
  box_center(a, ca, da);
  box_center(b, cb, db);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, axis.normalized()));
  const Eigen::Vector3d t = ca + offset * da - q * cb;
  return Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int interference(int which, int reps) {
  struct Case {
    const char *name, *a, *b;
    double degrees;
    Eigen::Vector3d axis, offset;
  };
  const Case cases[] = {{"bunny", "bunny00.off", "bunny00.off", 90, {-1, 0, 1}, {0.06, -0.2, -0.1}},
                        {"armadillo", "armadillo.off", "armadillo.off", 45, {0, 1, 1}, {0.2, 0.04, 0.03}},
                        {"elephant", "refined_elephant.off", "refined_elephant.off", 120, {-1, 1, 2}, {0.12, 0.02, 0.13}},
                        {"turbine", "turbine.off", "turbine.off", 45, {1, -1, 1}, {0.03, -0.07, -0.15}},
                        {"bunnyeleph", "bunny00.off", "refined_elephant.off", 45, {-1, 1, 2}, {-0.14, 0.16, 0.12}}};
  if (which < 0 || which > 4) return 2;
  const Case& c = cases[which];
  const Mesh ma = load_mesh(std::string("data/meshes/") + c.a), mb = load_mesh(std::string("data/meshes/") + c.b);
  const Pose pose_b = place(ma, mb, c.degrees, c.axis, c.offset);
  const auto a = build_model(ma), b = build_model(mb);
  const QueryRequest request;  // interference
  QueryResult r = query(*a, Pose{}, *b, pose_b, request);
  std::vector<double> ms;
  for (int i = 0; i < reps; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    r = query(*a, Pose{}, *b, pose_b, request);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::printf("%s contacts %zu node %llu leaf %llu median %.3f ms\n", c.name, r.contacts.size(),
              static_cast<unsigned long long>(r.stats.node_tests), static_cast<unsigned long long>(r.stats.leaf_tests),
              median(ms));
  return 0;
}

/// Mixes the bits of x into h.
void mix(unsigned long long& h, double x) {
  unsigned long long u;
  std::memcpy(&u, &x, sizeof u);
  h ^= u + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
}

int path(bool distance, int n, int reps) {
  Mesh a = load_mesh("data/meshes/bunny00.off"), b = load_mesh("data/meshes/turbine.off");
  scale_mesh(b, 0.3);
  BuildOptions build;
  build.oriented_boxes = true;
  const auto ma = build_model(a, build), mb = build_model(b, build);
  QueryRequest first;
  first.max_pairs = 1;
  QueryRequest request = first;
  if (distance) {
    request = QueryRequest{};
    request.kind = QueryKind::distance;
    request.tolerance = kUnbounded;
  }
  std::vector<Pose> poses;
  for (int i = 0; i < n; ++i) {
    const double s = n > 1 ? static_cast<double>(i) / (n - 1) : 0.0;
    const Eigen::Vector3d offset = Eigen::Vector3d(-0.45, -0.1, 0.05) + s * Eigen::Vector3d(0.9, 0.2, -0.1);
    const Pose p = place(a, b, 540.0 * s, Eigen::Vector3d(0.3, 1.0, 0.2), offset);
    if (!distance || query(*ma, Pose{}, *mb, p, first).contacts.empty()) poses.push_back(p);
  }
  unsigned long long hash = 0, nodes = 0, leaves = 0;
  std::vector<double> us;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const Pose& p : poses) {
      const QueryResult q = query(*ma, Pose{}, *mb, p, request);
      if (r != 0) continue;
      nodes += q.stats.node_tests;
      leaves += q.stats.leaf_tests;
      for (const Contact& c : q.contacts) {
        hash = hash * 1000003 + c.tri_a * 7 + c.tri_b;
        for (const double x :
             {c.distance, c.point_a.x(), c.point_a.y(), c.point_a.z(), c.point_b.x(), c.point_b.y(), c.point_b.z()})
          mix(hash, x);
      }
    }
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() /
                 static_cast<double>(poses.size()));
  }
  const auto per = [&](unsigned long long x) { return static_cast<double>(x) / static_cast<double>(poses.size()); };
  std::printf("%s poses %zu hash %llx node/q %.1f leaf/q %.1f median %.2f us/q\n", distance ? "distance" : "first_hit",
              poses.size(), hash, per(nodes), per(leaves), median(us));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: warm_queries interference CASE R | distance N R | first_hit N R\n");
    return 2;
  }
  const std::string mode = argv[1];
  const int x = std::atoi(argv[2]), reps = std::max(1, std::atoi(argv[3]));
  if (mode == "interference") return interference(x, reps);
  if (mode == "distance" || mode == "first_hit") return path(mode == "distance", std::max(x, 1), reps);
  std::fprintf(stderr, "warm_queries: unknown mode '%s'\n", mode.c_str());
  return 2;
}
