// Allocations in a steady-state step: counts every operator new made by Engine::step,
// for every method at 1 and 2 threads, on a scene whose objects keep touching (three procedural
// meshes), after warm-up steps. Checks that
//  (1) the count does not grow with the steps: on a fixed frame, steps 80-99 after warm-up allocate
//      no more than steps 0-19 (2 % + 100 of slack for a worker thread that first joins late and
//      sets up its scratch);
//  (2) it does not grow with the traversal's work: the same scene with every mesh 4x finer (about
//      7x the node tests, 19x the leaf tests, same pairs) allocates at most twice as much in the median
//      step, so nothing allocates per node test, leaf test or summary node;
//  (3) moving frames (contacts coming and going) allocate at most twice what the fixed frame does (medians);
//  (4) a batch of first hits (Engine::query_many, every entry a hit) allocates far fewer times than
//      it has entries once the engine has run one, and a batch of many contacts an entry leaves
//      the engine holding no more than a few contacts' storage an entry, however the batch ends (a
//      hook between its chunks that throws).
// Prints the counts. Exit 0: all hold; 1: a check failed; 77: skipped (sanitizer build, whose
// allocator hooks would count their own allocations).

#include <algorithm>
#include <vector>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <malloc.h>
#include <new>
#include <memory>
#include <string>

#include "caliber/engine.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/world.h"
#include "support/touching_world.h"

namespace {
std::atomic<long> gAllocations{0};
std::atomic<bool> gCounting{false};
std::atomic<long> gLive{0};  // bytes in blocks operator new handed out and delete has not taken back

void* counted(void* p) {
  gLive.fetch_add(static_cast<long>(malloc_usable_size(p)), std::memory_order_relaxed);
  return p;
}
void release(void* p) {
  if (p != nullptr) gLive.fetch_sub(static_cast<long>(malloc_usable_size(p)), std::memory_order_relaxed);
  std::free(p);
}
}  // namespace

