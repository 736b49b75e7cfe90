#pragma once
/// \file
/// Per-triangle data of a model beside its BVH, built in parallel chunks of `grain` triangles on the
/// executor the caller runs in, with the same result at any thread count.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "caliber/mesh.h"

namespace caliber::bvh {

/// Unit face normals (zero for a degenerate triangle).
std::vector<Eigen::Vector3d> face_normals(const Mesh& mesh, std::size_t grain);

/// Triangles that share a vertex position (vertices welded by exact equality, so files that repeat
/// vertices per face, like STL, still get their topology), as CSR: triangle t's neighbours are
/// adjacency[offsets[t] .. offsets[t + 1]), sorted and distinct.
void vertex_adjacency(const Mesh& mesh, std::size_t grain, std::vector<std::uint32_t>& offsets,
                      std::vector<std::uint32_t>& adjacency);

}  // namespace caliber::bvh
