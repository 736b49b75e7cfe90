#pragma once
/// \file
/// The layout of a built model, private to caliber: the BVH's nodes (what the node test reads),
/// the normals, the adjacency and the leaf order. The public caliber::Model is this, seen through
/// read-only accessors (data() gives this view to caliber's own code).

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "caliber/mesh.h"
#include "caliber/model.h"
#include "util/half_float.h"

namespace caliber {

/// One node of the BVH, as the node tests and the visits read it: 64 bytes aligned to 64, one cache
/// line. Two bounding volumes per node: the paper's sphere, tested first by the binary CD tree's
/// node test, and the node's axis-aligned box in the mesh's own frame, which sharpens what the
/// sphere lets through (thin and elongated parts, where spheres are loose). All boxes of one mesh
/// share that frame, so the rotation between two meshes' boxes is one matrix per query and the box
/// test is a separating-axis test on six face axes. Then what a visit of the wide CD tree reads
/// (narrow/visit.h): where the node's slab lies (`slot`: its place in the wide node that holds it,
/// which stores its slab (bvh::slot_slab), and which the visit that reached it read last)
/// and its wide node (`link`); for a leaf, where its triangle lies in its box (`shape`).
///
/// Values are stored as floats, rounded outward at build time (the radius and half-extents cover
/// the rounding of the centers), so every vertex below lies inside both volumes exactly as stored.
/// The children of an internal node are adjacent: `index` and `index + 1`.
struct alignas(64) BvhNode {
  /// `link` of a leaf, or of an internal node that is no wide node's root (collapsed away: it lies
  /// between a wide node and that node's slots).
  static constexpr std::uint32_t kNoWide = 0xFFFFFFFFu;
  /// `slot` of a node that is no slot (the root, the nodes collapsed away), or whose wide node's
  /// index is kSlotWideNodes or more: its slab is read from its BvhNodeFilter.
  static constexpr std::uint32_t kNoSlot = 0xFFFFFFFFu;
  /// The wide nodes whose slots `slot` can name (the last slot of the next would be kNoSlot).
  static constexpr std::uint32_t kSlotWideNodes = (std::uint32_t{1} << 29) - 1;
  /// Bounding-sphere center (object space).
  float center[3];
  /// Bounding-sphere radius.
  float radius;
  /// Box center (object space).
  float box_center[3];
  /// Box half-extents along the object axes.
  float box_half[3];
  /// Internal node: index of the first child (the second is index + 1). Leaf: the triangle id.
  std::uint32_t index;
  /// Number of triangles below (the paper's P); 1 for a leaf.
  std::uint32_t count;
  /// The wide node that holds it as a slot, its index in ModelData::wide times WideNode::kSlots
  /// plus the slot; or kNoSlot (bvh::build_wide_tree sets it).
  std::uint32_t slot = kNoSlot;
  /// The index of its wide node in ModelData::wide, or kNoWide (bvh::build_wide_tree sets it).
  std::uint32_t link = kNoWide;
  /// A leaf's triangle within its box (bvh/leaf_shape.h; 0 for an internal node): per axis
  /// i, bits 16i..16i+15 place the corner between the lowest and highest on the box's range in
  /// steps of 1/65535 (rounded to the nearest), bits 48+4i..49+4i name the lowest corner and bits
  /// 50+4i..51+4i the highest (the box's bounds). In the line's spare bytes: read with the box.
  std::uint64_t shape = 0;

