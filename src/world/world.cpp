// The world: shared models, poses per step, the broad phase, the frames it makes.

#include "caliber/world.h"

#include <algorithm>
#include <map>
#include <new>
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

}  // namespace

World::World(Scene scene) : mScene(std::move(scene)) {
  validate_request(mScene.query);
  mRequest = mScene.query;
  mRequest.groups = mScene.use_groups ? &mScene.compatibility : nullptr;
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
        if (o.scale != 1.0) scale_mesh(mesh, o.scale);
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

std::vector<Pose> World::poses_at(int step) const {
  std::vector<Pose> poses;
  poses.reserve(mScene.objects.size());
  const double t = step * mScene.dt;
  // A motion that leaves caliber's range is named by file, object and key.
  const std::string source = mScene.file.empty() ? "scene " + mScene.name : mScene.file.string();
  for (std::size_t i = 0; i < mScene.objects.size(); ++i) {
    const SceneObject& o = mScene.objects[i];
    poses.push_back(pose_at(o.pose, o.motion, t));
    const bool far = !poses.back().translation.allFinite() || poses.back().translation.cwiseAbs().maxCoeff() > kMaxCoordinate;
    if (!far && poses.back().rotation.coeffs().allFinite()) continue;
    const std::string key = "objects[" + std::to_string(i) + "].motion";
    if (far) {
      throw Error(ErrorCode::bad_value, source,
                  "object '" + o.name + "' (" + key + ") moves beyond +-1e15 (caliber's limit on coordinates) by step " +
                      std::to_string(step));
    }
    throw Error(ErrorCode::bad_value, source,
                "object '" + o.name + "' (" + key + ".angular): the turn by step " + std::to_string(step) +
                    " (angular velocity x time) overflows a double");
  }
  return poses;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> World::bounds(std::size_t i, const Pose& pose, double grow) const {
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

std::vector<PairSweep> World::sweep(int step, Engine& engine, const SweepRequest& request) const {
  return engine.sweep(mModels, poses_at(step), poses_at(step + 1), request, mStatic, mIgnored);
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
