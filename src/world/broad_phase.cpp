// The broad phase: sweep and prune along x over the objects' world boxes.

#include "caliber/broad_phase.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "caliber/error.h"
#include "world/world_box.h"

namespace caliber {
namespace {

using world::world_box;
using world::WorldBox;

Error bad(const std::string& problem) { return Error(ErrorCode::bad_argument, "broad phase", problem); }

}  // namespace

std::vector<ObjectPair> broad_phase(const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                                    double reach, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored) {
  const std::size_t n = models.size();
  if (poses.size() != n) throw bad(std::to_string(n) + " models but " + std::to_string(poses.size()) + " poses (one per object)");
  if (!fixed.empty() && fixed.size() != n) {
    throw bad(std::to_string(n) + " objects but " + std::to_string(fixed.size()) + " fixed flags (none, or one per object)");
  }
  if (!(reach >= 0.0) || !std::isfinite(reach)) throw Error(ErrorCode::bad_value, "broad phase", "reach must be finite and >= 0");
  for (std::size_t i = 0; i < n; ++i) {
    if (!models[i]) throw bad("object " + std::to_string(i) + " has no model");
    validate_pose(poses[i], "broad phase: pose of object " + std::to_string(i));
  }
  std::vector<ObjectPair> skip(ignored);
  for (const ObjectPair& p : skip) {
    if (p.a >= p.b || p.b >= n) {
      throw bad("ignored pair (" + std::to_string(p.a) + ", " + std::to_string(p.b) + ") must name two objects a < b < " +
                std::to_string(n));
    }
  }
  std::sort(skip.begin(), skip.end());

  const double grow = 0.5 * reach;
  std::vector<WorldBox> boxes;
  boxes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) boxes.push_back(world_box(*models[i], poses[i], grow));
  // Sweep and prune along x: sort by the boxes' low x, sweep, test y and z for the overlapping ones.
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return boxes[a].lo.x() < boxes[b].lo.x() || (boxes[a].lo.x() == boxes[b].lo.x() && a < b);
  });
  std::vector<ObjectPair> pairs;
  for (std::size_t i = 0; i < n; ++i) {
    const WorldBox& bi = boxes[order[i]];
    for (std::size_t j = i + 1; j < n && boxes[order[j]].lo.x() <= bi.hi.x(); ++j) {
      const WorldBox& bj = boxes[order[j]];
      if (bj.lo.y() > bi.hi.y() || bi.lo.y() > bj.hi.y() || bj.lo.z() > bi.hi.z() || bi.lo.z() > bj.hi.z()) continue;
      const ObjectPair p{std::min(order[i], order[j]), std::max(order[i], order[j])};
      if (!fixed.empty() && fixed[p.a] && fixed[p.b]) continue;
      if (std::binary_search(skip.begin(), skip.end(), p)) continue;
      pairs.push_back(p);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace caliber
