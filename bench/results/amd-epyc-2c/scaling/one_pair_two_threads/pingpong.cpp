// The bunny pair's interference query (bench_embree_compare's pose) run by two threads pinned to
// CPU 0 and CPU 1, in turn and never at once: thread 0, thread 0 again, thread 1, R times. Prints
// the median of the queries that followed one on the same core, and of those that followed one on
// the other core. Run from the repository root: pingpong R
#include <atomic>
#include <thread>
#include <chrono>
#include <cstdio>
#include <algorithm>
#include <vector>
#include <numbers>
#include <sched.h>
#include <Eigen/Geometry>
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
using namespace caliber;
static Pose place(const Mesh& a, const Mesh& b, double deg, Eigen::Vector3d axis, Eigen::Vector3d off) {
  auto bc = [](const Mesh& m, Eigen::Vector3d& c, double& d) {
    Eigen::Vector3d lo = m.vertices[0], hi = lo;
    for (auto& v : m.vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    c = 0.5 * (lo + hi);
    d = (hi - lo).norm();
  };
  Eigen::Vector3d ca, cb;
  double da, db;
  bc(a, ca, da);
  bc(b, cb, db);
  Eigen::Quaterniond q(Eigen::AngleAxisd(deg * std::numbers::pi / 180.0, axis.normalized()));
  Eigen::Vector3d t = ca + off * da - q * cb;
  return Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
}
int main(int argc, char** argv) {
  int reps = atoi(argv[1]);
  Mesh ma = load_mesh("data/meshes/bunny00.off");
  Pose pb = place(ma, ma, 90, {-1, 0, 1}, {0.06, -0.2, -0.1});
  auto a = build_model(ma);
  QueryRequest rq;
  std::atomic<int> turn{0};
  std::vector<double> same, cross;
  // Mode: each thread pinned; turn passes 0 -> 1 -> 0 ... ; "same" runs: thread 0 runs twice in a row.
  auto run = [&](int me) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(me, &set);
    sched_setaffinity(0, sizeof set, &set);
    for (int i = 0; i < reps; ++i) {
      // phase: 0: t0 query (after t1's: cross), 1: t0 query again (same), 2: t1 query (cross)
      for (int phase = 0; phase < 3; ++phase) {
        int owner = phase == 2 ? 1 : 0;
        if (owner != me) continue;
        while (turn.load() != i * 3 + phase) {}
        auto t0 = std::chrono::steady_clock::now();
        auto r = query(*a, Pose{}, *a, pb, rq);
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        (phase == 1 ? same : cross).push_back(ms);
        turn.store(i * 3 + phase + 1);
      }
    }
  };
  std::thread t1(run, 1);
  run(0);
  t1.join();
  std::sort(same.begin(), same.end());
  std::sort(cross.begin(), cross.end());
  std::printf("same core again %.3f ms, after the other core %.3f ms\n", same[same.size() / 2], cross[cross.size() / 2]);
}
