#pragma once
/// \file
/// The parallel engine: how a step's work is cut into tasks and scheduled on threads. Every method
/// runs the same traversal and returns byte-identical contacts; they differ only in the task list
/// and the schedule.

#include "caliber/export.h"
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "caliber/batch.h"
#include "caliber/executor.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"
#include "caliber/sweep.h"

namespace caliber {

struct ScheduleRecord;  // caliber/profile.h: the instrumentation, opt-in

/// An object pair to test (a < b) at a step. Its two object indices are also
/// its identity from frame to frame (the temporal state of aposteriori, hybrid and stealing is keyed
/// by them).
struct ObjectPair {
  std::uint32_t a;  ///< object id
  std::uint32_t b;  ///< object id, > a
  friend bool operator==(const ObjectPair&, const ObjectPair&) = default;
  friend auto operator<=>(const ObjectPair&, const ObjectPair&) = default;
};

/// One object pair's answer in a sweep of many objects (Engine::sweep).
struct PairSweep {
  ObjectPair pair;     ///< the object pair
  SweepResult result;  ///< caliber::sweep's answer for it
};

/// The work and result of one object pair in one step.
struct PairRecord {
  ObjectPair pair;             ///< the object pair
  QueryStats stats;            ///< node and leaf tests
  std::size_t contacts = 0;    ///< triangle pairs reported
  bool limit_reached = false;  ///< QueryRequest::max_pairs were found: it stopped, `contacts` may be partial
  /// Triangle pairs the traversals kept, before the contact reduction and max_pairs: what the
  /// pair's finalization worked on.
  std::size_t candidates = 0;
};

/// Everything one step produced.
struct StepResult {
  int step = 0;                          ///< step index
  double time = 0.0;                     ///< simulated time (step * dt)
  double broad_ms = 0.0;                 ///< broad-phase wall time
  double narrow_ms = 0.0;                ///< narrow-phase wall time (all pairs)
  double reduce_ms = 0.0;                ///< gathering and sorting the contacts
  std::vector<PairRecord> pair_records;  ///< one per object pair of the frame, in its order
  std::vector<Contact> contacts;         ///< every pair's contacts, sorted by (object_a, object_b, tri_a, tri_b)
  QueryStats stats;                      ///< totals over the pairs
  /// How the work was cut and scheduled (caliber/profile.h): null unless EngineOptions::profile
  /// (or timeline) is on.
  std::shared_ptr<const ScheduleRecord> schedule;
  bool limit_reached = false;  ///< some pair reached QueryRequest::max_pairs (its contacts may be partial)
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
  std::vector<ObjectPair> pairs;
  /// The query every pair runs (validated by Engine::step). A `groups` table it points to must
  /// outlive the step.
  QueryRequest request;
};

/// How a step's narrow phase is cut and scheduled.
enum class Method : std::uint8_t {
  sequential,    ///< one thread, the pairs one after another
  exploitation,  ///< a parallel loop over the pairs (the paper's "parallelism exploitation")
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
/// fastest measured at 16 threads on the four benchmark scenes, ahead of hybrid on each
/// (bench/results/intel-xeon-16c/engine/README.md).
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
  /// A host's own job system (caliber/executor.h): when given, the engine runs on the threads it
  /// lends for each call, at most `threads` of them (0: all it offers), and creates no thread of
  /// its own. The host must outlive the engine. Null (the default): oneTBB, as `threads` says.
  HostExecutor* host = nullptr;
  /// The thread count the cut is made for (calibrated methods: Omega = total weight / (beta *
  /// plan_threads); stealing: the heavy pairs' share, below); 0 means `threads`. Cut for one
  /// thread, every method runs each pair whole. The cut for P threads run on one thread measures
  /// each of its pieces undisturbed (what predicted_step_ms replays); the contacts are the same.
  int plan_threads = 0;
  /// Stealing: CD-tree depth from which a subtree is traversed serially by one job (the wide CD
  /// tree of interference, proximity and contact queries: at most the depth that gives about 32
  /// pieces a thread, 4 on 2 threads, 6 on 16, and for a pair with node tests last step the depth
  /// that gives its share of those pieces; the binary CD tree of distance queries at most the depth
  /// whose 2^depth reaches 2 x threads, 2 on 2 threads, 5 on 16). Only pairs whose share of
  /// the work (the larger of their share of the a priori weight and of last step's node tests, a
  /// pair without them counting its a priori weight scaled to node tests) is at least
  /// 1 / (64 x plan threads) are split; the others run whole, in a parallel loop over them.
  int stealing_depth = 10;
  /// Calibration: overthreading factor beta (> 0): Omega = total weight / (beta * threads).
  /// Default 6, measured (bench/results/amd-epyc-2c/engine/calibration_beta.md): with 2 threads, beta = 2
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
  /// Hand out how each step's work was cut and scheduled (StepResult::schedule, declared in
  /// caliber/profile.h with the load-balance simulation that replays it). Off by default.
  bool profile = false;
  /// Also record ScheduleRecord::timeline (thread and times of every piece of work) and
  /// ScheduleRecord::task_roots; implies `profile`. Costs two clock reads per piece; off by default.
  bool timeline = false;
  /// Called on the calling thread between the chunks of a long call: query_many every 8,192
  /// entries, sweep_many and sweep every 8,192 sweeps' worth of work. A host that wants to stop
  /// the call (Python on Ctrl-C) throws from it: the call ends by that exception, its results
  /// dropped, and the engine takes its next call as usual. Empty (default): never called.
  std::function<void()> between_chunks;
};

/// Runs frames with a method on the threads the host allows (EngineOptions::threads). Keeps,
/// between steps, what the temporal methods learn of each object pair. One step at a time: a step
/// or forget() called while another call on the same engine runs throws caliber::Error (use one
/// engine per thread to step several at once).
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
  /// Tests model A against model B at many poses: entry i answers caliber::query(a, poses_a[i], b,
  /// poses_b[i], request), bit for bit, whatever the method and threads. A side given one pose keeps
  /// it for every entry; otherwise both sides give the same number of poses. The entries run in
  /// parallel on the engine's threads. With max_pairs, or at least 8 entries per thread, each entry
  /// is traversed whole by one thread (with max_pairs, the pairs it finds first are then those
  /// caliber::query finds); fewer entries go through the method, which splits a heavy entry's
  /// traversal as it splits a heavy pair. Leaves what the temporal methods remember as it is.
  /// Throws caliber::Error on pose counts that do not match, a bad pose (named by its side and
  /// index) or a bad request, before any work.
  [[nodiscard]] BatchResult query_many(const Model& a, std::span<const Pose> poses_a, const Model& b,
                                       std::span<const Pose> poses_b, const QueryRequest& request);
  /// The broad phase on the engine's threads: sets frame.pairs to caliber::broad_phase(frame.models,
  /// frame.poses, reach(frame.request), fixed, ignored), the same pairs, starting from what it
  /// kept of the previous call (the objects' order in its tree, re-sorted only when the tree
  /// refitted over that order has grown by a quarter, and its buffers). Throws caliber::Error as
  /// caliber::broad_phase does, and on a bad request.
  void find_pairs(Frame& frame, const std::vector<bool>& fixed = {}, const std::vector<ObjectPair>& ignored = {});
  /// Continuous collision detection for many objects: object i moves from from[i] to to[i] (a
  /// SweptPose: translation linear, rotation by slerp). Every pair whose swept boxes overlap (the
  /// box of the segment its origin runs along, grown by its radius about the origin and by the
  /// tolerance) is swept with caliber::sweep, the pairs in parallel on the engine's threads.
  /// Returns the pairs whose sweep is not `free` (contact or undecided), sorted by pair; each
  /// answer is caliber::sweep's for that pair, whatever the method and threads (a heavy sweep's
  /// queries split as in sweep_many, its `stats` then counting the pieces' node tests), and no pair
  /// left out could have come within the tolerance. Pairs of two fixed objects and ignored pairs are skipped.
  /// Throws caliber::Error on counts that do not match, a bad pose (named by its object), a bad
  /// ignored pair or a bad request, before any work.
  [[nodiscard]] std::vector<PairSweep> sweep(const std::vector<std::shared_ptr<const Model>>& models,
                                             const std::vector<Pose>& from, const std::vector<Pose>& to,
                                             const SweepRequest& request = {}, const std::vector<bool>& fixed = {},
                                             const std::vector<ObjectPair>& ignored = {});
  /// Continuous collision detection for model A against model B along many motions: entry i
  /// answers caliber::sweep(a, motions_a[i], b, motions_b[i], request) (status, time, closest pair
  /// and query count, bit for bit, whatever the method and threads). A side given one motion
  /// keeps it for every entry; otherwise both sides give the same number. The sweeps run in
  /// parallel on the engine's threads; when fewer than 8 a thread are left, the next query of a
  /// sweep whose last was heavy is split by the engine's method as a heavy pair is (its `stats`
  /// then count the split traversal's node tests, which depend on the cut). Throws
  /// caliber::Error on counts that do not match, a bad pose (named "motions of B[3].end") or a
  /// bad request, before any work.
  [[nodiscard]] std::vector<SweepResult> sweep_many(const Model& a, std::span<const SweptPose> motions_a, const Model& b,
                                                    std::span<const SweptPose> motions_b, const SweepRequest& request = {});
  /// Drops what the temporal methods and the broad phase remember (after a jump in the motion, or
  /// when object indices start to denote other objects).
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
