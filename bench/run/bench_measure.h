#pragma once
// caliber-bench's measurements: its options, what a bench run shares (the log, the budget, the
// progress), and the runs of one scene (every method and thread count, the machine's ceiling, the
// load-balance simulation) and the timeline of one step, each logged as it ends.

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "bench_records.h"
#include "caliber/engine.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "interrupt.h"
#include "progress.h"
#include "timing.h"

namespace caliber::cli {

/// The options of caliber-bench (add_bench_options).
struct BenchOptions {
  std::vector<std::string> scenes;
  std::vector<std::string> methods = {"sequential", "exploitation", "stealing", "aposteriori", "apriori", "hybrid"};
  std::vector<int> threads;
  std::vector<int> simulate = {4, 8, 16, 32, 64};
  int repeat = 3;
  int steps = 0;           // 0: the scene's
  int simulate_steps = 0;  // steps replayed per simulated core count (0: all the scene's)
  int fcl_repeat = 3;
  std::string out;
  bool figures = true;
  bool fcl = true;
  bool ceiling = true;
  double budget_s = 0.0;  // 0: no budget
  std::string log;        // the JSON-lines log (default: OUT/runs.jsonl)
  std::string from_log;   // rebuild the report from this log instead of measuring
};

/// A method name as the bench knows it: the six methods, and "hybrid+history" (node history on).
struct Variant {
  std::string name;
  Method method;
  bool node_history;
};

inline Variant parse_variant(const std::string& name) {
  if (name == "hybrid+history") return {name, Method::hybrid, true};
  return {name, parse_method(name), false};
}

/// The time the bench may take (--budget-s): a run starts only if its estimated time still fits,
/// so the bench ends inside the budget with every finished run in its log.
class Budget {
 public:
  explicit Budget(double seconds) : mSeconds(seconds) {}
  /// Whether work estimated at `estimate_s` seconds (a quarter more for safety) still fits.
  [[nodiscard]] bool allows(double estimate_s) const { return mSeconds <= 0.0 || elapsed_s() + 1.25 * estimate_s <= mSeconds; }
  [[nodiscard]] double elapsed_s() const { return seconds_since(mStart); }

 private:
  Clock::time_point mStart = Clock::now();
  double mSeconds;
};

/// Everything a bench run shares: options, scenes, methods, the log, the budget, the progress.
struct BenchRun {
  const BenchOptions& opt;
  std::vector<std::unique_ptr<World>>& worlds;
  std::vector<double> load_s;  ///< per scene: loading and building its world once
  const std::vector<Variant>& variants;
  BenchLog& log;
  Budget budget;
  Progress progress;
  std::size_t done = 0;
  bool stopped = false;
  std::vector<double> sequential_s;  ///< per scene: one sequential run, in seconds (0 until run)

  /// Whether a signal (SIGINT, SIGTERM) stopped the bench; records that it stops here, before `what`.
  bool interrupted_before(const std::string& what) {
    if (stopped) return true;
    if (!interrupted()) return false;
    stopped = true;
    progress.end();
    log.add({{"kind", "stopped"},
             {"reason", "interrupted"},
             {"signal", interrupt_name()},
             {"after_s", budget.elapsed_s()},
             {"next", what}});
    std::fprintf(stderr, "\ncaliber-bench: interrupted (%s) after %.0f s; not run: %s and what follows\n", interrupt_name(),
                 budget.elapsed_s(), what.c_str());
    return true;
  }

  /// Whether work of `estimate_s` fits and no signal stopped the bench; if not, records that the
  /// run stops here.
  bool fits(double estimate_s, const std::string& what) {
    if (interrupted_before(what)) return false;
    if (budget.allows(estimate_s)) return true;
    stopped = true;
    log.add({{"kind", "stopped"}, {"reason", "budget"}, {"after_s", budget.elapsed_s()}, {"next", what}});
    std::fprintf(stderr, "\ncaliber-bench: --budget-s %g reached after %.0f s; not run: %s and what follows\n", opt.budget_s,
                 budget.elapsed_s(), what.c_str());
    return false;
  }
};

/// Steps replayed for the load-balance simulation of a scene.
inline int simulated_steps(const BenchOptions& opt, const Scene& scene) {
  return opt.simulate_steps > 0 ? std::min(opt.simulate_steps, scene.steps) : scene.steps;
}

/// Every measured run of one scene (index `si` of b.worlds), in rounds, then its ceiling and
/// simulation (bench_measure.cpp).
void bench_scene(BenchRun& b, std::size_t si);

/// The per-thread timeline of one step, exploitation against hybrid, logged.
void record_gantt(BenchRun& b);

}  // namespace caliber::cli
