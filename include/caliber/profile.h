#pragma once
/// \file
/// The engine's instrumentation, opt-in (EngineOptions::profile): how a step's work was cut and
/// scheduled, who ran what when, and the load-balance simulation that replays a step's recorded
/// work on any number of virtual cores. Not needed to run queries or steps.

#include <cstdint>
#include <memory>
#include <vector>

#include "caliber/engine.h"
#include "caliber/export.h"

namespace caliber {

/// One piece of a step's work on one thread (EngineOptions::timeline): what a Gantt chart draws.
struct TaskSpan {
  /// Which part of the step: the weight-driven stage of one split pair, one unit of depth-first
  /// traversal (a run-time task, a pair, a stealing piece), or one pair's finalization.
  enum class Phase : std::uint8_t { stage, traverse, finalize };
  int thread = 0;         ///< the executor's thread index (0 .. threads-1)
  double start_ms = 0.0;  ///< since the start of the step's narrow phase
  double end_ms = 0.0;
  Phase phase = Phase::traverse;
  /// What was run: stage and finalize, the pair's index in the frame's pairs (StepResult::pair_records);
  /// traverse, the run-time task's index in ScheduleRecord::task_node_tests (and task_roots), or,
  /// for stealing, the pair of the depth-first piece.
  std::uint32_t unit = 0;
};

/// Where a run-time task starts: a node of the CD tree of one of the step's pairs (a node of A's
/// BVH against a node of B's). A task traverses depth first from each of its roots.
struct TaskRoot {
  std::uint32_t pair = 0;    ///< index in the frame's pairs (StepResult::pair_records)
  std::uint32_t node_a = 0;  ///< node of A's BVH (an index below Model::node_count())
  std::uint32_t node_b = 0;  ///< node of B's BVH
};

/// How the engine cut and scheduled a step's work. The calibration fields are zero for the methods
/// that do not calibrate; `task_node_tests` is filled by every engine method.
struct ScheduleRecord {
  /// The step's query kind, which sets how a heavy pair's finalization runs (predicted_step_ms).
  QueryKind kind = QueryKind::interference;
  double omega = 0.0;                                ///< the caliber Omega (in weight units)
  std::size_t kept = 0;                              ///< pairs run as they are
  std::size_t split = 0;                             ///< pairs split by the weight-driven stage
  std::size_t carted = 0;                            ///< items merged in the cart (light pairs and light nodes)
  std::size_t generated = 0;                         ///< run-time tasks
  std::uint64_t stage_node_tests = 0;                ///< node tests made in the weight-driven stage
  std::size_t queue_peak = 0;                        ///< widest level of the weight-driven stage (nodes waiting at once)
  std::vector<std::uint64_t> stage_pair_node_tests;  ///< node tests of the weight-driven stage, per split pair
  /// The weight-driven stage level by level: for each level of each split pair (the split pairs in
  /// the order of stage_pair_node_tests, each one's levels from the root down), the node tests of
  /// each chunk of the level's nodes that one thread ran. A level waits for the one above it.
  std::vector<std::vector<std::uint64_t>> stage_levels;
  std::vector<std::uint32_t> stage_level_pair;  ///< the split pair (index in stage_pair_node_tests) of each stage level
  /// Per split pair, the stage's wall time outside its levels' parallel visits (taking each
  /// level's outcomes in order, the final sorts): serial within that pair's stage.
  std::vector<double> stage_serial_ms;
  /// Node tests of each unit the scheduler ran, in the order it was handed out: the run-time tasks
  /// (calibrated methods), the pairs (sequential, exploitation), or the depth-first pieces below the
  /// cut-off and the single node tests above it (stealing). The load-balance simulation replays them.
  std::vector<std::uint64_t> task_node_tests;
  std::vector<double> task_weights;    ///< estimated weight of each run-time task (calibrated methods)
  std::uint64_t split_node_tests = 0;  ///< stealing: node tests made above the cut-off, while splitting
  std::size_t taboo = 0;               ///< a posteriori: taboo nodes (sub-task roots) handed out
  /// A posteriori: node tests of sub-tasks whose root the original task never reached (an ancestor
  /// was pruned at this step): work the sequential traversal does not do. The other node tests add
  /// up to sequential's exactly.
  std::uint64_t taboo_unreached_node_tests = 0;
  /// Depth-first node tests done by each worker thread (unordered; the weight-driven stage's tests
  /// are in stage_pair_node_tests).
  std::vector<std::uint64_t> thread_node_tests;
  double calibrate_ms = 0.0;  ///< calibrated methods: weights, keep/split/cart, weight-driven stage, cart
  /// Depth-first traversals of the run-time tasks (or pairs, or pieces), with the finalization of
  /// each pair a task holds whole.
  double traverse_ms = 0.0;
  /// After the traversals: the per-pair merge, sort, local minima and world coordinates of the
  /// pairs cut into pieces.
  double finalize_ms = 0.0;
  /// Every piece of work with its thread and times, sorted by thread then start; empty unless
  /// EngineOptions::timeline is on.
  std::vector<TaskSpan> timeline;
  /// The roots of each run-time task, in the order of task_node_tests (every method but stealing,
  /// whose pieces are cut while it runs); empty unless EngineOptions::timeline is on.
  std::vector<std::vector<TaskRoot>> task_roots;
};

/// Makespan, in node tests, of greedy list scheduling: each cost in order goes to the least-loaded
/// of `cores` virtual cores (the policy of a dynamic parallel loop with grain 1).
/// (Each of these takes 1 to 65,536 cores: caliber::Error otherwise.)
[[nodiscard]] CALIBER_EXPORT double list_schedule_makespan(const std::vector<std::uint64_t>& costs, int cores);

/// The load-balance simulation: the speed-up on `cores` virtual cores that the step's recorded
/// work units (StepResult::schedule: a step run with EngineOptions::profile; caliber::Error without)
/// predict for `method` (total node tests / simulated makespan). Calibrated methods: the
/// weight-driven stage (each split pair's levels in turn, a level's chunks list-scheduled, the split
/// pairs side by side), then a barrier, then the run-time tasks in handout order. Exploitation: the
/// pairs in order. Stealing: its depth-first pieces, largest first, plus the splitting work spread
/// evenly (an optimistic model of stealing). Sequential: 1.
[[nodiscard]] CALIBER_EXPORT double simulated_speedup(const StepResult& step, Method method, int cores);

/// The load-balance simulation in time: the step's measured pieces of work replayed on `cores`
/// virtual cores, in ms: what the step (its broad phase, serial, its narrow phase and its
/// reduction) would take there. Needs the
/// step's timeline (EngineOptions::timeline) and is meant for a step run on one thread (pieces
/// timed undisturbed; EngineOptions::plan_threads = cores gives the cut made for that many).
/// Replayed: each weight-driven stage's levels (a stage's time, less its serial part, shared among
/// its levels' chunks by node tests, chunks list-scheduled, a barrier after each level, the serial
/// part on its path; the split pairs side by side),
/// then the traversal units list-scheduled in handout order (stealing: largest first), the
/// traversal's time outside them (handing units out; stealing's splitting above the cut-off)
/// spread evenly over the cores, then each pair's finalization list-scheduled (a pair with many
/// candidates as the chunks its finalization runs in parallel, its time shared evenly among them);
/// everything outside those pieces (setting up the pairs, weights, the cart, the reduction) stays
/// serial. Throws caliber::Error when the step has no timeline.
[[nodiscard]] CALIBER_EXPORT double predicted_step_ms(const StepResult& step, Method method, int cores);

/// The load-balance simulation over a run: the run's predicted speed-up on `cores` virtual cores is
/// its total node tests over the sum of its steps' simulated makespans.
class CALIBER_EXPORT SimulatedRun {
 public:
  SimulatedRun(Method method, int cores) : mMethod(method), mCores(cores) {}
  /// Adds one step (and its predicted_step_ms when it has a timeline).
  void add(const StepResult& step);
  /// The predicted speed-up of the steps added (1 when they did no work).
  [[nodiscard]] double speedup() const { return mSpan > 0.0 ? mWork / mSpan : 1.0; }
  /// The mean predicted_step_ms of the steps added with a timeline (0 when none had one).
  [[nodiscard]] double predicted_ms() const { return mTimed > 0 ? mPredictedMs / mTimed : 0.0; }
  /// The core count simulated.
  [[nodiscard]] int cores() const { return mCores; }

 private:
  Method mMethod;
  int mCores;
  double mWork = 0.0;
  double mSpan = 0.0;
  double mPredictedMs = 0.0;
  int mTimed = 0;
};

}  // namespace caliber
