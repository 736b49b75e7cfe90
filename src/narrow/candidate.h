#pragma once
/// \file
/// What the leaf test keeps of a triangle pair, and the order of closeness every part agrees on.

#include <cstdint>

#include <Eigen/Core>

namespace caliber {

/// A triangle pair: triangle of A, triangle of B (what the a posteriori weights keep of a step).
struct TrianglePair {
  std::uint32_t tri_a;  ///< triangle id in model A
  std::uint32_t tri_b;  ///< triangle id in model B
  friend bool operator==(const TrianglePair&, const TrianglePair&) = default;
  friend auto operator<=>(const TrianglePair&, const TrianglePair&) = default;
};

}  // namespace caliber

namespace caliber::narrow {

/// A triangle pair kept by the leaf test, in model A's frame.
struct Candidate {
  std::uint32_t tri_a;      ///< triangle of A
  std::uint32_t tri_b;      ///< triangle of B
  double distance;          ///< 0 when the triangles intersect
  Eigen::Vector3d point_a;  ///< closest point on A (A's frame); unset for interference
  Eigen::Vector3d point_b;  ///< closest point on B (A's frame); unset for interference
};

/// The order of closeness every traversal and the finalization agree on: closer first, then lower
/// triangle ids (a strict total order on a pair's candidates).
[[nodiscard]] inline bool closer(const Candidate& x, const Candidate& y) {
  if (x.distance != y.distance) return x.distance < y.distance;
  if (x.tri_a != y.tri_a) return x.tri_a < y.tri_a;
  return x.tri_b < y.tri_b;
}

}  // namespace caliber::narrow
