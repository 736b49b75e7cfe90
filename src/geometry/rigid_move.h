#pragma once
/// \file
/// The one formula by which caliber moves a vertex into another model's frame: r v + t, each row's
/// three products summed left to right, then the translation added. Written out rather than left
/// to Eigen's product, which sums the rows of a 3x3 in different orders (the last row's last two
/// products first), so that the lanes of a leaf batch (PairContext::gather_corners) compute the
/// same bits as a single vertex (PairContext::b_vertex).

#include <Eigen/Core>

namespace caliber::geometry {

/// Row i of r v + t: ((r[0] x + r[1] y) + r[2] z) + t.
inline double rigid_move_row(const double r[3], double t, double x, double y, double z) {
  return ((r[0] * x + r[1] * y) + r[2] * z) + t;
}

/// Rotation r (row-major) and translation t, read once from their Eigen forms.
struct RigidMove {
  double r[3][3];
  double t[3];

  RigidMove(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r[i][j] = rotation(i, j);
      t[i] = translation[i];
    }
  }
  /// r v + t.
  [[nodiscard]] Eigen::Vector3d operator()(const Eigen::Vector3d& v) const {
    return {rigid_move_row(r[0], t[0], v[0], v[1], v[2]), rigid_move_row(r[1], t[1], v[0], v[1], v[2]),
            rigid_move_row(r[2], t[2], v[0], v[1], v[2])};
  }
};

}  // namespace caliber::geometry
