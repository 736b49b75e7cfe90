// The world: shared models, poses per step, broad phase (sweep and prune), the sequential step.

#include "caliber/world.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <tuple>

#include "caliber/error.h"

namespace caliber {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

/// A world-space box of an object: its root box moved by its pose (conservative: |R| h).
struct WorldBox {
  Eigen::Vector3d lo, hi;
};

WorldBox world_box(const Model& m, const Pose& pose, double grow) {
  const BvhNode& root = m.nodes[0];
  const Eigen::Vector3d c(root.box_center[0], root.box_center[1], root.box_center[2]);
  const Eigen::Vector3d h(root.box_half[0], root.box_half[1], root.box_half[2]);
  const Eigen::Matrix3d r = pose.rotation_matrix();
  const Eigen::Vector3d center = r * c + pose.translation;
  const Eigen::Vector3d half = r.cwiseAbs() * h;
  // The same kind of safety margin as the narrow phase: rounding never drops a pair.
  const double margin = grow + 1e-9 * (m.extent + pose.translation.norm() + grow);
  return {center - half - Eigen::Vector3d::Constant(margin), center + half + Eigen::Vector3d::Constant(margin)};
}

}  // namespace

World::World(Scene scene) : mScene(std::move(scene)) {
  validate_request(mScene.query);
  mRequest = mScene.query;
  mRequest.groups = mScene.use_groups ? &mScene.compatibility : nullptr;
  // One model per (file, scale, refinement, groups): objects that share all four share the BVH.
  using Key = std::tuple<std::string, double, int, std::uint8_t, std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint8_t>>>;
  std::map<Key, std::shared_ptr<const Model>> cache;
  std::map<std::string, Mesh> loaded;
  for (const SceneObject& o : mScene.objects) {
    std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint8_t>> ranges;
    for (const GroupRange& g : o.groups) ranges.emplace_back(g.first, g.count, g.group);
    const Key key{o.mesh.string(), o.scale, o.refine, o.group, ranges};
    auto it = cache.find(key);
    if (it == cache.end()) {
      auto file = loaded.find(o.mesh.string());
      if (file == loaded.end()) file = loaded.emplace(o.mesh.string(), load_mesh(o.mesh)).first;
      Mesh mesh = refine_mesh(file->second, o.refine);
      if (o.scale != 1.0) scale_mesh(mesh, o.scale);
      if (o.group != 0 || !o.groups.empty()) {
        mesh.groups.assign(mesh.triangles.size(), o.group);
        for (const GroupRange& g : o.groups) {
          if (std::uint64_t{g.first} + g.count > mesh.triangles.size()) {
            throw Error(ErrorCode::bad_value, mScene.file.string(),
                        "object '" + o.name + "': group range beyond its " + std::to_string(mesh.triangles.size()) + " triangles");
          }
          std::fill_n(mesh.groups.begin() + g.first, g.count, g.group);
        }
      }
      it = cache.emplace(key, build_model(std::move(mesh))).first;
    }
    mModels.push_back(it->second);
    mStatic.push_back(o.motion.type == Motion::Type::fixed);
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
  for (const auto& m : mModels) n += m->mesh.triangles.size();
  return n;
}

std::vector<Pose> World::poses_at(int step) const {
  std::vector<Pose> poses;
  poses.reserve(mScene.objects.size());
  const double t = step * mScene.dt;
  for (const SceneObject& o : mScene.objects) {
    poses.push_back(pose_at(o.pose, o.motion, t));
    if (!poses.back().translation.allFinite() || poses.back().translation.cwiseAbs().maxCoeff() > kMaxCoordinate) {
      throw Error(ErrorCode::bad_value, "scene " + mScene.name,
                  "object '" + o.name + "' moves beyond +-1e15 (caliber's limit on coordinates) by step " +
                      std::to_string(step));
    }
  }
  return poses;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> World::bounds(std::size_t i, const Pose& pose, double grow) const {
  const WorldBox b = world_box(*mModels[i], pose, grow);
  return {b.lo, b.hi};
}

std::vector<Task> World::broad_phase(const std::vector<Pose>& poses) const {
  const std::size_t n = mScene.objects.size();
  const double grow = mRequest.kind == QueryKind::interference ? 0.0 : 0.5 * mRequest.tolerance;
  std::vector<WorldBox> boxes;
  boxes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) boxes.push_back(world_box(*mModels[i], poses[i], grow));
  // Sweep and prune along x: sort by the boxes' low x, sweep, test y and z for the overlapping ones.
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return boxes[a].lo.x() < boxes[b].lo.x() || (boxes[a].lo.x() == boxes[b].lo.x() && a < b);
  });
  std::vector<Task> tasks;
  for (std::size_t i = 0; i < n; ++i) {
    const WorldBox& bi = boxes[order[i]];
    for (std::size_t j = i + 1; j < n && boxes[order[j]].lo.x() <= bi.hi.x(); ++j) {
      const WorldBox& bj = boxes[order[j]];
      if (bj.lo.y() > bi.hi.y() || bi.lo.y() > bj.hi.y() || bj.lo.z() > bi.hi.z() || bi.lo.z() > bj.hi.z()) continue;
      const std::uint32_t a = std::min(order[i], order[j]);
      const std::uint32_t b = std::max(order[i], order[j]);
      if (mStatic[a] && mStatic[b]) continue;
      if (std::find(mScene.ignore.begin(), mScene.ignore.end(), std::pair<int, int>(int(a), int(b))) != mScene.ignore.end()) continue;
      tasks.push_back(Task{a, b});
    }
  }
  std::sort(tasks.begin(), tasks.end());
  return tasks;
}

