// World::sweep: a step's motion swept in pieces that follow the scene's motions exactly.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "caliber/error.h"
#include "caliber/world.h"

namespace caliber {
namespace {

/// The most a velocity motion may turn in one piece: a quarter turn, well inside the half turn up
/// to which the slerp between the piece's two poses is the motion's own turn.
constexpr double kPieceTurn = 0.5 * std::numbers::pi;

/// The most pieces a step's turns may ask for: a motion that turns more in one step is refused.
constexpr double kMaxTurnPieces = 4096.0;

/// A time inside a piece, as a fraction of the step, rounded towards the step's start: the
/// mapping may not make a contact later than the piece found it.
double step_fraction(double begin, double end, double t0, double span, double t) {
  const double at = ((begin - t0) + t * (end - begin)) / span;
  const double earlier = std::nextafter(std::nextafter(at, 0.0), 0.0);
  return std::clamp(earlier, 0.0, 1.0);
}

}  // namespace

std::vector<double> World::sweep_times(int step) const {
  const double t0 = step * mScene.dt, t1 = (step + 1) * mScene.dt;
  double pieces = 1.0;
  for (const SceneObject& o : mScene.objects) {
    if (o.motion.type != Motion::Type::velocity) continue;
    const double turn = o.motion.angular.norm() * (t1 - t0);
    const double need = std::ceil(turn / kPieceTurn);
    if (!(need <= kMaxTurnPieces)) {
      throw Error(ErrorCode::bad_value, mScene.file.empty() ? "scene " + mScene.name : mScene.file.string(),
                  "object '" + o.name + "' turns by " + std::to_string(turn) +
                      " radians in a step (angular velocity x dt), more than the swept query follows (4,096 quarter "
                      "turns); take a smaller dt");
    }
    pieces = std::max(pieces, need);
  }
  const auto n = static_cast<std::size_t>(pieces);
  std::vector<double> times(n + 1);
  for (std::size_t i = 0; i < n; ++i) times[i] = t0 + (t1 - t0) * (static_cast<double>(i) / static_cast<double>(n));
  times[n] = t1;
  for (const SceneObject& o : mScene.objects) {
    if (o.motion.type != Motion::Type::keyframes) continue;
    const auto& keys = o.motion.keys;
    auto it = std::upper_bound(keys.begin(), keys.end(), t0, [](double t, const Keyframe& k) { return t < k.time; });
    for (; it != keys.end() && it->time < t1; ++it) times.push_back(it->time);
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  return times;
}

std::vector<PairSweep> World::sweep(int step, Engine& engine, const SweepRequest& request) const {
  if (step == std::numeric_limits<int>::max()) throw Error(ErrorCode::bad_argument, "step", "has no step after it");
  validate_sweep_request(request);
  SweepRequest piece_request = request;
  if (piece_request.groups == nullptr) piece_request.groups = mRequest.groups;
  const std::vector<double> times = sweep_times(step);
  const std::size_t pieces = times.size() - 1;
  std::vector<Pose> from = poses_at(step);
  if (pieces == 1) return engine.sweep(mModels, from, poses_at(step + 1), piece_request, mStatic, mIgnored);
  // Piece by piece: a pair found (contact or undecided) is answered and left out of the pieces after.
  std::vector<ObjectPair> skip = mIgnored;
  std::vector<PairSweep> out;
  const double t0 = times.front(), span = times.back() - t0;
  for (std::size_t i = 0; i < pieces; ++i) {
    std::vector<Pose> to = i + 1 == pieces ? poses_at(step + 1) : poses_at_time(times[i + 1], step);
    std::vector<PairSweep> found = engine.sweep(mModels, from, to, piece_request, mStatic, skip);
    for (PairSweep& p : found) {
      p.result.time = step_fraction(times[i], times[i + 1], t0, span, p.result.time);
      skip.push_back(p.pair);
      out.push_back(p);
    }
    from = std::move(to);
  }
  std::sort(out.begin(), out.end(), [](const PairSweep& x, const PairSweep& y) {
    return x.pair.a != y.pair.a ? x.pair.a < y.pair.a : x.pair.b < y.pair.b;
  });
  return out;
}

}  // namespace caliber
