// World::sweep: a step's motion swept so that it follows the scene's motions exactly. Objects
// whose motion needs cuts inside the step (a fast turn, keys inside it) are swept pair by pair over
// the cuts of the two objects alone; the others in one Engine::sweep over the whole step.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "caliber/error.h"
#include "caliber/world.h"
#include "narrow/sweep_bounds.h"

namespace caliber {
namespace {

/// The most an object may turn in one piece: a quarter turn, well inside the half turn up to
/// which the slerp between the piece's two poses is the motion's own turn.
constexpr double kPieceTurn = 0.5 * std::numbers::pi;

/// The most pieces an object's turn may ask for in one step: a faster turn is refused.
constexpr double kMaxTurnPieces = 4096.0;

/// A time inside a piece, as a fraction of the step, rounded towards the step's start: the
/// mapping may not make a contact later than the piece found it.
double step_fraction(double begin, double end, double t0, double span, double t) {
  const double at = ((begin - t0) + t * (end - begin)) / span;
  return std::clamp(std::nextafter(std::nextafter(at, 0.0), 0.0), 0.0, 1.0);
}

/// The fastest turn (radians a second) of a motion within [t0, t1].
double turn_rate(const Motion& m, double t0, double t1) {
  if (m.type == Motion::Type::velocity) return m.angular.norm();
  if (m.type != Motion::Type::keyframes || m.keys.size() < 2) return 0.0;
  const auto& keys = m.keys;
  auto it = std::upper_bound(keys.begin(), keys.end(), t0, [](double t, const Keyframe& k) { return t < k.time; });
  std::size_t j = it == keys.begin() ? 0 : static_cast<std::size_t>(it - keys.begin()) - 1;
  double rate = 0.0;
  for (; j + 1 < keys.size() && keys[j].time < t1; ++j) {
    rate = std::max(rate, narrow::turn_angle(keys[j].orientation, keys[j + 1].orientation) / (keys[j + 1].time - keys[j].time));
  }
  return rate;
}

struct Swept {
  Eigen::Vector3d lo, hi;  ///< the box the object stays in over the step (its pieces' segments)
};

}  // namespace

std::vector<double> World::sweep_cuts(std::size_t i, int step) const {
  const double t0 = step * mScene.dt, t1 = (step + 1) * mScene.dt;
  const SceneObject& o = mScene.objects[i];
  const double turn = turn_rate(o.motion, t0, t1) * (t1 - t0);
  const double pieces = std::max(1.0, std::ceil(turn / kPieceTurn));
  if (!(pieces <= kMaxTurnPieces)) {
    throw Error(ErrorCode::bad_value, mScene.file.empty() ? "scene " + mScene.name : mScene.file.string(),
                "object '" + o.name + "' turns by " + std::to_string(turn) +
                    " radians in a step, more than the swept query follows (4,096 quarter turns); take a smaller dt");
  }
  std::vector<double> cuts;
  const auto n = static_cast<std::size_t>(pieces);
  for (std::size_t k = 1; k < n; ++k) cuts.push_back(t0 + (t1 - t0) * (static_cast<double>(k) / static_cast<double>(n)));
  if (o.motion.type == Motion::Type::keyframes) {
    const auto& keys = o.motion.keys;
    auto it = std::upper_bound(keys.begin(), keys.end(), t0, [](double t, const Keyframe& k) { return t < k.time; });
    for (; it != keys.end() && it->time < t1; ++it) cuts.push_back(it->time);
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  std::erase_if(cuts, [&](double t) { return !(t > t0 && t < t1); });
  return cuts;
}

std::vector<PairSweep> World::sweep(int step, Engine& engine, const SweepRequest& request) const {
  if (step == std::numeric_limits<int>::max()) throw Error(ErrorCode::bad_argument, "step", "has no step after it");
  validate_sweep_request(request);
  SweepRequest r = request;
  if (r.groups == nullptr) r.groups = mRequest.groups;
  const std::size_t n = mScene.objects.size();
  std::vector<std::vector<double>> cuts(n);
  std::vector<std::uint32_t> whole;  // objects swept over the whole step at once
  for (std::size_t i = 0; i < n; ++i) {
    cuts[i] = sweep_cuts(i, step);
    if (cuts[i].empty()) whole.push_back(static_cast<std::uint32_t>(i));
  }
  const std::vector<Pose> from = poses_at(step), to = poses_at(step + 1);
  if (whole.size() == n) return engine.sweep(mModels, from, to, r, mStatic, mIgnored);
  std::vector<PairSweep> out = sweep_whole(engine, r, whole, from, to);
  const std::vector<PairSweep> cut = sweep_cut(step, r, cuts);
  out.insert(out.end(), cut.begin(), cut.end());
  std::sort(out.begin(), out.end(), [](const PairSweep& x, const PairSweep& y) {
    return x.pair.a != y.pair.a ? x.pair.a < y.pair.a : x.pair.b < y.pair.b;
  });
  return out;
}

std::vector<PairSweep> World::sweep_whole(Engine& engine, const SweepRequest& request, const std::vector<std::uint32_t>& whole,
                                          const std::vector<Pose>& from, const std::vector<Pose>& to) const {
  if (whole.size() < 2) return {};
  std::vector<std::uint32_t> local(mModels.size(), std::numeric_limits<std::uint32_t>::max());
  std::vector<std::shared_ptr<const Model>> models;
  std::vector<Pose> a, b;
  std::vector<bool> fixed;
  for (const std::uint32_t i : whole) {
    local[i] = static_cast<std::uint32_t>(models.size());
    models.push_back(mModels[i]);
    a.push_back(from[i]);
    b.push_back(to[i]);
    fixed.push_back(mStatic[i]);
  }
  std::vector<ObjectPair> ignored;
  for (const ObjectPair& p : mIgnored) {
    if (local[p.a] != std::numeric_limits<std::uint32_t>::max() && local[p.b] != std::numeric_limits<std::uint32_t>::max()) {
      ignored.push_back(ObjectPair{local[p.a], local[p.b]});
    }
  }
  std::vector<PairSweep> out = engine.sweep(models, a, b, request, fixed, ignored);
  for (PairSweep& p : out) p.pair = ObjectPair{whole[p.pair.a], whole[p.pair.b]};
  return out;
}

std::vector<PairSweep> World::sweep_cut(int step, const SweepRequest& request,
                                        const std::vector<std::vector<double>>& cuts) const {
  const std::size_t n = mScene.objects.size();
  const double t0 = step * mScene.dt, t1 = (step + 1) * mScene.dt, span = t1 - t0;
  // Each object's box over the step: its pieces' segments (the origin's path within a piece),
  // grown as Engine::sweep grows a segment's box (radius, half the largest tolerance, margin).
  std::vector<Swept> boxes(n);
  double largest = 0.0, reach = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    largest = std::max(largest, mModels[i]->extent());
    boxes[i].lo = boxes[i].hi = object_pose(i, t0, step).translation;
    for (std::size_t k = 0; k <= cuts[i].size(); ++k) {
      const Eigen::Vector3d p = object_pose(i, k < cuts[i].size() ? cuts[i][k] : t1, step).translation;
      boxes[i].lo = boxes[i].lo.cwiseMin(p);
      boxes[i].hi = boxes[i].hi.cwiseMax(p);
      reach = std::max(reach, p.norm());
    }
  }
  const double margin = narrow::kSweepMargin * (2.0 * largest + reach) + narrow::kSweepFlush;
  const double tolerance = narrow::sweep_tolerance(request, largest, margin);
  for (std::size_t i = 0; i < n; ++i) {
    const double grow = mModels[i]->extent() + 0.5 * tolerance + margin;
    boxes[i].lo.array() -= grow;
    boxes[i].hi.array() += grow;
  }
  // The pairs with a cut object whose boxes overlap: sorted along x, each against those that start
  // before it ends.
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return boxes[x].lo.x() < boxes[y].lo.x(); });
  std::vector<std::uint64_t> skipped;
  for (const ObjectPair& p : mIgnored) skipped.push_back(std::uint64_t{p.a} << 32 | p.b);
  std::sort(skipped.begin(), skipped.end());
  std::vector<PairSweep> out;
  for (std::size_t x = 0; x < n; ++x) {
    for (std::size_t y = x + 1; y < n && boxes[order[y]].lo.x() <= boxes[order[x]].hi.x(); ++y) {
      const std::uint32_t a = std::min(order[x], order[y]), b = std::max(order[x], order[y]);
      if (cuts[a].empty() && cuts[b].empty()) continue;  // swept whole
      if ((mStatic[a] && mStatic[b]) || std::binary_search(skipped.begin(), skipped.end(), std::uint64_t{a} << 32 | b)) continue;
      if ((boxes[a].lo.array() > boxes[b].hi.array()).any() || (boxes[b].lo.array() > boxes[a].hi.array()).any()) continue;
      // The pair's pieces: both objects' cuts; the first piece where it is not free answers.
      std::vector<double> times{t0};
      std::merge(cuts[a].begin(), cuts[a].end(), cuts[b].begin(), cuts[b].end(), std::back_inserter(times));
      times.push_back(t1);
      times.erase(std::unique(times.begin(), times.end()), times.end());
      PairSweep found{ObjectPair{a, b}, {}};
      for (std::size_t k = 0; k + 1 < times.size(); ++k) {
        const SweptPose ma{object_pose(a, times[k], step), object_pose(a, times[k + 1], step)};
        const SweptPose mb{object_pose(b, times[k], step), object_pose(b, times[k + 1], step)};
        const SweepResult s =
            narrow::sweep_checked(*mModels[a], mModels[a]->extent(), ma, *mModels[b], mModels[b]->extent(), mb, request);
        found.result.queries += s.queries;
        found.result.stats.node_tests += s.stats.node_tests;
        found.result.stats.leaf_tests += s.stats.leaf_tests;
        if (s.status == SweepStatus::free) continue;
        found.result.status = s.status;
        found.result.time = step_fraction(times[k], times[k + 1], t0, span, s.time);
        found.result.closest = s.closest;
        out.push_back(found);
        break;
      }
    }
  }
  return out;
}

}  // namespace caliber
