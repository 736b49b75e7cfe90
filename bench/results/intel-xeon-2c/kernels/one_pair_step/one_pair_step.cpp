// One posed pair of bench_embree_compare as a one-pair frame: the sequential engine and stealing
// on 2 threads, interleaved, each step timed; with the timeline on, the median of each engine's
// finalization span. Built against a commit's libcaliber.a and public headers, run from the
// repository root:
//
//   g++ -O2 -std=c++20 -Iinclude -Ibuild/include -I/usr/include/eigen3 one_pair_step.cpp \
//     build/libcaliber.a -lassimp -ltbb -lpthread -o one_pair_step
//   one_pair_step CASE STEPS [timeline]      CASE 0-4: bunny, armadillo, elephant, turbine, bunny x elephant

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "caliber/engine.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/profile.h"
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

/// B's pose as bench_embree_compare's place() makes it.
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
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// The step's finalization spans, summed.
double finalize_ms(const StepResult& r) {
  double ms = 0.0;
  if (r.schedule) {
    for (const TaskSpan& s : r.schedule->timeline) {
      if (s.phase == TaskSpan::Phase::finalize) ms += s.end_ms - s.start_ms;
    }
  }
  return ms;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: one_pair_step CASE STEPS [timeline]\n");
    return 2;
  }
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
  const int which = std::atoi(argv[1]), steps = std::max(1, std::atoi(argv[2]));
  if (which < 0 || which > 4) return 2;
  const bool timeline = argc > 3;
  const Case& c = cases[which];
  const Mesh ma = load_mesh(std::string("data/meshes/") + c.a), mb = load_mesh(std::string("data/meshes/") + c.b);
  const Frame frame{{build_model(ma), build_model(mb)}, {Pose{}, place(ma, mb, c.degrees, c.axis, c.offset)}, {{0, 1}}, {}};
  EngineOptions one, two;
  one.method = Method::sequential, one.threads = 1, one.timeline = timeline;
  two.method = Method::stealing, two.threads = 2, two.timeline = timeline;
  Engine sequential(one), stealing(two);
  std::vector<double> seq_ms, steal_ms, seq_fin, steal_fin;
  std::size_t contacts = 0;
  for (int i = 0; i < 5 + steps; ++i) {
    auto t0 = std::chrono::steady_clock::now();
    const StepResult x = sequential.step(frame);
    const double s = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    const StepResult y = stealing.step(frame);
    const double t = ms_since(t0);
    if (i < 5) continue;  // warm-up
    seq_ms.push_back(s);
    steal_ms.push_back(t);
    seq_fin.push_back(finalize_ms(x));
    steal_fin.push_back(finalize_ms(y));
    contacts = y.contacts.size() == x.contacts.size() ? x.contacts.size() : 0;
  }
  std::printf("%s contacts %zu: sequential %.3f ms, stealing 2 threads %.3f ms", c.name, contacts, median(seq_ms),
              median(steal_ms));
  if (timeline) std::printf("; finalization %.4f / %.4f ms", median(seq_fin), median(steal_fin));
  std::printf("\n");
  return 0;
}
