// The broad phase: the objects' world boxes and the pairs whose boxes overlap (broad/box_tree.h).

#include "broad/broad_phase.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "caliber/broad_phase.h"
#include "caliber/error.h"
#include "caliber/mesh.h"
#include "mesh/pose_check.h"
#include "parallel/executor.h"

namespace caliber {
namespace broad {
void validate_objects(const char* source, const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                      const char* pose_name, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored) {
  const auto bad = [&](const std::string& problem) { return Error(ErrorCode::bad_argument, source, problem); };
  const std::size_t n = models.size();
  if (poses.size() != n) {
    throw bad(std::to_string(n) + " models but " + std::to_string(poses.size()) + " " + pose_name + "s (one per object)");
  }
  if (!fixed.empty() && fixed.size() != n) {
    throw bad(std::to_string(n) + " objects but " + std::to_string(fixed.size()) + " fixed flags (none, or one per object)");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!models[i]) throw bad("object " + std::to_string(i) + " has no model");
    validate_pose_named(poses[i], [&] { return std::string(source) + ": " + pose_name + " of object " + std::to_string(i); });
  }
  for (const ObjectPair& p : ignored) {
    if (p.a >= p.b || p.b >= n) {
      throw bad("ignored pair (" + std::to_string(p.a) + ", " + std::to_string(p.b) + ") must name two objects a < b < " +
                std::to_string(n));
    }
  }
}

void pair_keys(const std::vector<ObjectPair>& pairs, std::vector<std::uint64_t>& keys) {
  keys.clear();
  for (const ObjectPair& p : pairs) keys.push_back(std::uint64_t{p.a} << 32 | p.b);
  std::sort(keys.begin(), keys.end());
}

void find_pairs(State& state, const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                double reach, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored,
                std::vector<ObjectPair>& out) {
  validate_objects("broad phase", models, poses, "pose", fixed, ignored);
  // As a query's tolerance (validate_request): a reach past caliber's range would grow every box
  // past the range its exact tests are proved in.
  if (!(reach >= 0.0) || !std::isfinite(reach) || reach > kMaxCoordinate) {
    char given[32];
    std::snprintf(given, sizeof given, "%g", reach);
    throw Error(ErrorCode::bad_value, "reach",
                std::string("must be finite, >= 0 and at most 1e15 (caliber's limit on coordinates), not ") + given);
  }
  pair_keys(ignored, state.ignored);
  const std::size_t n = models.size();
  const double grow = 0.5 * reach;
  state.boxes.resize(n);
  parallel::parallel_for(0, n, 4096, [&](std::size_t first, std::size_t last) {
    for (std::size_t i = first; i != last; ++i) state.boxes[i] = world_box(*models[i], poses[i], grow);
  });
  const PairFilter filter{fixed.empty() ? nullptr : &fixed, state.ignored.empty() ? nullptr : &state.ignored};
  state.tree.pairs(state.boxes, filter, out);
}

}  // namespace broad

std::vector<ObjectPair> broad_phase(const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                                    double reach, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored) {
  broad::State state;
  std::vector<ObjectPair> pairs;
  broad::find_pairs(state, models, poses, reach, fixed, ignored, pairs);
  return pairs;
}

}  // namespace caliber