// Replaced global allocation functions: every form forwards to the two below.
void* operator new(std::size_t size) {
  if (gCounting.load(std::memory_order_relaxed)) gAllocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return counted(p);
  throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t align) {
  if (gCounting.load(std::memory_order_relaxed)) gAllocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return counted(p);
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new[](std::size_t size, std::align_val_t align) { return operator new(size, align); }
void operator delete(void* p) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }
void operator delete(void* p, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { release(p); }

namespace {

struct Counts {
  long first = 0;                // allocations over the first window after warm-up
  long last = 0;                 // over the last window
  long most = 0;                 // the most in one step
  long median = 0;               // the median step's, after warm-up
  std::uint64_t node_tests = 0;  // the most in one step
};

/// Steps an engine through warm-up, a first window, a gap and a last window, counting the
/// allocations of each Engine::step (the frame is made outside the count).
Counts count(const caliber::World& world, caliber::Method method, int threads, bool moving) {
  constexpr int kWarmup = 20, kWindow = 20, kGap = 60;
  caliber::EngineOptions options;
  options.method = method;
  options.threads = threads;
  caliber::Engine engine(options);
  const caliber::Frame fixed = world.frame(7);
  Counts c;
  std::vector<long> per_step;
  for (int k = 0; k < kWarmup + 2 * kWindow + kGap; ++k) {
    const caliber::Frame frame = moving ? world.frame(k) : fixed;
    gAllocations = 0;
    gCounting = true;
    const caliber::StepResult result = engine.step(frame);
    gCounting = false;
    const long n = gAllocations.load();
    const int at = k - kWarmup;
    if (at < 0) continue;
    if (at < kWindow) c.first += n;
    if (at >= kWindow + kGap) c.last += n;
    c.most = std::max(c.most, n);
    per_step.push_back(n);
    c.node_tests = std::max(c.node_tests, result.stats.node_tests);
  }
  std::nth_element(per_step.begin(), per_step.begin() + static_cast<std::ptrdiff_t>(per_step.size() / 2), per_step.end());
  c.median = per_step[per_step.size() / 2];
  return c;
}

/// What a batch allocates and leaves behind (check 4).
struct BatchCounts {
  std::size_t entries = 0;
  std::size_t hits = 0;            // entries of the first-hit batch that found a pair
  long first_hit_allocations = 0;  // the second first-hit batch's
  std::size_t contacts = 0;        // of the batch of many contacts an entry
  long kept_bytes = 0;             // live bytes after that batch's result is gone, less those before it
  long allowed_bytes = 0;          // what check 4 allows: a few contacts' storage an entry, and the scratch
};

/// The box against the ball of the touching world, one entry per frame.
BatchCounts count_batch(const caliber::World& world, int threads) {
  constexpr std::size_t kEntries = 3000;
  const caliber::Frame frame = world.frame(0);
  std::vector<caliber::Pose> pa, pb;
  for (std::size_t k = 0; k < kEntries; ++k) {
    const caliber::Frame f = world.frame(static_cast<int>(k));
    pa.push_back(f.poses[0]);
    pb.push_back(f.poses[1]);
  }
  caliber::EngineOptions options;
  options.threads = threads;
  caliber::Engine engine(options);
  caliber::QueryRequest first;
  first.max_pairs = 1;
  caliber::QueryRequest every;
  every.kind = caliber::QueryKind::proximity;
  every.tolerance = 0.01;
  const auto batch = [&](const caliber::QueryRequest& request) {
    return engine.query_many(*frame.models[0], pa, *frame.models[1], pb, request);
  };
  BatchCounts c;
  c.entries = batch(first).size();
  gAllocations = 0;
  gCounting = true;
  const caliber::BatchResult hits = batch(first);
  gCounting = false;
  c.first_hit_allocations = gAllocations.load();
  for (std::size_t i = 0; i < hits.size(); ++i) c.hits += hits.hit(i) ? 1 : 0;
  const long before = gLive.load();
  c.contacts = batch(every).contacts.size();
  c.kept_bytes = gLive.load() - before;
  // Per entry its result and up to 16 contacts; per thread its kept traversal scratch and
  // candidates (up to 2 MiB each).
  c.allowed_bytes =
      static_cast<long>(kEntries * (sizeof(caliber::QueryResult) + 16 * sizeof(caliber::Contact))) + threads * (4L << 20);
  return c;
}

/// Live bytes an engine keeps after a batch that between_chunks stopped: one entry of many contacts
/// (a sphere against itself, every triangle pair within the tolerance) among 8,192 apart, then the
/// hook throws before the second chunk.
long stopped_batch_kept_bytes(int threads) {
  const auto ball = caliber::build_model(caliber::make_sphere(1.0, 12, 24));
  std::vector<caliber::Pose> pb(8193, caliber::Pose::from_values(100, 0, 0, 1, 0, 0, 0));
  pb[0] = caliber::Pose{};
  const std::vector<caliber::Pose> pa{caliber::Pose{}};
  caliber::QueryRequest every;
  every.kind = caliber::QueryKind::proximity;
  every.tolerance = 3.0;
  struct Stop {};
  caliber::EngineOptions options;
  options.threads = threads;
  options.between_chunks = [] { throw Stop{}; };
  caliber::Engine engine(options);
  const long before = gLive.load();
  try {
    (void)engine.query_many(*ball, pa, *ball, pb, every);
  } catch (const Stop&) {}
  return gLive.load() - before;
}

}  // namespace

int main() {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  std::puts("caliber_alloc_test: skipped in a sanitizer build");
  return 77;
#else
  const auto coarse = caliber::test::touching_world(1, "alloc");
  const auto fine = caliber::test::touching_world(4, "alloc_fine");
  int failures = 0;
  const auto check = [&](bool ok, const char* what) {
    if (!ok) {
      std::printf("    FAILED: %s\n", what);
      ++failures;
    }
  };
  std::puts(
      "method        threads  allocations a step, median: fixed, 4x finer, moving;  most: the same;  node tests fixed / finer");
  for (const caliber::Method method : {caliber::Method::sequential, caliber::Method::exploitation, caliber::Method::stealing,
                                       caliber::Method::aposteriori, caliber::Method::apriori, caliber::Method::hybrid}) {
    for (const int threads : {1, 2}) {
      if (method == caliber::Method::sequential && threads > 1) continue;
      const Counts base = count(*coarse, method, threads, false);
      const Counts finer = count(*fine, method, threads, false);
      const Counts moving = count(*coarse, method, threads, true);
      std::printf("%-13s %7d  %8ld %9ld %7ld;  %8ld %9ld %7ld;  %llu / %llu\n", std::string(caliber::to_string(method)).c_str(),
                  threads, base.median, finer.median, moving.median, base.most, finer.most, moving.most,
                  static_cast<unsigned long long>(base.node_tests), static_cast<unsigned long long>(finer.node_tests));
      check(finer.node_tests >= 5 * base.node_tests, "the finer scene does at least 5x the node tests");
      for (const Counts* c : {&base, &finer}) {
        check(static_cast<double>(c->last) <= 1.02 * static_cast<double>(c->first) + 100.0,
              "a fixed frame's allocations do not grow with the steps");
      }
      // Medians: anything allocated per node test, leaf test or summary node shows in every step,
      // while the most in one step also counts a worker that joins late and sets up its scratch
      // then (seen under a loaded run: stealing on 2 threads 88 in one step against a median of 45).
      check(finer.median <= 2 * base.median, "4x finer meshes allocate at most twice as much a step");
      check(moving.median <= 2 * base.median, "moving frames allocate at most twice what a fixed one does");
      check(finer.most <= 4 * base.most + 100, "no step of the finer meshes allocates far beyond the coarse ones' worst");
    }
  }
  for (const int threads : {1, 2}) {
    const BatchCounts b = count_batch(*coarse, threads);
    std::printf("batch, %d threads: %zu entries; %zu first hits: %ld allocations; %zu contacts: %ld bytes kept (%ld allowed)\n",
                threads, b.entries, b.hits, b.first_hit_allocations, b.contacts, b.kept_bytes, b.allowed_bytes);
    check(b.hits >= b.entries / 2, "most entries of the first-hit batch are hits");
    check(b.first_hit_allocations <= static_cast<long>(b.entries / 20), "a batch of first hits allocates far less than an entry");
    check(b.contacts > 64 * b.entries, "the batch of many contacts has many an entry");
    check(b.kept_bytes <= b.allowed_bytes, "the engine keeps a few contacts' storage an entry, no more");
    // 576 triangles a side: 331,776 contacts (34.5 MB) in the first entry's answer.
    const long stopped = stopped_batch_kept_bytes(threads);
    const long allowed = threads * (4L << 20) + (1L << 20);
    std::printf("batch stopped between chunks, %d threads: %ld bytes kept (%ld allowed)\n", threads, stopped, allowed);
    check(stopped <= allowed, "a batch stopped between its chunks leaves the engine its scratch, no answer's storage");
  }
  std::printf("%s\n", failures == 0 ? "bounded and flat" : "FAILED");
  return failures == 0 ? 0 : 1;
#endif
}
