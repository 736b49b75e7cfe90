#pragma once
/// \file
/// The narrow-phase query between two posed models: interference, proximity, contact and distance.

#include "caliber/export.h"
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "caliber/model.h"
#include "caliber/pose.h"

namespace caliber {

/// What a query reports.
enum class QueryKind : std::uint8_t {
  interference,  ///< every intersecting triangle pair (exact predicates)
  proximity,     ///< every triangle pair at distance <= tolerance, with closest points
  contact,       ///< quasi-LMD: proximity pairs whose normals face each other, reduced to local minima
  distance,      ///< the minimum distance: the closest triangle pair (0 when the meshes intersect), if within the tolerance
};

/// "interference", "proximity", "contact" or "distance".
[[nodiscard]] CALIBER_EXPORT std::string_view to_string(QueryKind kind);
/// Parses a kind name; throws caliber::Error on an unknown name.
[[nodiscard]] CALIBER_EXPORT QueryKind parse_query_kind(std::string_view name);

/// Which primitive groups may touch: group g may touch group h iff bit h of compatible[g] is set.
/// The matrix should be symmetric; the default lets every group touch every group.
struct GroupCompatibility {
  /// Row g: the groups that g may touch.
  std::array<std::uint64_t, 64> compatible;
  /// All groups compatible with all.
  GroupCompatibility() { compatible.fill(~std::uint64_t{0}); }
  /// Whether groups a and b may touch.
  [[nodiscard]] bool allows(unsigned a, unsigned b) const { return (compatible[a] >> b) & 1u; }
};

/// Every option of a query, with defaults.
struct QueryRequest {
  /// What to report.
  QueryKind kind = QueryKind::interference;
  /// Distance d (world units) for proximity and contact; must be finite and >= 0 (validated for
  /// every kind, interference too, which does not use it). For distance, the largest distance of
  /// interest ("not closer than d" is answered without looking further): may be kUnbounded there,
  /// and only there.
  double tolerance = 0.0;
  /// Angle theta in degrees, [0, 180], for contact: normals must face each other within it.
  double angle_deg = 30.0;
  /// Group compatibility; null means every group may touch every group. Not owned.
  const GroupCompatibility* groups = nullptr;
  /// The most triangle pairs to report per object pair; 0: no limit. A query stops as soon as it
  /// has found max_pairs pairs and sets QueryResult::limit_reached: it returns max_pairs of the
  /// pairs it found (the lowest ids among them; which pairs it found first depends on the
  /// traversal and the method), and memory stays bounded. An unflagged result is the whole
  /// answer; a flagged one may be too (ask for one more pair than you need to know). 1 asks "do
  /// they touch at all?" (any pair, or none), stopping at the first pair found. For contact
  /// queries the limit applies before the local-minimum reduction, which sees only the pairs found:
  /// it may report fewer, and pairs the whole answer's reduction would drop (a closer neighbour of
  /// theirs was not found). Ignored by distance queries.
  std::size_t max_pairs = 0;
  /// Distance queries on meshes that intersect (distance 0, many pairs at 0). false (default): the
  /// query reports the first hit (the pair an interference query with max_pairs = 1 stops at), the
  /// pair every method and thread count reports, at about the first hit's cost; two models with at most 16
  /// triangle pairs between them (two tetrahedra) have every pair tested, and report the lowest
  /// ids. true: every pair at distance 0 is examined and the lowest triangle ids are reported, as
  /// for ties at any other distance (query_brute_force's answer; on two intersecting meshes of
  /// 10^4-10^5 triangles, much slower).
  /// Ignored by the other kinds.
  bool lowest_ids = false;
  /// Distance queries without lowest_ids: true (default): the first hit is asked for before the
  /// distance traversal, and where the meshes intersect it is the answer (see lowest_ids). false:
  /// the distance traversal runs alone and stops at the first intersecting pairs it meets itself
  /// (their lowest ids: another pair than the first hit, the same for every method and thread
  /// count). For poses known to be apart, where the first hit finds nothing and costs an
  /// interference query: caliber::sweep's conservative advancement asks with false (its poses are
  /// apart but close, where that interference query costs a fifth of a distance query). Ignored by
  /// the other kinds.
  bool first_hit = true;
};

/// A distance query's tolerance when any distance will do.
inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

/// Throws caliber::Error (bad_value) on a negative or non-finite tolerance (but kUnbounded for a
/// distance query) or an angle outside [0, 180].
CALIBER_EXPORT void validate_request(const QueryRequest& request);

/// The distance within which a request reports triangle pairs: 0 for interference (the triangles
/// must meet), the tolerance for proximity, contact and distance.
[[nodiscard]] inline double reach(const QueryRequest& request) {
  return request.kind == QueryKind::interference ? 0.0 : request.tolerance;
}

/// One reported triangle pair, in world coordinates: the one result shape of caliber::query and
/// Engine::step. Interference reports the triangle ids only (points and normal zero, distance 0).
struct Contact {
  std::uint32_t object_a = 0;  ///< object id of A: its index in the frame (caliber::query: 0)
  std::uint32_t object_b = 0;  ///< object id of B, > object_a (caliber::query: 1)
  std::uint32_t tri_a = 0;     ///< triangle id in model A
  std::uint32_t tri_b = 0;     ///< triangle id in model B
  Eigen::Vector3d point_a;     ///< closest point on triangle A
  Eigen::Vector3d point_b;     ///< closest point on triangle B
  Eigen::Vector3d normal;      ///< unit normal from A to B (zero only if undefined: both degenerate and touching)
  double distance = 0.0;       ///< triangle distance; exactly 0 when the triangles intersect
  /// Intersecting pairs (distance 0) with a normal: a penetration estimate, local to the pair: how
  /// far B's deepest vertex lies behind the plane through A's closest point, along the normal (the
  /// translation of B along the normal that takes that triangle's vertices out of A's half-space).
  /// Not the meshes' global penetration depth. 0 otherwise.
  double depth = 0.0;
};

/// Work counters: the parallel engine weighs pairs by them.
struct QueryStats {
  std::uint64_t node_tests = 0;  ///< node-node tests (BVH node pairs examined)
  std::uint64_t leaf_tests = 0;  ///< triangle-pair tests
};

/// The result of a query: its contacts, one per reported triangle pair, sorted by (tri_a, tri_b).
/// A distance query reports one, the closest pair (ties: the lowest triangle ids; at distance 0, as
/// QueryRequest::lowest_ids and first_hit say), or none when the meshes are farther apart than the
/// tolerance.
struct QueryResult {
  QueryKind kind = QueryKind::interference;  ///< the kind that produced it
  std::vector<Contact> contacts;             ///< sorted by (tri_a, tri_b)
  QueryStats stats;                          ///< work done
  /// QueryRequest::max_pairs pairs were found: the query stopped there, and `contacts` (max_pairs
  /// pairs) may be a part of the answer; a contact query's are those its reduction keeps of the
  /// pairs found, which the whole answer may not hold (QueryRequest::max_pairs).
  bool limit_reached = false;
};

/// Runs the query between model A at pose_a and model B at pose_b: one depth-first traversal of
/// the two BVHs. Exact: the same pairs as query_brute_force, but where the request asks for less: a
/// limit (max_pairs) returns some of them, and a distance query on meshes that intersect reports
/// the pair QueryRequest::lowest_ids and first_hit choose. Thread-safe on shared models.
[[nodiscard]] CALIBER_EXPORT QueryResult query(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b,
                                               const QueryRequest& request);

/// The O(n*m) oracle: runs the leaf test on every triangle pair. For tests.
[[nodiscard]] CALIBER_EXPORT QueryResult query_brute_force(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b,
                                                           const QueryRequest& request);

}  // namespace caliber
