#pragma once
/// \file
/// Per-triangle data of a model beside its BVH, built in parallel chunks of `grain` triangles on the
/// executor the caller runs in, with the same result at any thread count.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "bvh/model_data.h"
#include "caliber/mesh.h"

namespace caliber::bvh {

/// Unit face normals (zero for a degenerate triangle).
std::vector<Eigen::Vector3d> face_normals(const Mesh& mesh, std::size_t grain);

/// The vertex adjacency of a model (its corner_vertex, vertex_offsets, vertex_triangles and
/// largest_degree, written there): vertices welded
/// by exact position (a parallel sort) and numbered in the order of their first vertex, then the
/// triangles around each welded vertex. corner_vertex is left empty where no two vertices share a
/// position (each corner's welded vertex is then its own vertex index). Time
/// O(V log V + corners) and memory linear in the corners, whatever a vertex's degree (a polygon
/// of 100,000 corners fanned from one vertex costs no more than 100,000 separate triangles).
void vertex_adjacency(const Mesh& mesh, ModelData& model);

}  // namespace caliber::bvh
