// What a model keeps per triangle beside its BVH: face normals and vertex adjacency.

#include "bvh/adjacency.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "parallel/executor.h"

namespace caliber::bvh {

using Vec3 = Eigen::Vector3d;

std::vector<Vec3> face_normals(const Mesh& mesh, std::size_t grain) {
  std::vector<Vec3> normals(mesh.triangles.size());
  parallel::parallel_for(0, mesh.triangles.size(), grain, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t t = lo; t != hi; ++t) {
      const auto& tri = mesh.triangles[t];
      const Vec3 n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]).cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
      const double len = n.norm();
      normals[t] = (len > 0.0 && std::isfinite(len)) ? Vec3(n / len) : Vec3::Zero();
    }
  });
  return normals;
}

void vertex_adjacency(const Mesh& mesh, ModelData& model) {
  std::vector<std::uint32_t>& corner_vertex = model.corner_vertex;
  std::vector<std::uint64_t>& offsets = model.vertex_offsets;
  std::vector<std::uint32_t>& triangles = model.vertex_triangles;
  const std::size_t nv = mesh.vertices.size();
  std::vector<std::uint32_t> order(nv);
  std::iota(order.begin(), order.end(), 0u);
  const auto less = [&](std::uint32_t a, std::uint32_t b) {
    const Vec3& p = mesh.vertices[a];
    const Vec3& q = mesh.vertices[b];
    if (p.x() != q.x()) return p.x() < q.x();
    if (p.y() != q.y()) return p.y() < q.y();
    if (p.z() != q.z()) return p.z() < q.z();
    return a < b;
  };
  parallel::parallel_sort(order.begin(), order.end(), less);  // distinct keys (ties by index)
  // Each vertex's representative: the first vertex (least index) at its position. Welded vertices
  // are numbered in the order of their representatives, so that a mesh without repeated positions
  // keeps its own numbering and needs no corner_vertex.
  std::vector<std::uint32_t> weld(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    const bool repeats = i > 0 && mesh.vertices[order[i]] == mesh.vertices[order[i - 1]];
    weld[order[i]] = repeats ? weld[order[i - 1]] : order[i];
  }
  std::uint32_t next = 0;
  for (std::size_t v = 0; v < nv; ++v) weld[v] = weld[v] == v ? next++ : weld[weld[v]];
  const std::size_t nw = next;
  const std::size_t nt = mesh.triangles.size();
  corner_vertex.resize(3 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    for (std::size_t k = 0; k < 3; ++k) corner_vertex[3 * t + k] = weld[mesh.triangles[t][k]];
  }
  // Triangles around each welded vertex (CSR, 64-bit offsets), filled in triangle order: ascending.
  // A triangle with a repeated corner position is listed once per corner there.
  offsets.assign(nw + 1, 0);
  for (const std::uint32_t w : corner_vertex) ++offsets[w + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  triangles.resize(corner_vertex.size());
  std::vector<std::uint64_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t c = 0; c < corner_vertex.size(); ++c) triangles[fill[corner_vertex[c]]++] = static_cast<std::uint32_t>(c / 3);
  model.largest_degree = 0;
  for (std::size_t w = 0; w < nw; ++w) model.largest_degree = std::max(model.largest_degree, offsets[w + 1] - offsets[w]);
  if (nw == nv) std::vector<std::uint32_t>().swap(corner_vertex);  // every corner is its own vertex
}

}  // namespace caliber::bvh
