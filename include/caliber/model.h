#pragma once
/// \file
/// A Model is a mesh together with everything built once for it: the sphere-tree BVH, the face
/// normals and the triangle adjacency. Built once in object space, immutable afterwards, and safe
/// to share between threads and between objects that use the same mesh.

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "caliber/mesh.h"

namespace caliber {

/// One node of the sphere-tree BVH: 64 bytes, one cache line. Nodes are stored depth-first:
/// the left child of an internal node `i` is `i + 1`, the right child is `right`.
struct BvhNode {
  /// Bounding-sphere center (object space).
  double center[3];
  /// Bounding-sphere radius: every vertex of every triangle below lies within it.
  double radius;
  /// Normal-cone axis (unit, rounded to float; the half-angle is measured from this rounded axis).
  float cone_axis[3];
  /// Normal-cone half-angle in radians, rounded up; negative when every triangle below is
  /// degenerate (no normal, so no contact can come from this node).
  float cone_angle;
  /// Internal node: index of the right child. Leaf: the triangle id.
  std::uint32_t index;
  /// Number of triangles below (the paper's P); 1 for a leaf.
  std::uint32_t count;
  /// Bit g set when some triangle below is in primitive group g.
  std::uint64_t groups;

  /// True for a leaf (one triangle).
  [[nodiscard]] bool is_leaf() const { return count == 1; }
};
static_assert(sizeof(BvhNode) == 64, "BvhNode is meant to fill one cache line");

/// A second bounding volume per node, beside the sphere: the node's axis-aligned box in the mesh's
/// own frame. All boxes of one mesh share that frame, so the rotation between two meshes' boxes is
/// one matrix per query and the box test costs a few multiply-adds (a separating-axis test on the
/// six face axes). The sphere test runs first; the box only sharpens what the sphere lets through
/// (thin and elongated parts, where spheres are loose).
struct BvhBox {
  /// Box center (object space).
  double center[3];
  /// Half-extents along the object axes: every vertex below lies within center +- half.
  double half[3];
};
static_assert(sizeof(BvhBox) == 48);

/// Options of the BVH build.
struct BuildOptions {
  /// Compute the vertex-adjacency of triangles (needed by contact queries). On by default.
  bool adjacency = true;
};

/// A mesh with its BVH, normals and adjacency. Create with build_model; never modified afterwards.
struct Model {
  /// The mesh, as loaded (triangle ids unchanged).
  Mesh mesh;
  /// BVH nodes, root first, depth-first order.
  std::vector<BvhNode> nodes;
  /// boxes[i] is the object-space box of nodes[i].
  std::vector<BvhBox> boxes;
  /// Unit face normal of each triangle in object space; zero for a degenerate triangle.
  std::vector<Eigen::Vector3d> normals;
  /// Triangles sharing a vertex position with triangle t are
  /// adjacency[adjacency_offsets[t] .. adjacency_offsets[t+1]) (sorted, t excluded).
  std::vector<std::uint32_t> adjacency_offsets;
  /// See adjacency_offsets.
  std::vector<std::uint32_t> adjacency;
  /// Largest distance of a vertex from the object-space origin (used to bound rounding error).
  double extent = 0.0;
  /// Height of the BVH (a root-only tree has height 1).
  int height = 0;
};

/// Validates the mesh and builds its model in O(n log n). Throws caliber::Error on a bad mesh.
[[nodiscard]] std::shared_ptr<const Model> build_model(Mesh mesh, const BuildOptions& options = {});

}  // namespace caliber
