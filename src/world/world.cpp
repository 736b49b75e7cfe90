// The world: shared models, poses per step, the broad phase, the frames it makes.

#include "caliber/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <new>
#include <string>
#include <tuple>

#include "caliber/broad_phase.h"
#include "caliber/error.h"
#include "util/timing.h"
#include "broad/world_box.h"

namespace caliber {
namespace {

using broad::world_box;
using broad::WorldBox;

using util::Clock;
using util::ms_since;

/// How messages name a scene: its file, or its name for a scene built in memory.
std::string source_of(const Scene& scene) { return scene.file.empty() ? "scene " + scene.name : scene.file.string(); }

void check_object(std::size_t i, std::size_t objects) {
  if (i >= objects) {
    throw Error(ErrorCode::bad_argument, "object",
                "index " + std::to_string(i) + " is past the world's " + std::to_string(objects) + " objects");
  }
}

/// What parse_scene checks of a scene file, for a Scene built by hand: dt > 0, each object's
/// scale > 0 and refinement, finite numbers in its pose and motion, and a keyframe motion with
/// keys at finite, increasing times. (Where a motion takes an object is checked at each step,
/// poses_at.)
void check_scene(const Scene& scene) {
  const std::string source = source_of(scene);
  if (!(scene.dt > 0.0) || !std::isfinite(scene.dt)) throw Error(ErrorCode::bad_value, source, "dt must be finite and > 0");
  const auto finite = [](const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
    return p.allFinite() && q.coeffs().allFinite() && q.coeffs().squaredNorm() > 0.0;
  };
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    const std::string what = "object '" + o.name + "' (objects[" + std::to_string(i) + "])";
    if (!(o.scale > 0.0) || !std::isfinite(o.scale))
      throw Error(ErrorCode::bad_value, source, what + ": scale must be finite and > 0");
    if (o.refine < 0 || o.refine > 6) throw Error(ErrorCode::bad_value, source, what + ": refine must be in [0, 6]");
    const Motion& m = o.motion;
    if (m.type != Motion::Type::keyframes && !finite(o.pose.translation, o.pose.rotation)) {
      throw Error(ErrorCode::bad_value, source, what + ": its pose must be finite, with a non-zero quaternion");
    }
    if (!m.linear.allFinite() || !m.angular.allFinite()) {
      throw Error(ErrorCode::bad_value, source, what + ": its velocities must be finite");
    }
    if (m.type != Motion::Type::keyframes) continue;
    if (m.keys.empty()) throw Error(ErrorCode::bad_value, source, what + ": a keyframe motion needs at least one key");
    for (std::size_t k = 0; k < m.keys.size(); ++k) {
      const Keyframe& key = m.keys[k];
      const std::string at = what + ": key " + std::to_string(k);
      if (!std::isfinite(key.time) || (k > 0 && !(key.time > m.keys[k - 1].time))) {
        throw Error(ErrorCode::bad_value, source, at + ": key times must be finite and increase");
      }
      if (k > 0 && !std::isfinite(key.time - m.keys[k - 1].time)) {
        throw Error(ErrorCode::bad_value, source,
                    at + ": is too far from the key before it (their difference overflows a double)");
      }
      if (!finite(key.position, key.orientation)) {
        throw Error(ErrorCode::bad_value, source, at + ": its pose must be finite, with a non-zero quaternion");
      }
    }
  }
}

}  // namespace

World::World(const World& other)
    : mScene(other.mScene), mRequest(other.mRequest), mModels(other.mModels), mStatic(other.mStatic), mIgnored(other.mIgnored) {
  point_at_groups();
}

World::World(World&& other) noexcept
    : mScene(std::move(other.mScene)),
      mRequest(other.mRequest),
      mModels(std::move(other.mModels)),
      mStatic(std::move(other.mStatic)),
      mIgnored(std::move(other.mIgnored)) {
  point_at_groups();
}

World& World::operator=(const World& other) {
  if (this != &other) *this = World(other);
  return *this;
}

World& World::operator=(World&& other) noexcept {
  mScene = std::move(other.mScene);
  mRequest = other.mRequest;
  mModels = std::move(other.mModels);
  mStatic = std::move(other.mStatic);
  mIgnored = std::move(other.mIgnored);
  point_at_groups();
  return *this;
}

