// An OpenMP host that runs caliber's queries on its own threads: a motion planner's loop over
// poses, `#pragma omp parallel for`, each iteration one caliber::query on models shared by every
// thread. caliber::query runs on the thread that calls it, and the models are built with
// BuildOptions::threads = 1 (on the calling thread): caliber starts no thread of its own.
//
//   caliber_example_openmp_host
//
// Checks what it claims: the process's thread count (/proc/self/task) before and after, and each
// pose's contacts against those of the default engine. Exits 0 when all hold, 1 when one does not,
// 2 on an error.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <omp.h>

#include <caliber/caliber.h>
#include <caliber/procedural.h>

namespace {

std::size_t os_threads() {
  std::size_t n = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) n += entry.is_directory() ? 1 : 0;
  return n;
}

/// Pose k of the planner's path: the sphere moving across the torus's tube, turning as it goes.
caliber::Pose path_pose(int k) {
  caliber::Pose pose;
  pose.translation = {0.7 + 0.01 * k, 0.0, 0.2};
  pose.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitZ()));
  return pose;
}

}  // namespace

int main() {
  try {
    constexpr int kPoses = 64;
    omp_set_num_threads(2);
#pragma omp parallel
    { (void)omp_get_thread_num(); }  // the host's pool starts
    const std::size_t threads_before = os_threads();

    caliber::BuildOptions on_this_thread;
    on_this_thread.threads = 1;
    const auto torus = caliber::build_model(caliber::make_torus(1.0, 0.3, 64, 32), on_this_thread);
    const auto sphere = caliber::build_model(caliber::make_sphere(0.3, 24, 48), on_this_thread);
    caliber::QueryRequest request;
    request.kind = caliber::QueryKind::proximity;
    request.tolerance = 0.02;
    std::vector<caliber::QueryResult> results(kPoses);
#pragma omp parallel for schedule(dynamic)
    for (int k = 0; k < kPoses; ++k) results[k] = caliber::query(*torus, caliber::Pose{}, *sphere, path_pose(k), request);
    const std::size_t threads_after = os_threads();

    // The reference: the default engine (its own threads, started only now), one frame per pose.
    caliber::Engine engine;
    bool ok = threads_after == threads_before;
    std::size_t contacts = 0;
    for (int k = 0; k < kPoses; ++k) {
      caliber::Frame frame;
      frame.models = {torus, sphere};
      frame.poses = {caliber::Pose{}, path_pose(k)};
      frame.pairs = {{0, 1}};
      frame.request = request;
      const caliber::StepResult step = engine.step(frame);
      const caliber::QueryResult& mine = results[k];
      contacts += mine.contacts.size();
      bool same = step.contacts.size() == mine.contacts.size();
      for (std::size_t i = 0; same && i < mine.contacts.size(); ++i) {
        const caliber::Contact &p = step.contacts[i], &q = mine.contacts[i];
        same = p.tri_a == q.tri_a && p.tri_b == q.tri_b && p.point_a == q.point_a && p.point_b == q.point_b &&
               p.distance == q.distance;
      }
      if (!same) {
        std::printf("FAIL: pose %d: the query's contacts differ from the engine's\n", k);
        ok = false;
      }
    }
    std::printf("%d poses on %d OpenMP threads: %zu contacts; process threads %zu before, %zu after\n", kPoses, 2, contacts,
                threads_before, threads_after);
    if (threads_after != threads_before) std::printf("FAIL: caliber started threads\n");
    if (contacts == 0) {
      std::printf("FAIL: no contact: the example shows nothing\n");
      ok = false;
    }
    std::printf("%s\n", ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
  } catch (const caliber::Error& e) {
    std::fprintf(stderr, "caliber_example_openmp_host: %s\n", e.what());
    return 2;
  }
}