  /// True for a leaf (one triangle).
  [[nodiscard]] bool is_leaf() const { return count == 1; }
  /// A leaf's triangle.
  [[nodiscard]] std::uint32_t triangle() const { return index; }
  /// Whether it is a wide node's root (`link` names it).
  [[nodiscard]] bool has_wide() const { return link != kNoWide; }
  /// What the wide CD tree compares to choose the side that descends: the sum of its box's
  /// half-extents in float (a model scaled by a power of two scales it exactly, where its boxes'
  /// half-extents are normal floats).
  [[nodiscard]] float size() const { return (box_half[0] + box_half[1]) + box_half[2]; }
};
static_assert(sizeof(BvhNode) == 64, "BvhNode is meant to stay one cache line");

/// The rest of a node: its normal cone and slab (read by the node test once the sphere and box
/// tests have passed; the cone only by contact queries): 32 bytes aligned to 32, two to a cache
/// line and never across two. Kept apart from BvhNode, whose line the first two tests read.
struct alignas(32) BvhNodeFilter {
  /// Normal-cone axis (unit up to float rounding; the half-angle is measured from this axis).
  float cone_axis[3];
  /// Normal-cone half-angle in radians, rounded up; negative when every triangle below is
  /// degenerate (no normal, so no contact can come from this node).
  float cone_angle;
  /// cos(cone_angle) and sin(cone_angle), so the cone test needs no trigonometric call.
  float cone_cos, cone_sin;
  /// Slab along cone_axis (as stored, not renormalized): every vertex v below has
  /// slab_lo <= cone_axis . v <= slab_hi, the bounds rounded outward. Thin where the triangles
  /// below are nearly coplanar, whatever their tilt against the box's axes; both 0 when the axis
  /// is 0 (no normal below), which prunes nothing.
  float slab_lo, slab_hi;
};
static_assert(sizeof(BvhNodeFilter) == 32);

/// What only the distance query reads of a node: the ranges along the two lateral axes of its cone
/// axis (lateral_axes), every vertex v below having lo[k] <= axis_k . v <= hi[k] as lateral_range
/// decodes them, rounded outward. With the slab, a box around the triangles below in the frame of
/// the cone axis, tight where they are nearly coplanar. The lateral axes are turned about the cone
/// axis to follow the patch (a leaf: its triangle's principal direction in the slab's plane; a
/// parent: the line between its children, across which the build partitioned it), so that an
/// elongated patch gets a narrow box whatever its direction. All 0 when the cone axis is 0.
/// 12 bytes: the ranges are stored in steps of lateral_step about the node's box center.
struct BvhNodeLateral {
  /// The ranges, in steps (lateral_range).
  std::int16_t lo[2], hi[2];
  /// (cos, sin) of the turn, up to scale, as integers of at most 32767 in magnitude (normalized
  /// in double where used).
  std::int16_t turn[2];
};
static_assert(sizeof(BvhNodeLateral) == 12);

/// The step of node n's lateral ranges: 1/32000 of what a unit axis can see of its box (at most
/// sqrt(3) times its largest half-extent), with a hair of its distance from the origin for the
/// rounding of the ranges' ends.
inline double lateral_step(const BvhNode& n) {
  double h = 0.0, c = 0.0;
  for (int k = 0; k < 3; ++k) {
    h = std::max(h, static_cast<double>(n.box_half[k]));
    c = std::max(c, std::abs(static_cast<double>(n.box_center[k])));
  }
  return (1.7320508075688772 * h + 1e-12 * (c + h)) / 32000.0;
}

/// Where node n's range along the axis a is measured from: a . (its box center).
inline double lateral_middle(const BvhNode& n, const double a[3]) {
  return (a[0] * n.box_center[0] + a[1] * n.box_center[1]) + a[2] * n.box_center[2];
}

/// Node n's lateral ranges along its lateral axes u and v (lateral_axes), decoded from l:
/// lateral_middle + q lateral_step, in double.
inline void lateral_range(const BvhNode& n, const BvhNodeLateral& l, const double u[3], const double v[3], double lo[2],
                          double hi[2]) {
  const double step = lateral_step(n);
  const double mid[2] = {lateral_middle(n, u), lateral_middle(n, v)};
  for (int k = 0; k < 2; ++k) {
    lo[k] = mid[k] + l.lo[k] * step;
    hi[k] = mid[k] + l.hi[k] * step;
  }
}

/// The two axes that complete a unit axis (nx, ny, nz) to an orthonormal frame (Duff et al. 2017's
/// branchless basis), up to double rounding.
inline void lateral_axes_of_unit(double nx, double ny, double nz, double u[3], double v[3]) {
  const double sign = std::copysign(1.0, nz);
  const double a = -1.0 / (sign + nz);
  const double b = nx * ny * a;
  u[0] = 1.0 + sign * nx * nx * a;
  u[1] = sign * b;
  u[2] = -sign * nx;
  v[0] = b;
  v[1] = sign + ny * ny * a;
  v[2] = -ny;
}

/// Turns the orthonormal pair (u, v) about their normal by the angle whose (cos, sin) is `turn` up
/// to scale (normalized here in double, so the pair stays orthonormal up to double rounding; a zero
/// turn leaves it as it is).
inline void turn_lateral_axes(const std::int16_t turn[2], double u[3], double v[3]) {
  double c = turn[0], s = turn[1];
  const double r = std::sqrt(c * c + s * s);
  if (!(r > 0.0)) return;
  c /= r;
  s /= r;
  for (int k = 0; k < 3; ++k) {
    const double uk = u[k], vk = v[k];
    u[k] = c * uk + s * vk;
    v[k] = c * vk - s * uk;
  }
}

/// The lateral axes of a stored float cone axis before their turn: those of the normalized axis
/// (lateral_axes_of_unit). Both 0 when the axis is 0.
inline void unturned_lateral_axes(const float axis[3], double u[3], double v[3]) {
  const double x = axis[0], y = axis[1], z = axis[2];
  const double len = std::sqrt(x * x + y * y + z * z);
  if (!(len > 0.0)) {
    for (int k = 0; k < 3; ++k) u[k] = v[k] = 0.0;
    return;
  }
  lateral_axes_of_unit(x / len, y / len, z / len, u, v);
}

/// The two axes that complete a node's cone axis to a frame: those of the normalized stored float
/// axis, turned by the stored turn, by the same formulas at build and at query time. Both 0 when
/// the axis is 0.
inline void lateral_axes(const float axis[3], const std::int16_t turn[2], double u[3], double v[3]) {
  unturned_lateral_axes(axis, u, v);
  turn_lateral_axes(turn, u, v);
}

/// A box around the triangles below a node along axes of its own, in double precision: what the
/// distance query's bound reads of a node (Model::oriented_boxes). Where the node has a slab, the
/// box of its slab and lateral ranges: axis[0] the normalized cone axis, axis[1] and axis[2] its
/// lateral axes (lateral_axes); else its BvhNode box along the model's axes. Computed from the
/// stored BvhNode, BvhNodeFilter and BvhNodeLateral by one function, at build time or by the query.
struct BvhNodeOrientedBox {
  /// Unit axes (orthonormal up to double rounding), in object space.
  double axis[3][3];
  /// Center, in object space.
  double center[3];
  /// Half-extents along axis[0], axis[1], axis[2].
  double half[3];
};

/// The oriented box of a node from its stored parts: the box of its slab (along the normalized
/// cone axis, as lateral_axes normalizes it) and lateral ranges where it has a slab, else its
/// BvhNode box. Where it has a slab, each half-extent grows by a relative 1e-12 for the rounding
/// of the division by the axis's length.
inline void node_oriented_box(const BvhNode& n, const BvhNodeFilter& f, const BvhNodeLateral& l, BvhNodeOrientedBox& out) {
  const double x = f.cone_axis[0], y = f.cone_axis[1], z = f.cone_axis[2];
  const double len = std::sqrt(x * x + y * y + z * z);
  if (len > 0.0) {
    const double axis[3] = {x / len, y / len, z / len};  // as lateral_axes computes them
    double u[3], v[3];
    lateral_axes_of_unit(axis[0], axis[1], axis[2], u, v);
    turn_lateral_axes(l.turn, u, v);
    double lateral_lo[2], lateral_hi[2];
    lateral_range(n, l, u, v, lateral_lo, lateral_hi);
    const double lo[3] = {f.slab_lo / len, lateral_lo[0], lateral_lo[1]};
    const double hi[3] = {f.slab_hi / len, lateral_hi[0], lateral_hi[1]};
    double mid[3], half[3];
    for (int k = 0; k < 3; ++k) {
      mid[k] = 0.5 * (lo[k] + hi[k]);
      half[k] = 0.5 * (hi[k] - lo[k]) * (1.0 + 1e-12);  // the division by len rounds
    }
    for (int i = 0; i < 3; ++i) {
      out.axis[0][i] = axis[i];
      out.axis[1][i] = u[i];
      out.axis[2][i] = v[i];
      out.center[i] = mid[0] * axis[i] + mid[1] * u[i] + mid[2] * v[i];
    }
    for (int k = 0; k < 3; ++k) out.half[k] = half[k];
    return;
  }
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < 3; ++i) out.axis[k][i] = k == i ? 1.0 : 0.0;
    out.center[k] = n.box_center[k];
    out.half[k] = n.box_half[k];
  }
}

