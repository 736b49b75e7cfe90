// The first hit (max_pairs 1; `d`: unbounded distance) on bench_batch's path of N poses (the
// scaled turbine through the bunny): a loop of caliber::query calls, Engine::query_many on 1
// thread and on 2, interleaved, R rounds, medians in µs a pose. Built against a commit's
// libcaliber.a and public headers, run from the repository root:
//
//   g++ -O2 -std=c++20 -Iinclude -Ibuild/include -I/usr/include/eigen3 first_hit_batch.cpp \
//     build/libcaliber.a -lassimp -ltbb -lpthread -o first_hit_batch
//   first_hit_batch N R [d]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>
#include <Eigen/Geometry>
#include "caliber/batch.h"
#include "caliber/engine.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
using namespace caliber;
static void box_center(const Mesh& m, Eigen::Vector3d& c, double& d) {
  Eigen::Vector3d lo = m.vertices[0], hi = lo;
  for (const auto& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  c = 0.5 * (lo + hi);
  d = (hi - lo).norm();
}
static Pose place(const Mesh& a, const Mesh& b, double deg, Eigen::Vector3d axis, Eigen::Vector3d off) {
  Eigen::Vector3d ca, cb;
  double da, db;
  box_center(a, ca, da);
  box_center(b, cb, db);
  Eigen::Quaterniond q(Eigen::AngleAxisd(deg * std::numbers::pi / 180.0, axis.normalized()));
  Eigen::Vector3d t = ca + off * da - q * cb;
  return Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
}
static double med(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
int main(int argc, char** argv) {
  int n = atoi(argv[1]), reps = atoi(argv[2]);
  bool distance = argc > 3;
  Mesh a = load_mesh("data/meshes/bunny00.off"), b = load_mesh("data/meshes/turbine.off");
  scale_mesh(b, 0.3);
  BuildOptions build;
  build.oriented_boxes = true;
  auto ma = build_model(a, build), mb = build_model(b, build);
  QueryRequest rq;
  rq.max_pairs = 1;
  if (distance) {
    rq = QueryRequest{};
    rq.kind = QueryKind::distance;
    rq.tolerance = kUnbounded;
  }
  std::vector<Pose> poses;
  for (int i = 0; i < n; ++i) {
    double s = n > 1 ? double(i) / (n - 1) : 0.0;
    Eigen::Vector3d off = Eigen::Vector3d(-0.45, -0.1, 0.05) + s * Eigen::Vector3d(0.9, 0.2, -0.1);
    poses.push_back(place(a, b, 540.0 * s, Eigen::Vector3d(0.3, 1.0, 0.2), off));
  }
  EngineOptions o;
  o.threads = 1;
  Engine e(o);
  EngineOptions o2;
  o2.threads = 2;
  Engine e2(o2);
  std::vector<double> t2;
  std::vector<Pose> pa{Pose{}};
  std::vector<double> tl, tb;
  std::size_t hits_l = 0, hits_b = 0;
  for (int r = 0; r < reps; ++r) {
    auto s = std::chrono::steady_clock::now();
    std::size_t h = 0;
    for (const Pose& p : poses) h += query(*ma, Pose{}, *mb, p, rq).contacts.size();
    tl.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - s).count() / n);
    s = std::chrono::steady_clock::now();
    BatchResult br = e.query_many(*ma, pa, *mb, poses, rq);
    tb.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - s).count() / n);
    hits_l = h;
    hits_b = br.contacts.size();
    s = std::chrono::steady_clock::now();
    BatchResult b2 = e2.query_many(*ma, pa, *mb, poses, rq);
    t2.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - s).count() / n);
  }
  std::printf("loop %.3f us batch1t %.3f us batch2t %.3f us batch/loop %.3f 2t/1t %.2f (contacts %zu %zu)\n", med(tl), med(tb),
              med(t2), med(tb) / med(tl), med(tb) / med(t2), hits_l, hits_b);
}
