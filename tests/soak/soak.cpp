// Soak: runs one engine over many steps of a world whose objects keep touching (pure rotations),
// and checks that (1) peak memory stays flat: VmHWM after the last step is within 2 % + 1 MiB of
// VmHWM after step 1,000, and (2) the engine's answer at sampled steps, after thousands of steps
// of temporal state, is byte-identical to a fresh engine's and to a fresh sequential engine's at the same step.
//   caliber_soak [--steps N] [--method NAME] [--threads T] [--node-history]
// Exit 0: flat and identical; 1: a check failed; 2: bad arguments.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/world.h"
#include "support/touching_world.h"

namespace {

/// A field of /proc/self/status in KiB (VmRSS, VmHWM), or -1 where there is none.
long status_kib(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::strtol(line.c_str() + field.size() + 1, nullptr, 10);
  }
  return -1;
}

bool same(const caliber::StepResult& a, const caliber::StepResult& b) {
  if (a.contacts.size() != b.contacts.size() || a.pair_records.size() != b.pair_records.size()) return false;
  for (std::size_t i = 0; i < a.pair_records.size(); ++i) {
    if (!(a.pair_records[i].pair == b.pair_records[i].pair)) return false;
  }
  for (std::size_t i = 0; i < a.contacts.size(); ++i) {
    const auto& x = a.contacts[i];
    const auto& y = b.contacts[i];
    if (x.object_a != y.object_a || x.object_b != y.object_b || x.tri_a != y.tri_a || x.tri_b != y.tri_b ||
        x.distance != y.distance || x.point_a != y.point_a || x.point_b != y.point_b || x.normal != y.normal) {
      return false;
    }
  }
  return true;
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;  // the sanitizers' allocators hold freed memory back on purpose
#else
constexpr bool kSanitized = false;
#endif

}  // namespace

int main(int argc, char** argv) {
  int steps = 10000, threads = 2;
  caliber::EngineOptions options;
  options.method = caliber::Method::hybrid;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      const auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw caliber::Error(caliber::ErrorCode::bad_argument, arg, "needs a value");
        return argv[++i];
      };
      if (arg == "--steps")
        steps = std::stoi(value());
      else if (arg == "--threads")
        threads = std::stoi(value());
      else if (arg == "--method")
        options.method = caliber::parse_method(value());
      else if (arg == "--node-history")
        options.node_history = true;
      else
        throw caliber::Error(caliber::ErrorCode::bad_argument, arg, "unknown argument");
    }
    if (steps < 1000) throw caliber::Error(caliber::ErrorCode::bad_value, "--steps", "must be >= 1000");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "caliber_soak: %s\n", e.what());
    return 2;
  }
  options.threads = threads;

  const auto owned = caliber::test::touching_world(1, "soak");
  const caliber::World& world = *owned;

  caliber::Engine engine(options);
  const auto start = std::chrono::steady_clock::now();
  long hwm_1000 = -1;
  std::size_t contacts = 0, mismatches = 0, samples = 0;
  for (int k = 0; k < steps; ++k) {
    const caliber::StepResult got = caliber::step(world, engine, k);
    contacts += got.contacts.size();
    if (k % 1000 == 999 || k == steps - 1) {
      caliber::EngineOptions fresh_options = options;
      caliber::Engine fresh(fresh_options);
      caliber::Engine sequential{caliber::EngineOptions{}};
      const bool ok = same(got, caliber::step(world, fresh, k)) && same(got, caliber::step(world, sequential, k));
      ++samples;
      if (!ok) ++mismatches;
      std::printf("step %5d: %zu contacts, VmRSS %ld KiB, VmHWM %ld KiB%s\n", k + 1, got.contacts.size(), status_kib("VmRSS"),
                  status_kib("VmHWM"), ok ? "" : "  MISMATCH with a fresh run");
      std::fflush(stdout);
    }
    if (k == 999) hwm_1000 = status_kib("VmHWM");
  }
  const long hwm_end = status_kib("VmHWM");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%d steps of %s on %d thread(s) in %.1f s, %zu contacts in all\n", steps,
              std::string(caliber::to_string(options.method)).c_str(), engine.threads(), seconds, contacts);
  bool failed = false;
  if (contacts == 0) {
    std::printf("FAIL: no contacts at all; the soak tested nothing\n");
    failed = true;
  }
  if (mismatches > 0) {
    std::printf("FAIL: %zu of %zu sampled steps differ from a fresh run\n", mismatches, samples);
    failed = true;
  }
  const long allowed = hwm_1000 + hwm_1000 / 50 + 1024;
  if (kSanitized) {
    std::printf("memory: VmHWM %ld -> %ld KiB (not checked under a sanitizer)\n", hwm_1000, hwm_end);
  } else if (hwm_1000 < 0 || hwm_end > allowed) {
    std::printf("FAIL: peak memory grew: VmHWM %ld KiB after step 1000, %ld KiB after step %d (allowed %ld)\n", hwm_1000, hwm_end,
                steps, allowed);
    failed = true;
  } else {
    std::printf("memory flat: VmHWM %ld KiB after step 1000, %ld KiB after step %d\n", hwm_1000, hwm_end, steps);
  }
  return failed ? 1 : 0;
}
