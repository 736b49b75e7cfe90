// An OpenMP program lends its team to caliber (caliber/executor.h): the step runs inside the
// program's own parallel region, caliber's work as OpenMP tasks on the team's threads, and caliber
// creates no thread. Checks, for every method, that the process has the same threads before and
// after, and that the contacts are the sequential engine's (exit 1 otherwise).
//   host_openmp

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <caliber/caliber.h>
#include <caliber/procedural.h>

/// OpenMP as caliber's host: called from inside a parallel region, each range becomes an OpenMP
/// task that the team's threads run (the others wait at the region's barrier, where OpenMP runs
/// tasks), and finish() waits for them with taskwait; outside a parallel region, the ranges run at
/// once on the calling thread ("ran inline").
class OpenMPHost final : public caliber::HostExecutor {
 public:
  int thread_count() const override { return omp_in_parallel() ? omp_get_num_threads() : 1; }
  void* enqueue(const Job& job, std::size_t count, std::size_t grain) override {
    if (!omp_in_parallel()) {
      for (std::size_t begin = 0; begin < count; begin += grain) job(begin, std::min(count, begin + grain), 0);
      return nullptr;
    }
    for (std::size_t begin = 0; begin < count; begin += grain) {
      const std::size_t end = std::min(count, begin + grain);
#pragma omp task firstprivate(begin, end) shared(job)
      job(begin, end, omp_get_thread_num());
    }
    return this;
  }
  void finish(void*) override {
#pragma omp taskwait
  }
};

static std::size_t os_threads() {
  std::size_t n = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) n += entry.is_directory();
  return n;
}

/// A torus and twelve spheres just off its outer rim; the broad phase picks the pairs.
static caliber::Frame make_frame() {
  caliber::Frame frame;
  caliber::BuildOptions build;
  build.threads = 1;  // the models are built before the team lends its threads
  frame.models = {caliber::build_model(caliber::make_torus(1.0, 0.3, 64, 32), build)};
  frame.poses = {caliber::Pose{}};
  const auto sphere = caliber::build_model(caliber::make_sphere(0.3, 24, 48), build);
  for (int i = 0; i < 12; ++i) {
    caliber::Pose pose;
    pose.translation = {1.605 * std::cos(i * 0.5236), 1.605 * std::sin(i * 0.5236), 0.0};
    frame.models.push_back(sphere);
    frame.poses.push_back(pose);
  }
  frame.request.kind = caliber::QueryKind::contact;
  frame.request.tolerance = 0.02;
  frame.pairs = caliber::broad_phase(frame.models, frame.poses, caliber::reach(frame.request));
  return frame;
}

static bool same(const caliber::StepResult& x, const caliber::StepResult& y) {
  if (x.contacts.size() != y.contacts.size()) return false;
  for (std::size_t i = 0; i < x.contacts.size(); ++i) {
    const caliber::Contact &p = x.contacts[i], &q = y.contacts[i];
    if (p.object_a != q.object_a || p.object_b != q.object_b || p.tri_a != q.tri_a || p.tri_b != q.tri_b ||
        p.point_a != q.point_a || p.point_b != q.point_b)
      return false;
  }
  return true;
}

int main() {
  omp_set_num_threads(4);
#pragma omp parallel
  { (void)omp_get_thread_num(); }  // the team's threads start
  const caliber::Frame frame = make_frame();
  caliber::EngineOptions sequential;
  sequential.method = caliber::Method::sequential;
  const caliber::StepResult reference = caliber::Engine(sequential).step(frame);
  const std::size_t before = os_threads();
  OpenMPHost host;
  bool ok = !reference.contacts.empty();
  for (const caliber::Method method : {caliber::Method::exploitation, caliber::Method::stealing, caliber::Method::aposteriori,
                                       caliber::Method::apriori, caliber::Method::hybrid}) {
    caliber::EngineOptions options;
    options.method = method;
    options.host = &host;
    caliber::Engine engine(options);
    caliber::StepResult step;
    int threads = 0;
#pragma omp parallel
#pragma omp single
    {
      threads = engine.threads();
      step = engine.step(frame);
    }
    const bool equal = same(step, reference);
    std::printf("%s on %d threads of the OpenMP team: %s\n", std::string(caliber::to_string(method)).c_str(), threads,
                equal ? "the sequential engine's contacts" : "DIFFERENT contacts");
    ok = ok && equal && threads > 1;
  }
  const std::size_t after = os_threads();
  std::printf("%zu contacts; process threads %zu before, %zu after: %s\n", reference.contacts.size(), before, after,
              ok && after == before ? "ok" : "FAILED");
  return ok && after == before ? 0 : 1;
}
