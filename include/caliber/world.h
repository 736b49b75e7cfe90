#pragma once
/// \file
/// The world: a scene's meshes loaded once, models shared between objects that use the same mesh,
/// poses per step and the broad phase, which together make each step's Frame for the engine.

#include "caliber/export.h"
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "caliber/engine.h"
#include "caliber/model.h"
#include "caliber/query.h"
#include "caliber/scene.h"

namespace caliber {

/// Where a World builds its models, as BuildOptions::threads and BuildOptions::host: by default in
/// the oneTBB arena the World is made in; with a host (caliber/executor.h), on the threads it lends
/// and on no thread of caliber's own. The models are the same whatever the threads.
struct WorldOptions {
  int threads = 0;               ///< 0 .. 1024, as BuildOptions::threads
  HostExecutor* host = nullptr;  ///< a host's own job system, or none
};

/// A loaded scene. Immutable after construction: `frame` may be called from any thread.
class CALIBER_EXPORT World {
 public:
  /// Loads every mesh once (objects that share file, scale and refinement share one Model) and
  /// builds the models where `options` says. Throws caliber::Error on bad meshes (naming the
  /// object and file) and on a thread count out of range.
  explicit World(Scene scene, const WorldOptions& options = {});
  /// Copies and moves keep the request's group table pointing at their own scene's.
  World(const World& other);
  World(World&& other) noexcept;
  World& operator=(const World& other);
  World& operator=(World&& other) noexcept;
  ~World() = default;

  /// The scene.
  [[nodiscard]] const Scene& scene() const { return mScene; }
  /// Number of objects.
  [[nodiscard]] std::size_t object_count() const { return mScene.objects.size(); }
  /// The model of object i (shared between objects with the same mesh); Error for an i past the
  /// objects.
  [[nodiscard]] const Model& model(std::size_t i) const;
  /// Number of distinct models built.
  [[nodiscard]] std::size_t distinct_models() const;
  /// Total triangles over the objects.
  [[nodiscard]] std::size_t triangle_count() const;

  /// The poses of all objects at step k.
  [[nodiscard]] std::vector<Pose> poses_at(int step) const;
  /// World-space box of object i at `pose` (its root box moved by the pose, grown by `grow` and a
  /// rounding margin), as the broad phase uses it: low corner, high corner. Error for an i past
  /// the objects, a pose validate_pose refuses, or a grow that is not finite and >= 0.
  [[nodiscard]] std::pair<Eigen::Vector3d, Eigen::Vector3d> bounds(std::size_t i, const Pose& pose, double grow) const;
  /// The broad phase (caliber::broad_phase): object pairs whose world boxes, grown by the tolerance,
  /// overlap; pairs of two static objects and ignored pairs are skipped. Sorted.
  [[nodiscard]] std::vector<ObjectPair> broad_phase(const std::vector<Pose>& poses) const;
  /// Step k as a frame: every object's model and pose, the broad phase's pairs, the request.
  /// The frame points to this world's group table: it must not outlive the world.
  [[nodiscard]] Frame frame(int step) const;
  /// Step k as a frame whose pairs the engine's broad phase finds (Engine::find_pairs: the same
  /// pairs, on the engine's threads, from what it kept of the previous step). Not const on the
  /// engine: one engine per thread.
  [[nodiscard]] Frame frame(int step, Engine& engine) const;
  /// The pairs that come within the tolerance between step k and step k + 1, each object moving
  /// along the scene's own motion. An object that turns more than a quarter turn in the step, or
  /// has keys inside it, has its motion cut there (pieces of at most a quarter turn, ending at its
  /// keys): within a piece its motion is a SweptPose's. Pairs of objects without cuts are swept
  /// whole by Engine::sweep (on its threads); a pair with cuts over both objects' pieces, one
  /// after another on the calling thread (caliber::sweep's answer for each), its answer that of
  /// the first piece where it is not free (its queries and stats count every piece swept). The
  /// scene's groups apply unless the request names its own. Pairs of two static objects and
  /// ignored pairs are skipped. The times are fractions of the step: t* = 0.25 is a quarter of the
  /// way from k to k + 1. Throws caliber::Error naming the object when a motion turns more than
  /// 4,096 quarter turns in a step.
  [[nodiscard]] std::vector<PairSweep> sweep(int step, Engine& engine, const SweepRequest& request = {}) const;
  /// The query request every pair runs (with the scene's group compatibility when it has one).
  [[nodiscard]] const QueryRequest& request() const { return mRequest; }

 private:
  /// mRequest.groups: this world's group table, or null when the scene has none.
  void point_at_groups() { mRequest.groups = mScene.use_groups ? &mScene.compatibility : nullptr; }
  /// Step k's models, poses and request, without pairs.
  [[nodiscard]] Frame posed_frame(int step) const;
  /// The poses of all objects at time t (seconds), inside step `step` (named in errors).
  [[nodiscard]] std::vector<Pose> poses_at_time(double t, int step) const;
  /// Object i's pose at time t, inside step `step` (named in errors).
  [[nodiscard]] Pose object_pose(std::size_t i, double t, int step) const;
  /// The times (seconds) strictly inside step k at which object i's motion is cut for the swept
  /// query: pieces in which it turns at most a quarter turn, cut at every key of its own inside.
  [[nodiscard]] std::vector<double> sweep_cuts(std::size_t i, int step) const;
  /// World::sweep's pairs of two objects in `whole` (no cuts): one Engine::sweep over the step.
  [[nodiscard]] std::vector<PairSweep> sweep_whole(Engine& engine, const SweepRequest& request,
                                                   const std::vector<std::uint32_t>& whole, const std::vector<Pose>& from,
                                                   const std::vector<Pose>& to) const;
  /// World::sweep's pairs with an object that has cuts (cuts[i]: sweep_cuts(i, step)): each
  /// pair swept over both objects' pieces, one after another.
  [[nodiscard]] std::vector<PairSweep> sweep_cut(int step, const SweepRequest& request,
                                                 const std::vector<std::vector<double>>& cuts) const;

  Scene mScene;
  QueryRequest mRequest;
  std::vector<std::shared_ptr<const Model>> mModels;
  std::vector<bool> mStatic;
  std::vector<ObjectPair> mIgnored;
};

/// Step k of a world on an engine: its frame (poses and the engine's broad phase, timed as
/// broad_ms), then engine.step; fills the result's step, time and broad_ms. k is any step: the
/// poses follow the scene's motions at time k dt, within its `steps` (what `caliber run` runs) or
/// beyond.
[[nodiscard]] CALIBER_EXPORT StepResult step(const World& world, Engine& engine, int k);

}  // namespace caliber