/// A node of the wide tree, read by the pair-collecting queries' node test (narrow/wide_test.h):
/// a node of the BVH whose subtree is collapsed to at most kWideSlots slots, each slot a node
/// below it (build_wide_tree: the slot of largest box surface that is not a leaf is replaced by its
/// two children until the slots are full or all leaves; then each slot that is not a leaf gets a
/// wide node of its own). A slot keeps its BVH node's id, so that the CD tree's nodes stay pairs
/// of BVH nodes. Per slot, in lanes: its box as 16-bit bounds on the node's grid (low, high), and
/// a slab: an axis in half floats (slab_axis: its BvhNodeFilter's axis, each component cut toward
/// zero) with float bounds for that axis (bvh::slot_slab: the filter's, moved over the
/// node's box and rounded outward). The grid: a power of two `step` and an `origin` on it, both
/// floats, so that every bound origin + q step is a float, the same however computed; each bound
/// is the grid's nearest outside the float bound nearest outside its BvhNode box's double bound
/// (bvh::build_wide_tree). Slots past the last are empty: node kEmpty, low above high; count()
/// says how many are in use (every visit reads it), leaves() which are leaves (so a visit knows
/// its children that are pairs of leaves before it reads their BVH nodes): both in the step's
/// word. 256 bytes, aligned to a cache line: four lines.
struct alignas(64) WideNode {
  static constexpr int kSlots = 8;
  static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
  /// The most steps a bound lies from the origin.
  static constexpr int kSteps = 32767;
  /// The bits of `grid` that hold the step (a power of two's float bits: its mantissa's low bits
  /// are 0).
  static constexpr std::uint32_t kStepBits = 0xFFFF0000u;
  // (The float and id arrays at multiples of 32 bytes, the 16-bit ones of 16: the test's aligned
  // loads.)
  float slab_lo[kSlots], slab_hi[kSlots];     ///< slab bounds along slab_axis
  std::uint32_t node[kSlots];                 ///< the slot's BVH node, kEmpty past the last
  std::int16_t lo[3][kSlots], hi[3][kSlots];  ///< box bounds along the object axes, in steps
  std::uint16_t axis[3][kSlots];              ///< slab axis, as half floats (util/half_float.h)
  float origin[3];                            ///< the grid's origin (a multiple of step)
  std::uint32_t grid = 0;                     ///< step's float bits | leaves() << 8 | count()
  /// Slot k's low and high bounds along axis i (exact: origin + q step is a float).
  [[nodiscard]] float low(int i, int k) const { return static_cast<float>(lo[i][k]) * step() + origin[i]; }
  [[nodiscard]] float high(int i, int k) const { return static_cast<float>(hi[i][k]) * step() + origin[i]; }
  /// Component i of slot k's slab axis (exact).
  [[nodiscard]] float slab_axis(int i, int k) const { return util::half_value(axis[i][k]); }
  /// The grid's step, a power of two.
  [[nodiscard]] float step() const { return std::bit_cast<float>(grid & kStepBits); }
  /// Number of slots in use (they come first): 2 .. kSlots, 1 in bvh::single_slot's.
  [[nodiscard]] int count() const { return static_cast<int>(grid & 0xFFu); }
  /// Bit k set where slot k is a leaf (one triangle).
  [[nodiscard]] unsigned leaves() const { return grid >> 8 & 0xFFu; }
  void set_step(float s) { grid = (std::bit_cast<std::uint32_t>(s) & kStepBits) | (grid & ~kStepBits); }
  void set_count(int n) { grid = (grid & ~0xFFu) | (static_cast<std::uint32_t>(n) & 0xFFu); }
  void set_leaves(unsigned mask) { grid = (grid & ~0xFF00u) | (mask & 0xFFu) << 8; }
};
static_assert(sizeof(WideNode) == 256);
static_assert(offsetof(WideNode, lo) % 16 == 0 && offsetof(WideNode, hi) % 16 == 0 && offsetof(WideNode, axis) % 16 == 0 &&
              offsetof(WideNode, slab_lo) % 32 == 0 && offsetof(WideNode, slab_hi) % 32 == 0 &&
              offsetof(WideNode, node) % 32 == 0);

