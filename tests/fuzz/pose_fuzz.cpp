// Fuzz target: the pose parser ("tx ty tz qw qx qy qz"), Pose::from_values on raw doubles, and the
// query request check. What they accept must be finite with a unit quaternion.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string_view>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/pose.h"
#include "caliber/query.h"
#include "fuzz_target.h"

namespace {

/// Anything accepted must be usable: validate_pose passes (finite, within the coordinate limit,
/// unit quaternion) and applying it gives finite points. Otherwise: abort, a finding.
void check(const caliber::Pose& p) {
  try {
    caliber::validate_pose(p, "accepted pose");
  } catch (const caliber::Error& e) {
    std::fprintf(stderr, "accepted a pose that validate_pose rejects: %s\n", e.what());
    std::abort();
  }
  if (!p.apply(Eigen::Vector3d(1, 2, 3)).allFinite()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::optional<caliber::Pose> parsed;
  try {
    parsed = caliber::parse_pose(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz");
  } catch (const caliber::Error&) {}
  if (parsed) check(*parsed);
  if (size >= 7 * sizeof(double)) {
    double v[9] = {};
    std::memcpy(v, data, std::min(size, sizeof v));
    std::optional<caliber::Pose> built;
    try {
      built = caliber::Pose::from_values(v[0], v[1], v[2], v[3], v[4], v[5], v[6], "fuzz");
    } catch (const caliber::Error&) {}
    if (built) check(*built);
    try {
      caliber::validate_request(caliber::QueryRequest{caliber::QueryKind::contact, v[7], v[8], nullptr});
      if (!(v[7] >= 0 && v[7] <= caliber::kMaxCoordinate && v[8] >= 0 && v[8] <= 180)) std::abort();
    } catch (const caliber::Error&) {}
  }
  return 0;
}