StepResult World::step(int step) const {
  StepResult out;
  out.step = step;
  out.time = step * mScene.dt;
  auto start = Clock::now();
  const std::vector<Pose> poses = poses_at(step);
  const std::vector<Task> tasks = broad_phase(poses);
  out.broad_ms = ms_since(start);

  start = Clock::now();
  std::vector<QueryResult> results;
  results.reserve(tasks.size());
  for (const Task& t : tasks) results.push_back(query(*mModels[t.a], poses[t.a], *mModels[t.b], poses[t.b], mRequest));
  out.narrow_ms = ms_since(start);

  start = Clock::now();
  gather_step(tasks, results, out);
  out.reduce_ms = ms_since(start);
  return out;
}

void gather_step(const std::vector<Task>& tasks, const std::vector<QueryResult>& results, StepResult& out) {
  out.tasks.clear();
  out.contacts.clear();
  out.stats = QueryStats{};
  std::size_t total = 0;
  for (const QueryResult& r : results) total += r.pairs.size();
  out.contacts.reserve(total);
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const QueryResult& r = results[i];
    out.tasks.push_back(TaskRecord{tasks[i], r.stats, r.pairs.size()});
    out.stats.node_tests += r.stats.node_tests;
    out.stats.leaf_tests += r.stats.leaf_tests;
    for (std::size_t k = 0; k < r.pairs.size(); ++k) {
      SceneContact c{tasks[i].a, tasks[i].b, {}};
      if (r.contacts.empty()) {
        c.contact.tri_a = r.pairs[k].tri_a;
        c.contact.tri_b = r.pairs[k].tri_b;
        c.contact.point_a = c.contact.point_b = c.contact.normal = Eigen::Vector3d::Zero();
      } else {
        c.contact = r.contacts[k];
      }
      out.contacts.push_back(c);
    }
  }
}

}  // namespace caliber

namespace caliber {

void RunStats::add(const StepResult& step) {
  mStepMs.push_back(step.broad_ms + step.narrow_ms + step.reduce_ms);
  mNodeTests += step.stats.node_tests;
  mContacts += step.contacts.size();
  mTasks += step.tasks.size();
  if (!step.contacts.empty()) ++mStepsWithContacts;
  for (const TaskRecord& t : step.tasks) mPairWork[t.task] += t.stats.node_tests;
}

double RunStats::median_step_ms() const {
  if (mStepMs.empty()) return 0.0;
  std::vector<double> sorted = mStepMs;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t n = sorted.size();
  return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

double RunStats::mean_step_ms() const {
  double sum = 0.0;
  for (const double t : mStepMs) sum += t;
  return mStepMs.empty() ? 0.0 : sum / static_cast<double>(mStepMs.size());
}

double RunStats::mean_node_tests() const { return steps() ? double(mNodeTests) / double(steps()) : 0.0; }
double RunStats::mean_contacts() const { return steps() ? double(mContacts) / double(steps()) : 0.0; }
double RunStats::mean_tasks() const { return steps() ? double(mTasks) / double(steps()) : 0.0; }

std::vector<std::pair<std::uint64_t, Task>> RunStats::ranked() const {
  std::vector<std::pair<std::uint64_t, Task>> r;
  for (const auto& [task, work] : mPairWork) r.emplace_back(work, task);
  std::sort(r.begin(), r.end(), [](const auto& x, const auto& y) { return x.first != y.first ? x.first > y.first : x.second < y.second; });
  return r;
}

std::pair<Task, double> RunStats::heaviest_pair() const {
  const auto r = ranked();
  if (r.empty() || mNodeTests == 0) return {Task{0, 0}, 0.0};
  return {r[0].second, double(r[0].first) / double(mNodeTests)};
}

std::pair<Task, double> RunStats::second_heaviest_pair() const {
  const auto r = ranked();
  if (r.size() < 2 || mNodeTests == 0) return {Task{0, 0}, 0.0};
  return {r[1].second, double(r[1].first) / double(mNodeTests)};
}

}  // namespace caliber
