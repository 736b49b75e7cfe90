#pragma once
/// \file
/// The world: a scene's meshes loaded once, models shared between objects that use the same mesh,
/// poses per step, the broad phase, and the sequential step. The parallel engine schedules the
/// explicit task list a step produces.

#include <cstdint>
#include <map>
#include <utility>
#include <memory>
#include <vector>

#include "caliber/model.h"
#include "caliber/query.h"
#include "caliber/scene.h"

namespace caliber {

/// One initial task: an object pair (a < b) that the broad phase kept.
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
  Task task;              ///< the object pair
  QueryStats stats;       ///< node and leaf tests
  std::size_t pairs = 0;  ///< triangle pairs reported
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
};

/// How the engine cut and scheduled a step's work. The calibration fields are zero for the methods
/// that do not calibrate; `task_node_tests` is filled by every engine method.
struct ScheduleRecord {
  double omega = 0.0;                          ///< the caliber Omega (in weight units)
  std::size_t kept = 0;                        ///< initial tasks run as they are
  std::size_t split = 0;                       ///< initial tasks split by the weight-driven stage
  std::size_t carted = 0;                      ///< items merged in the cart (light tasks and light nodes)
  std::size_t generated = 0;                   ///< run-time tasks
  std::uint64_t stage_node_tests = 0;          ///< node tests made in the weight-driven stage
  std::size_t queue_peak = 0;                  ///< widest level of the weight-driven stage (nodes waiting at once)
  std::vector<std::uint64_t> stage_task_node_tests;  ///< node tests of the weight-driven stage, per split task
  /// Node tests of each unit the scheduler ran, in the order it was handed out: the run-time tasks
  /// (calibrated methods), the pairs (sequential, exploitation), or the depth-first pieces below the
  /// cut-off and the single node tests above it (stealing). The load-balance simulation replays them.
  std::vector<std::uint64_t> task_node_tests;
  std::vector<double> task_weights;            ///< estimated weight of each run-time task (calibrated methods)
  std::uint64_t split_node_tests = 0;          ///< stealing: node tests made above the cut-off, while splitting
  std::size_t taboo = 0;                       ///< a posteriori: taboo nodes (sub-task roots) handed out
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
};

/// Everything one step produced.
struct StepResult {
  int step = 0;                         ///< step index
  double time = 0.0;                    ///< simulated time (step * dt)
  double broad_ms = 0.0;                ///< broad-phase wall time
  double narrow_ms = 0.0;               ///< narrow-phase wall time (all tasks)
  double reduce_ms = 0.0;               ///< gathering and sorting the contacts
  std::vector<TaskRecord> tasks;        ///< one per initial task, in task order
  std::vector<SceneContact> contacts;   ///< sorted by (object a, object b, tri a, tri b)
  QueryStats stats;                     ///< totals over the tasks
  ScheduleRecord schedule;              ///< how the work was cut and scheduled
};

/// The reduction of a step: per-task records and the contacts of every task, in task order (tasks
/// are sorted and each result is sorted, so the concatenation is canonical). Fills out.tasks,
/// out.contacts and out.stats; every method of the engine ends its step with it.
void gather_step(const std::vector<Task>& tasks, const std::vector<QueryResult>& results, StepResult& out);

/// The paper's Table 1 for a run, and its timing summary, accumulated step by step (no step is kept).
class RunStats {
 public:
  /// Adds one step.
  void add(const StepResult& step);

  /// Steps added.
  [[nodiscard]] std::size_t steps() const { return mStepMs.size(); }
  /// Median wall time of a step (broad + narrow + reduction), ms.
  [[nodiscard]] double median_step_ms() const;
  /// Mean wall time of a step, ms.
  [[nodiscard]] double mean_step_ms() const;
  /// Mean node tests per step.
  [[nodiscard]] double mean_node_tests() const;
  /// Mean contacts (reported pairs) per step.
  [[nodiscard]] double mean_contacts() const;
  /// Mean initial tasks (broad-phase pairs) per step.
  [[nodiscard]] double mean_tasks() const;
  /// Steps with at least one contact.
  [[nodiscard]] std::size_t steps_with_contacts() const { return mStepsWithContacts; }
  /// Distinct object pairs the broad phase kept over the run.
  [[nodiscard]] std::size_t candidate_pairs() const { return mPairWork.size(); }
  /// The object pair with the most node tests over the run, and its share of all node tests (0..1).
  [[nodiscard]] std::pair<Task, double> heaviest_pair() const;
  /// The pair with the second most node tests over the run, and its share.
  [[nodiscard]] std::pair<Task, double> second_heaviest_pair() const;

 private:
  [[nodiscard]] std::vector<std::pair<std::uint64_t, Task>> ranked() const;

  std::vector<double> mStepMs;
  std::uint64_t mNodeTests = 0;
  std::uint64_t mContacts = 0;
  std::uint64_t mTasks = 0;
  std::size_t mStepsWithContacts = 0;
  std::map<Task, std::uint64_t> mPairWork;
};

/// A loaded scene. Immutable after construction: `step` may be called from any thread.
class World {
 public:
  /// Loads every mesh once (objects that share file, scale and refinement share one Model) and
  /// builds the models. Throws caliber::Error on bad meshes (naming the object and file).
  explicit World(Scene scene);

  /// The scene.
  [[nodiscard]] const Scene& scene() const { return mScene; }
  /// Number of objects.
  [[nodiscard]] std::size_t object_count() const { return mScene.objects.size(); }
  /// The model of object i (shared between objects with the same mesh).
  [[nodiscard]] const Model& model(std::size_t i) const { return *mModels[i]; }
  /// Number of distinct models built.
  [[nodiscard]] std::size_t distinct_models() const;
  /// Total triangles over the objects.
  [[nodiscard]] std::size_t triangle_count() const;

  /// The poses of all objects at step k.
  [[nodiscard]] std::vector<Pose> poses_at(int step) const;
  /// World-space box of object i at `pose` (its root box moved by the pose, grown by `grow` and a
  /// rounding margin), as the broad phase uses it: low corner, high corner.
  [[nodiscard]] std::pair<Eigen::Vector3d, Eigen::Vector3d> bounds(std::size_t i, const Pose& pose, double grow) const;
  /// The broad phase: object pairs whose world boxes, grown by the tolerance, overlap; pairs of two
  /// static objects and ignored pairs are skipped. Sorted. Sweep and prune along x.
  [[nodiscard]] std::vector<Task> broad_phase(const std::vector<Pose>& poses) const;
  /// Runs one query per task, one after another, and gathers the contacts canonically sorted.
  [[nodiscard]] StepResult step(int step) const;
  /// The query request every task runs (with the scene's group compatibility when it has one).
  [[nodiscard]] const QueryRequest& request() const { return mRequest; }

 private:
  Scene mScene;
  QueryRequest mRequest;
  std::vector<std::shared_ptr<const Model>> mModels;
  std::vector<bool> mStatic;
};

}  // namespace caliber