/// What a Model holds: the mesh with its BVH, normals and adjacency, laid out for the traversal.
/// Made by build_model; never modified afterwards.
struct ModelData : Model {
  /// The mesh, as loaded (triangle ids unchanged).
  Mesh mesh;
  /// BVH nodes, root first; siblings adjacent.
  std::vector<BvhNode> nodes;
  /// filters[i]: normal cone and slab of nodes[i].
  std::vector<BvhNodeFilter> filters;
  /// group_masks[i]: bit g set when some triangle below nodes[i] is in primitive group g. Empty
  /// when the mesh has no groups (every triangle in group 0): see group_mask.
  std::vector<std::uint64_t> group_masks;
  /// laterals[i]: the lateral ranges of nodes[i] (distance queries).
  std::vector<BvhNodeLateral> laterals;
  /// oriented_boxes[i]: the oriented box of nodes[i], as node_oriented_box computes it from the
  /// three above; empty unless built with BuildOptions::oriented_boxes.
  std::vector<BvhNodeOrientedBox> oriented_boxes;
  /// Position of each triangle in the leaf order. Every subtree is a run of it: the triangles below
  /// node i are those whose position lies in [first, first + nodes[i].count), where the root's
  /// first is 0 and a node's first child's is its own, its second child's its own plus the first
  /// child's count (first_leaf).
  std::vector<std::uint32_t> leaf_position;