World::World(Scene scene, const WorldOptions& options) : mScene(std::move(scene)) {
  validate_request(mScene.query);
  check_scene(mScene);
  mRequest = mScene.query;
  point_at_groups();
  // One model per (file, scale, refinement, groups): objects that share all four share the BVH.
  using Key =
      std::tuple<std::string, double, int, std::uint8_t, std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint8_t>>>;
  std::map<Key, std::shared_ptr<const Model>> cache;
  std::map<std::string, Mesh> loaded;
  for (const SceneObject& o : mScene.objects) {
    std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint8_t>> ranges;
    for (const GroupRange& g : o.groups) ranges.emplace_back(g.first, g.count, g.group);
    const Key key{o.mesh.string(), o.scale, o.refine, o.group, ranges};
    auto it = cache.find(key);
    if (it == cache.end()) try {
        auto file = loaded.find(o.mesh.string());
        if (file == loaded.end()) file = loaded.emplace(o.mesh.string(), load_mesh(o.mesh)).first;
        Mesh mesh = refine_mesh(file->second, o.refine);
        if (o.scale != 1.0) {
          try {
            scale_mesh(mesh, o.scale);
          } catch (const Error& e) {  // the object and its key named, the mesh file in the message
            throw Error(
                e.code(), mScene.file.string(),
                "object '" + o.name + "' (objects[" + std::to_string(&o - mScene.objects.data()) + "].scale): " + e.what());
          }
        }
        if (o.group != 0 || !o.groups.empty()) {
          mesh.groups.assign(mesh.triangles.size(), o.group);
          for (const GroupRange& g : o.groups) {
            if (std::uint64_t{g.first} + g.count > mesh.triangles.size()) {
              throw Error(
                  ErrorCode::bad_value, mScene.file.string(),
                  "object '" + o.name + "': group range beyond its " + std::to_string(mesh.triangles.size()) + " triangles");
            }
            std::fill_n(mesh.groups.begin() + g.first, g.count, g.group);
          }
        }
        BuildOptions build;
        build.threads = options.threads;
        build.host = options.host;
        build.adjacency = mRequest.kind == QueryKind::contact;        // only the contact reduction reads it
        build.oriented_boxes = mRequest.kind == QueryKind::distance;  // only the distance bound reads them
        it = cache.emplace(key, build_model(std::move(mesh), build)).first;
      } catch (const std::bad_alloc&) {
        throw Error(ErrorCode::out_of_memory, o.mesh.string(),
                    "out of memory while loading and building the model of object '" + o.name + "'");
      }
    mModels.push_back(it->second);
    mStatic.push_back(o.motion.type == Motion::Type::fixed);
  }
  for (const auto& [a, b] : mScene.ignore) {
    if (a < 0 || a >= b || static_cast<std::size_t>(b) >= mScene.objects.size()) {
      throw Error(ErrorCode::bad_value, "scene " + mScene.name,
                  "ignored pair (" + std::to_string(a) + ", " + std::to_string(b) + ") must name two objects a < b");
    }
    mIgnored.push_back(ObjectPair{static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b)});
  }
}

std::size_t World::distinct_models() const {
  std::vector<const Model*> models;
  for (const auto& m : mModels) models.push_back(m.get());
  std::sort(models.begin(), models.end());
  return static_cast<std::size_t>(std::unique(models.begin(), models.end()) - models.begin());
}

std::size_t World::triangle_count() const {
  std::size_t n = 0;
  for (const auto& m : mModels) n += m->triangle_count();
  return n;
}

std::vector<Pose> World::poses_at(int step) const { return poses_at_time(step * mScene.dt, step); }

std::vector<Pose> World::poses_at_time(double t, int step) const {
  std::vector<Pose> poses;
  poses.reserve(mScene.objects.size());
  for (std::size_t i = 0; i < mScene.objects.size(); ++i) poses.push_back(object_pose(i, t, step));
  return poses;
}

Pose World::object_pose(std::size_t i, double t, int step) const {
  // A motion that leaves caliber's range is named by file, object and key.
  const SceneObject& o = mScene.objects[i];
  Pose pose = pose_at(o.pose, o.motion, t);
  {
    const Eigen::Vector3d& at = pose.translation;
    const bool far = !at.allFinite() || at.cwiseAbs().maxCoeff() > kMaxCoordinate;
    bool tiny = false;
    for (int k = 0; k < 3; ++k) tiny = tiny || (at[k] != 0.0 && std::abs(at[k]) < kMinCoordinate);
    if (!far && !tiny && pose.rotation.coeffs().allFinite()) return pose;
    const std::string source = source_of(mScene);
    // An object that does not move is out of range where it stands.
    const bool still = o.motion.type == Motion::Type::fixed;
    const std::string key = "objects[" + std::to_string(i) + (still ? "].position" : "].motion");
    if (tiny && !far) {
      throw Error(ErrorCode::bad_value, source,
                  "object '" + o.name + "' (" + key + ") has a translation component below 2^-120 (about 7.5e-37, the smallest " +
                      "non-zero coordinate caliber takes)" + (still ? std::string() : " at step " + std::to_string(step)));
    }
    if (far) {
      throw Error(ErrorCode::bad_value, source,
                  "object '" + o.name + "' (" + key + ") " +
                      (still ? std::string("lies beyond +-1e15 (caliber's limit on coordinates)")
                             : "moves beyond +-1e15 (caliber's limit on coordinates) by step " + std::to_string(step)));
    }
    throw Error(ErrorCode::bad_value, source,
                "object '" + o.name + "' (" + key + ".angular): the turn by step " + std::to_string(step) +
                    " (angular velocity x time) overflows a double");
  }
}

const Model& World::model(std::size_t i) const {
  check_object(i, mModels.size());
  return *mModels[i];
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> World::bounds(std::size_t i, const Pose& pose, double grow) const {
  check_object(i, mModels.size());
  validate_pose(pose, "pose");
  if (!(grow >= 0.0) || !std::isfinite(grow)) throw Error(ErrorCode::bad_value, "grow", "must be finite and >= 0");
  const WorldBox b = world_box(*mModels[i], pose, grow);
  return {b.lo, b.hi};
}

std::vector<ObjectPair> World::broad_phase(const std::vector<Pose>& poses) const {
  return caliber::broad_phase(mModels, poses, reach(mRequest), mStatic, mIgnored);
}

Frame World::posed_frame(int step) const {
  Frame frame;
  frame.poses = poses_at(step);
  frame.models = mModels;
  frame.request = mRequest;
  return frame;
}

Frame World::frame(int step) const {
  Frame frame = posed_frame(step);
  frame.pairs = broad_phase(frame.poses);
  return frame;
}

Frame World::frame(int step, Engine& engine) const {
  Frame frame = posed_frame(step);
  engine.find_pairs(frame, mStatic, mIgnored);
  return frame;
}

StepResult step(const World& world, Engine& engine, int k) {
  const auto start = Clock::now();
  const Frame frame = world.frame(k, engine);
  const double broad_ms = ms_since(start);
  StepResult out = engine.step(frame);
  out.step = k;
  out.time = k * world.scene().dt;
  out.broad_ms = broad_ms;
  return out;
}

}  // namespace caliber
