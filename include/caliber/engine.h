#pragma once
/// \file
/// The parallel engine: how a step's work is cut into tasks and scheduled on threads. Every method
/// runs the same traversal and returns byte-identical contacts; they differ only in the task list
/// and the schedule.

#include <cstdint>
#include <memory>
#include <string_view>

#include "caliber/world.h"

namespace caliber {
namespace narrow {
class PairContext;
}

/// How a step's narrow phase is cut and scheduled.
enum class Method : std::uint8_t {
  sequential,    ///< one thread, the initial tasks one after another
  exploitation,  ///< a parallel loop over the initial tasks (the paper's "parallelism exploitation")
  stealing,      ///< recursive parallel traversal on oneTBB's work stealing, serial below a depth cut-off
  aposteriori,   ///< task calibration with temporal weights: last step's node tests, summary tree, taboo lists
  apriori,       ///< task calibration with geometric weights (the weight-driven stage splits heavy pairs)
  hybrid,        ///< task calibration with geometric weights rescaled by the previous step's node tests
};

/// "sequential", "exploitation", "stealing", "aposteriori", "apriori" or "hybrid".
[[nodiscard]] std::string_view to_string(Method method);
/// Parses a method name; throws caliber::Error on an unknown one.
[[nodiscard]] Method parse_method(std::string_view name);

/// Options of the engine.
struct EngineOptions {
  /// The method.
  Method method = Method::sequential;
  /// Worker threads (1..1024); 0 means the machine's hardware threads. `sequential` always uses one.
  int threads = 0;
  /// Stealing: CD-tree depth from which a subtree is traversed serially by one task.
  int stealing_depth = 10;
  /// Calibration: overthreading factor beta (> 0): Omega = total weight / (beta * threads).
  /// Default 6, measured (bench/results/amd-epyc-2c/calibration_sweep.md): with 2 threads, beta = 2
  /// cuts scenes of many light pairs (funnel) into about 4 coarse tasks that cannot be balanced;
  /// a larger beta costs a longer serial weight-driven stage on a scene of one pair (two_small).
  double beta = 6.0;
  /// Calibration: tolerance on Omega, as a fraction of Omega (>= 0).
  double epsilon = 0.25;
  /// A posteriori: the most sub-task roots (taboo nodes) one task may hand out (>= 1).
  int taboo_cap = 64;
  /// Hybrid: weigh a CD node by the node tests its subtree took at the previous step when the
  /// weight-driven stage popped it then (a priori, rescaled, otherwise). Not in the paper.
  bool node_history = false;
  /// Record ScheduleRecord::timeline (thread and times of every piece of work). Costs two clock
  /// reads per piece; off by default.
  bool timeline = false;
};

/// Makespan, in node tests, of greedy list scheduling: each cost in order goes to the least-loaded
/// of `cores` virtual cores (the policy of a dynamic parallel loop with grain 1).
[[nodiscard]] double list_schedule_makespan(const std::vector<std::uint64_t>& costs, int cores);

/// The load-balance simulation: the speed-up on `cores` virtual cores that the step's recorded
/// work units predict for `method` (total node tests / simulated makespan). Calibrated methods: the
/// weight-driven stage, then a barrier, then the run-time tasks in handout order. Exploitation: the
/// pairs in order. Stealing: its depth-first pieces, largest first, plus the splitting work spread
/// evenly (an optimistic model of stealing). Sequential: 1.
[[nodiscard]] double simulated_speedup(const StepResult& step, Method method, int cores);

/// Runs a world's steps with a method on a fixed number of threads (a oneTBB task arena of exactly
/// that many). Not thread-safe itself: one step at a time.
class Engine {
 public:
  /// Throws caliber::Error on a thread count outside 0..1024 or a negative stealing depth.
  Engine(const World& world, const EngineOptions& options);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// Runs step k. The contacts are identical to World::step(k), whatever the method or threads.
  [[nodiscard]] StepResult step(int k);
  /// The number of worker threads.
  [[nodiscard]] int threads() const;
  /// The options in force (threads resolved).
  [[nodiscard]] const EngineOptions& options() const { return mOptions; }

 private:
  struct Impl;
  void run_calibrated(const std::vector<Task>& tasks, const std::vector<narrow::PairContext>& contexts,
                      std::vector<QueryResult>& results, ScheduleRecord& record);
  const World& mWorld;
  EngineOptions mOptions;
  std::unique_ptr<Impl> mImpl;
};

}  // namespace caliber