  /// The group mask of node i (read only by queries with a group table).
  [[nodiscard]] std::uint64_t group_mask(std::uint32_t i) const { return group_masks.empty() ? 1 : group_masks[i]; }

  /// Whether `triangle` lies below `node`, whose run of leaves starts at `first`.
  [[nodiscard]] bool holds(std::uint32_t node, std::uint32_t first, std::uint32_t triangle) const {
    const std::uint32_t p = leaf_position[triangle];
    return p >= first && p < first + nodes[node].count;
  }
  /// The wide tree (WideNode), its root's first (BvhNode::link and BvhNode::slot name its nodes).
  std::vector<WideNode> wide;
  /// Where the run of leaves of `node` starts: the place of its first leaf (its first children's).
  [[nodiscard]] std::uint32_t first_leaf(std::uint32_t node) const {
    while (!nodes[node].is_leaf()) node = nodes[node].index;
    return leaf_position[nodes[node].index];
  }
  /// Unit face normal of each triangle in object space; zero for a degenerate triangle.
  std::vector<Eigen::Vector3d> normals;
  /// Vertex adjacency (BuildOptions::adjacency), linear in the corners whatever a vertex's degree:
  /// the welded vertex of each corner (corner t*3 + k of triangle t; vertices are welded by exact
  /// position, so files that repeat vertices per face still get their topology), or nothing where
  /// no two vertices share a position (the welded vertices are then the mesh's own: welded_corners)
  /// ...
  std::vector<std::uint32_t> corner_vertex;
  /// ... and the triangles around each welded vertex w, ascending:
  /// vertex_triangles[vertex_offsets[w] .. vertex_offsets[w + 1]).
  std::vector<std::uint64_t> vertex_offsets;
  /// See vertex_offsets.
  std::vector<std::uint32_t> vertex_triangles;
  std::uint64_t largest_degree = 0;  ///< The most corners at one welded vertex (0 without adjacency).
  [[nodiscard]] bool has_adjacency() const { return !vertex_offsets.empty(); }  ///< Whether the vertex adjacency was built.
  /// The welded vertices of triangle t's three corners.
  [[nodiscard]] const std::uint32_t* welded_corners(std::uint32_t t) const {
    return corner_vertex.empty() ? mesh.triangles[t].data() : &corner_vertex[std::size_t{t} * 3];
  }
  /// Calls f(u) for the triangles u that share a vertex position with triangle t (u != t; a triangle
  /// sharing two or three positions with t comes two or three times) until f returns true: whether it did.
  template <class F>
  bool any_neighbour(std::uint32_t t, F&& f) const {
    const std::uint32_t* corners = welded_corners(t);
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t w = corners[k];
      for (std::uint64_t i = vertex_offsets[w]; i < vertex_offsets[w + 1]; ++i) {
        if (vertex_triangles[i] != t && f(vertex_triangles[i])) return true;
      }
    }
    return false;
  }
  /// Whether u is among the triangles any_neighbour(t, ...) gives: distinct from t, sharing
  /// a vertex position with it.
  [[nodiscard]] bool are_neighbours(std::uint32_t t, std::uint32_t u) const {
    if (t == u) return false;
    const std::uint32_t* vt = welded_corners(t);
    const std::uint32_t* vu = welded_corners(u);
    bool shared = false;
    for (int k = 0; k < 3; ++k) shared |= (vt[k] == vu[0]) | (vt[k] == vu[1]) | (vt[k] == vu[2]);
    return shared;
  }
  /// Largest distance of a vertex from the object-space origin (used to bound rounding error).
  double extent = 0.0;
  /// The point the node volumes are relative to (object space): a node's stored center c stands
  /// for origin + c. The center of the vertices' box for a mesh far from its own origin (farther
  /// than the box is large), so that its nodes are as fine as at the origin; else zero.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  /// Largest distance of a vertex from `origin` (extent when origin is zero).
  double local_extent = 0.0;
  /// Height of the BVH (a root-only tree has height 1).
  int height = 0;
};

/// The layout behind a model (every Model is a ModelData: build_model makes them).
[[nodiscard]] inline const ModelData& data(const Model& model) { return static_cast<const ModelData&>(model); }

}  // namespace caliber
