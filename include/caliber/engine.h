#pragma once
/// \file
/// The parallel engine: how a step's work is cut into tasks and scheduled on threads. Every method
/// runs the same traversal and returns byte-identical contacts; they differ only in the task list
/// and the schedule.

#include "caliber/export.h"
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"

namespace caliber {

/// An object pair to test (a < b): one initial task of a step. Its two object indices are also
/// its identity from frame to frame (the temporal state of aposteriori and hybrid is keyed by them).
struct Task {
  std::uint32_t a;  ///< object id
  std::uint32_t b;  ///< object id, > a
  friend bool operator==(const Task&, const Task&) = default;
  friend auto operator<=>(const Task&, const Task&) = default;
};

/// A contact between two objects of a scene, in world coordinates.
struct SceneContact {
  std::uint32_t object_a;  ///< object id (lower)
  std::uint32_t object_b;  ///< object id (higher)
  Contact contact;         ///< triangle ids, points, normal, distance (points unset for interference)
};

/// The work and result of one task in one step.
struct TaskRecord {
  Task task;                   ///< the object pair
  QueryStats stats;            ///< node and leaf tests
  std::size_t pairs = 0;       ///< triangle pairs reported
  bool limit_reached = false;  ///< more than QueryRequest::max_pairs were found: `pairs` is partial
  /// Triangle pairs the traversals kept, before the contact reduction and max_pairs: what the
  /// pair's finalization worked on.
  std::size_t candidates = 0;
};

/// One piece of a step's work on one thread (EngineOptions::timeline): what a Gantt chart draws.
struct TaskSpan {
  /// Which part of the step: the weight-driven stage of one split task, one unit of depth-first
  /// traversal (a run-time task, a pair, a stealing piece), or one pair's finalization.
  enum class Phase : std::uint8_t { stage, traverse, finalize };
  int thread = 0;         ///< the executor's thread index (0 .. threads-1)
  double start_ms = 0.0;  ///< since the start of the step's narrow phase
  double end_ms = 0.0;
  Phase phase = Phase::traverse;
  /// What was run: stage and finalize, the pair's index in the frame's pairs (StepResult::tasks);
  /// traverse, the run-time task's index in ScheduleRecord::task_node_tests (and task_roots), or,
  /// for stealing, the pair of the depth-first piece.
  std::uint32_t unit = 0;
};

/// Where a run-time task starts: a node of the CD tree of one of the step's pairs (a node of A's
/// BVH against a node of B's). A task traverses depth first from each of its roots.
struct TaskRoot {
  std::uint32_t pair = 0;    ///< index in the frame's pairs (StepResult::tasks)
  std::uint32_t node_a = 0;  ///< node of A's BVH (Model::nodes)
  std::uint32_t node_b = 0;  ///< node of B's BVH
};

/// How the engine cut and scheduled a step's work. The calibration fields are zero for the methods
/// that do not calibrate; `task_node_tests` is filled by every engine method.
struct ScheduleRecord {
  double omega = 0.0;                                ///< the caliber Omega (in weight units)
  std::size_t kept = 0;                              ///< initial tasks run as they are
  std::size_t split = 0;                             ///< initial tasks split by the weight-driven stage
  std::size_t carted = 0;                            ///< items merged in the cart (light tasks and light nodes)
  std::size_t generated = 0;                         ///< run-time tasks
  std::uint64_t stage_node_tests = 0;                ///< node tests made in the weight-driven stage
  std::size_t queue_peak = 0;                        ///< widest level of the weight-driven stage (nodes waiting at once)
  std::vector<std::uint64_t> stage_task_node_tests;  ///< node tests of the weight-driven stage, per split task
  /// The weight-driven stage level by level: for each level of each split task (the split tasks in
  /// the order of stage_task_node_tests, each one's levels from the root down), the node tests of
  /// each chunk of the level's nodes that one thread ran. A level waits for the one above it.
  std::vector<std::vector<std::uint64_t>> stage_levels;
  std::vector<std::uint32_t> stage_level_task;  ///< the split task (index in stage_task_node_tests) of each stage level
  /// Per split task, the stage's wall time outside its levels' parallel visits (taking each
  /// level's outcomes in order, the final sorts): serial within that task's stage.
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
  /// are in stage_task_node_tests).
  std::vector<std::uint64_t> thread_node_tests;
  double calibrate_ms = 0.0;  ///< calibrated methods: weights, keep/split/cart, weight-driven stage, cart
  double traverse_ms = 0.0;   ///< depth-first traversals of the run-time tasks (or pairs, or pieces)
  double finalize_ms = 0.0;   ///< per-pair merge, sort, local minima and world coordinates
  /// Every piece of work with its thread and times, sorted by thread then start; empty unless
  /// EngineOptions::timeline is on.
  std::vector<TaskSpan> timeline;
  /// The roots of each run-time task, in the order of task_node_tests (every method but stealing,
  /// whose pieces are cut while it runs); empty unless EngineOptions::timeline is on.
  std::vector<std::vector<TaskRoot>> task_roots;
};

/// Everything one step produced.
struct StepResult {
  int step = 0;                        ///< step index
  double time = 0.0;                   ///< simulated time (step * dt)
  double broad_ms = 0.0;               ///< broad-phase wall time
  double narrow_ms = 0.0;              ///< narrow-phase wall time (all tasks)
  double reduce_ms = 0.0;              ///< gathering and sorting the contacts
  std::vector<TaskRecord> tasks;       ///< one per initial task, in task order
  std::vector<SceneContact> contacts;  ///< sorted by (object a, object b, tri a, tri b)
  QueryStats stats;                    ///< totals over the tasks
  ScheduleRecord schedule;             ///< how the work was cut and scheduled
  bool limit_reached = false;          ///< some pair reached QueryRequest::max_pairs (its contacts are partial)
};

/// One moment of a set of rigid objects, as the engine takes it: whatever produced it (a scene's
/// World, a physics engine, a planner), the engine needs nothing else, no file and no scene.
struct Frame {
  /// The model of each object; objects may share one. None is null. Immutable and shared, so a
  /// program keeps its models from frame to frame and only the poses change.
  std::vector<std::shared_ptr<const Model>> models;
  /// The pose of each object (one per model).
  std::vector<Pose> poses;
  /// The object pairs to test: a < b < objects, sorted, each once (a broad phase's output, or every
  /// pair a program wants tested). Keep an object's index from frame to frame so that the temporal
  /// methods find a pair's history; Engine::forget() drops it.
  std::vector<Task> pairs;
  /// The query every pair runs (validated by Engine::step). A `groups` table it points to must
  /// outlive the step.
  QueryRequest request;
};

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
[[nodiscard]] CALIBER_EXPORT std::string_view to_string(Method method);
/// Parses a method name; throws caliber::Error on an unknown one.
[[nodiscard]] CALIBER_EXPORT Method parse_method(std::string_view name);

/// The default method of the library, the command line and the Python module: work stealing, the
/// fastest measured at 16 threads on three of the four benchmark scenes (16-core Intel Xeon,
/// medians of 5 interleaved rounds: stealing 7.9 / 6.9 / 9.5 / 10.2x, hybrid 8.7 / 2.3 / 9.1 /
/// 7.3x on two_large / two_small / funnel / front_car; bench/results/intel-xeon-16c/).
inline constexpr Method kDefaultMethod = Method::stealing;

/// Options of the engine.
struct EngineOptions {
  /// The method (kDefaultMethod unless told otherwise).
  Method method = kDefaultMethod;
  /// Where the engine runs (0..1024). 0: in the oneTBB arena step() is called from, with that
  /// arena's concurrency (a host's own tbb::task_arena, or oneTBB's default one, which follows the
  /// CPU affinity), at most the process's limit. 1: on the calling thread alone, creating no thread
  /// (a host that runs caliber from its own threads, such as OpenMP's). N > 1: a oneTBB arena of
  /// its own of N threads, at most the process's limit. caliber never changes the limit (no
  /// tbb::global_control). `sequential` always runs on the calling thread.
  int threads = 0;
  /// Calibrated methods: the thread count the cut is made for (Omega = total weight / (beta *
  /// plan_threads)); 0 means `threads`. The cut for P threads run on one thread measures each of
  /// its pieces undisturbed (what predicted_step_ms replays); the contacts are the same.
  int plan_threads = 0;
  /// Stealing: CD-tree depth from which a subtree is traversed serially by one task.
  int stealing_depth = 10;
  /// Calibration: overthreading factor beta (> 0): Omega = total weight / (beta * threads).
  /// Default 6, measured (bench/results/amd-epyc-2c/engine/calibration_sweep.md): with 2 threads, beta = 2
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
  /// Record ScheduleRecord::timeline (thread and times of every piece of work) and
  /// ScheduleRecord::task_roots. Costs two clock reads per piece; off by default.
  bool timeline = false;
};

/// Makespan, in node tests, of greedy list scheduling: each cost in order goes to the least-loaded
/// of `cores` virtual cores (the policy of a dynamic parallel loop with grain 1).
[[nodiscard]] CALIBER_EXPORT double list_schedule_makespan(const std::vector<std::uint64_t>& costs, int cores);

/// The load-balance simulation: the speed-up on `cores` virtual cores that the step's recorded
/// work units predict for `method` (total node tests / simulated makespan). Calibrated methods: the
/// weight-driven stage (each split task's levels in turn, a level's chunks list-scheduled, the split
/// tasks side by side), then a barrier, then the run-time tasks in handout order. Exploitation: the
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
/// part on its path; the split tasks side by side),
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

/// Runs frames with a method on the threads the host allows (EngineOptions::threads). Keeps,
/// between steps, what the temporal methods learn of each object pair. Not thread-safe itself: one
/// step at a time (use one engine per thread to step several at once).
class CALIBER_EXPORT Engine {
 public:
  /// Throws caliber::Error on a thread count outside 0..1024, a negative stealing depth, a beta
  /// that is not > 0, a negative epsilon or a taboo cap below 1.
  explicit Engine(const EngineOptions& options = {});
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// Tests every pair of the frame: the narrow phase and the reduction. The contacts are those of
  /// caliber::query on each pair, whatever the method or threads; `step`, `time` and `broad_ms`
  /// of the result are left to the caller (caliber::step fills them for a World).
  /// Throws caliber::Error, naming the problem, on a frame that breaks Frame's rules.
  [[nodiscard]] StepResult step(const Frame& frame);
  /// Drops what the temporal methods remember of every pair (after a jump in the motion, or when
  /// object indices start to denote other objects).
  void forget();
  /// The threads a step called from this thread now would run on (the caller included): 1 for
  /// `sequential` or threads = 1; else the arena's concurrency, at most the process's limit. A
  /// step cuts its work for that count.
  [[nodiscard]] int threads() const;
  /// The options as given.
  [[nodiscard]] const EngineOptions& options() const { return mOptions; }

 private:
  struct Impl;
  EngineOptions mOptions;
  std::unique_ptr<Impl> mImpl;
};

/// Checks a frame against Frame's rules; throws caliber::Error (source "frame") naming the first
/// problem. Engine::step calls it.
CALIBER_EXPORT void validate_frame(const Frame& frame);

}  // namespace caliber
