// A oneTBB host that limits the process to 2 threads and works in its own arena of 2. caliber,
// called inside that arena, runs there: no thread of its own, the host's limit untouched, even for
// an engine that asks for 8. Checks it (exit 1 otherwise), and that the contacts are the
// sequential engine's.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <caliber/caliber.h>
#include <caliber/procedural.h>

static std::size_t os_threads() {
  std::size_t n = 0;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) n += task.is_directory();
  return n;
}

/// A torus and twelve spheres just off its outer rim, made in memory; the broad phase picks the pairs.
static caliber::Frame make_frame() {
  caliber::Frame frame;
  frame.models = {caliber::build_model(caliber::make_torus(1.0, 0.3, 64, 32))};  // on the caller's arena
  frame.poses = {caliber::Pose{}};
  const auto sphere = caliber::build_model(caliber::make_sphere(0.3, 24, 48));
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
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  tbb::task_arena arena(2);
  arena.execute([] { tbb::parallel_for(0, 1000, [](int) {}); });  // the host's worker starts
  const std::size_t before = os_threads();

  caliber::Frame frame;
  caliber::StepResult step, greedy_step;
  int threads = 0, greedy_threads = 0;
  // [readme]
  arena.execute([&] {
    frame = make_frame();
    caliber::Engine engine;  // the default method, on the arena it is called from
    threads = engine.threads();
    step = engine.step(frame);
    caliber::EngineOptions eight;
    eight.threads = 8;  // more than the host allows: gets what the host allows
    caliber::Engine greedy(eight);
    greedy_threads = greedy.threads();
    greedy_step = greedy.step(frame);
  });
  // [/readme]
  const std::size_t after = os_threads();

  caliber::EngineOptions sequential;
  sequential.method = caliber::Method::sequential;
  const caliber::StepResult reference = caliber::Engine(sequential).step(frame);
  const bool ok = after == before && threads <= 2 && greedy_threads <= 2 && !step.contacts.empty() && same(step, reference) &&
                  same(greedy_step, reference) &&
                  tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) == 2;
  std::printf("%zu contacts on %d and %d threads; process threads %zu before, %zu after: %s\n", step.contacts.size(), threads,
              greedy_threads, before, after, ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
