#pragma once
/// \file
/// Batch queries: one pair of models at many poses in one call (Engine::query_many), the answers
/// in arrays, and poses read from raw arrays (N 4 x 4 matrices, or N translations + quaternions).

#include "caliber/export.h"
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "caliber/pose.h"
#include "caliber/query.h"

namespace caliber {

/// The answers of a batch: entry i holds what caliber::query answers for the i-th poses, bit for
/// bit (the same contacts, objects 0 and 1, sorted by triangles), whatever the method and threads.
struct BatchResult {
  QueryKind kind = QueryKind::interference;  ///< the kind that produced it
  /// size() + 1 offsets into `contacts`: entry i's contacts are [offsets[i], offsets[i + 1]).
  std::vector<std::size_t> offsets{0};
  /// Every entry's contacts, entry after entry. A distance entry has one (its closest pair) or
  /// none (farther than the tolerance).
  std::vector<Contact> contacts;
  /// Per entry: 1 when it found QueryRequest::max_pairs pairs and stopped (its contacts may be a part).
  std::vector<std::uint8_t> limit_reached;
  /// Node and leaf tests over the whole batch.
  QueryStats stats;

  /// The number of entries (poses).
  [[nodiscard]] std::size_t size() const { return offsets.size() - 1; }
  /// Entry i's contacts.
  [[nodiscard]] std::span<const Contact> contacts_of(std::size_t i) const {
    return std::span<const Contact>(contacts).subspan(offsets[i], offsets[i + 1] - offsets[i]);
  }
  /// Whether entry i reported a pair: for interference, the meshes touch; for proximity and
  /// distance, they come within the tolerance; for contact, a pair of facing triangles does
  /// (meshes that interpenetrate may have none).
  [[nodiscard]] bool hit(std::size_t i) const { return offsets[i + 1] != offsets[i]; }
};

/// How seven values write a pose: the translation, then the quaternion as (w, x, y, z) (caliber's
/// and Eigen's order) or as (x, y, z, w) (scipy's and ROS's).
enum class QuaternionOrder : std::uint8_t { wxyz, xyzw };

/// N poses from N 4 x 4 rigid transforms, row-major, one after the other (16 N values), each
/// checked and made orthonormal as Pose::from_matrix does. Throws caliber::Error naming
/// `source`[i] for the first that is not a rigid transform within `tolerance`, or when the value
/// count is not a multiple of 16.
[[nodiscard]] CALIBER_EXPORT std::vector<Pose> poses_from_matrices(std::span<const double> values, double tolerance = 1e-9,
                                                                   std::string_view source = "poses");

/// N poses from N rows of seven values (translation, then quaternion in `order`), normalized as
/// Pose::from_values does. Throws caliber::Error naming `source`[i] for the first row with a
/// non-finite value or a zero quaternion, or when the value count is not a multiple of 7.
[[nodiscard]] CALIBER_EXPORT std::vector<Pose> poses_from_vectors(std::span<const double> values,
                                                                  QuaternionOrder order = QuaternionOrder::wxyz,
                                                                  std::string_view source = "poses");

}  // namespace caliber
