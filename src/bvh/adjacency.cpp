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

void vertex_adjacency(const Mesh& mesh, std::size_t grain, std::vector<std::uint32_t>& offsets,
                      std::vector<std::uint32_t>& adjacency) {
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
  std::vector<std::uint32_t> weld(nv);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < nv; ++i) {
    if (i > 0 && mesh.vertices[order[i]] != mesh.vertices[order[i - 1]]) ++next;
    weld[order[i]] = next;
  }
  const std::uint32_t nw = nv == 0 ? 0 : next + 1;
  // Triangles around each welded vertex (CSR).
  std::vector<std::uint32_t> start(nw + 1, 0);
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) ++start[weld[v] + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint32_t> incident(start.back());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const std::uint32_t v : mesh.triangles[t]) incident[fill[weld[v]]++] = t;
  }
  // Each triangle's neighbours, sorted and distinct, found in parallel chunks of triangles, then
  // copied in parallel into their places: the same list a loop over the triangles would write.
  const std::size_t nt = mesh.triangles.size();
  const std::size_t chunks = (nt + grain - 1) / grain;
  std::vector<std::vector<std::uint32_t>> found(chunks);
  offsets.assign(nt + 1, 0);
  parallel::parallel_for(0, chunks, 1, [&](std::size_t c_lo, std::size_t c_hi) {
    std::vector<std::uint32_t> around;
    for (std::size_t c = c_lo; c != c_hi; ++c) {
      for (std::size_t t = c * grain; t < std::min(nt, (c + 1) * grain); ++t) {
        around.clear();
        for (const std::uint32_t v : mesh.triangles[t]) {
          const std::uint32_t w = weld[v];
          for (std::uint32_t k = start[w]; k < start[w + 1]; ++k) {
            if (incident[k] != t) around.push_back(incident[k]);
          }
        }
        std::sort(around.begin(), around.end());
        around.erase(std::unique(around.begin(), around.end()), around.end());
        found[c].insert(found[c].end(), around.begin(), around.end());
        offsets[t + 1] = static_cast<std::uint32_t>(around.size());
      }
    }
  });
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  adjacency.resize(offsets.back());
  parallel::parallel_for(0, chunks, 1, [&](std::size_t c_lo, std::size_t c_hi) {
    for (std::size_t c = c_lo; c != c_hi; ++c) {
      std::copy(found[c].begin(), found[c].end(), adjacency.begin() + offsets[c * grain]);
    }
  });
}

}  // namespace caliber::bvh
