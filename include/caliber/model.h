#pragma once
/// \file
/// A Model is a mesh together with everything built once for it: the sphere-tree BVH, the face
/// normals and the triangle adjacency. Built once in object space, immutable afterwards, and safe
/// to share between threads and between objects that use the same mesh.

#include "caliber/export.h"
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "caliber/executor.h"

#include "caliber/mesh.h"

namespace caliber {

/// Options of the BVH build.
struct BuildOptions {
  /// Compute the vertex-adjacency of triangles (needed by contact queries). On by default.
  bool adjacency = true;
  /// Keep each node's oriented box (Model::oriented_boxes, 120 bytes a node): a distance query
  /// then reads it instead of computing it from the node (a square root and divisions) each time
  /// it meets the node. Same results either way. Off by default; the CLI and scenes turn it on
  /// for distance queries.
  bool oriented_boxes = false;
  /// Where the build runs, as EngineOptions::threads: 0, in the oneTBB arena build_model is called
  /// from (the host's); 1, on the calling thread alone, creating no thread; N > 1, an arena of its
  /// own of N threads, at most the process's limit. The model is the same whatever the count.
  int threads = 0;
  /// A host's own job system (caliber/executor.h): when given, the build runs on the threads it
  /// lends, at most `threads` of them (0: all it offers), and creates no thread of its own.
  HostExecutor* host = nullptr;
};

/// A mesh with its BVH, normals and adjacency: what caliber::query and the engine traverse. Made
/// by build_model; immutable (read-only accessors), so any number of threads and objects may
/// share one. Its BVH's layout is private to caliber.
class CALIBER_EXPORT Model {
 public:
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  /// The mesh, as given to build_model (triangle ids unchanged).
  [[nodiscard]] const Mesh& mesh() const;
  /// Unit face normal of each triangle in object space; zero for a degenerate triangle.
  [[nodiscard]] const std::vector<Eigen::Vector3d>& normals() const;
  /// Number of triangles.
  [[nodiscard]] std::size_t triangle_count() const;
  /// Number of BVH nodes (2 x triangles - 1).
  [[nodiscard]] std::size_t node_count() const;
  /// Height of the BVH (a one-triangle model has height 1).
  [[nodiscard]] int height() const;
  /// Largest distance from the object-space origin of a vertex that a triangle uses.
  [[nodiscard]] double extent() const;
  /// Whether the triangle adjacency was built (BuildOptions::adjacency: contact queries need it).
  [[nodiscard]] bool has_adjacency() const;
  /// Whether the distance query's oriented boxes were kept (BuildOptions::oriented_boxes).
  [[nodiscard]] bool has_oriented_boxes() const;
  /// Bytes the model holds: its mesh (vertices, triangles, groups), normals, BVH (what the
  /// traversals read, the leaf order, oriented boxes when kept; the wide tree the pair-collecting
  /// queries walk, about 70 bytes a triangle, built for every model) and adjacency.
  [[nodiscard]] std::size_t memory_bytes() const;

 protected:
  Model() = default;
  ~Model() = default;
};

/// One node of a model's BVH as a viewer draws it: its box (center and half-extents along the
/// model's axes, in the model's frame) and its children's node indices (none for a leaf). Node 0 is
/// the root; TaskRoot and the profile name nodes by the same indices.
struct NodeBox {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  std::uint32_t children[2] = {0, 0};
  int child_count = 0;  ///< 0 for a leaf, else 2
};

/// Node `node` of the model's BVH (node < node_count()). Throws caliber::Error on a node past the
/// last.
[[nodiscard]] CALIBER_EXPORT NodeBox node_box(const Model& model, std::uint32_t node);

/// Validates the mesh and builds its model in O(n log n). Throws caliber::Error on a bad mesh.
[[nodiscard]] CALIBER_EXPORT std::shared_ptr<const Model> build_model(Mesh mesh, const BuildOptions& options = {});

}  // namespace caliber
