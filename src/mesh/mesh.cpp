#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <utility>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "mesh/readers.h"
#include "util/printable.h"

namespace caliber {
namespace {

std::string tiny_coordinate(std::size_t v, double x) {
  char value[32];
  std::snprintf(value, sizeof value, "%.3g", x);
  return "vertex " + std::to_string(v) + " has a coordinate of magnitude " + value +
         ", below 2^-120 (about 7.5e-37), the smallest non-zero coordinate caliber's exact predicates take; "
         "scale the mesh up (coordinates 0 or between 7.5e-37 and 1e15 are accepted)";
}

template <class Real, class Index>
Mesh from_buffers(std::span<const Real> xyz, std::span<const Index> indices, std::string source) {
  if (xyz.size() % 3 != 0) {
    throw Error(ErrorCode::bad_argument, source,
                "the vertex buffer holds " + std::to_string(xyz.size()) + " values, not x, y, z triples (a multiple of 3)");
  }
  if (indices.size() % 3 != 0) {
    throw Error(ErrorCode::bad_argument, source,
                "the index buffer holds " + std::to_string(indices.size()) + " values, not three per triangle (a multiple of 3)");
  }
  const std::size_t n = xyz.size() / 3;
  if (n > std::size_t{UINT32_MAX}) {
    throw Error(ErrorCode::bad_value, source, std::to_string(n) + " vertices: more than 32-bit vertex ids reach");
  }
  Mesh mesh;
  mesh.source = std::move(source);
  mesh.vertices.reserve(n);
  for (std::size_t v = 0; v < n; ++v) {
    mesh.vertices.emplace_back(static_cast<double>(xyz[3 * v]), static_cast<double>(xyz[3 * v + 1]),
                               static_cast<double>(xyz[3 * v + 2]));
  }
  mesh.triangles.reserve(indices.size() / 3);
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    std::array<std::uint32_t, 3> tri{};
    for (std::size_t k = 0; k < 3; ++k) {
      const Index index = indices[3 * t + k];
      // Compared as signed 64-bit values: a negative index, or one past the vertices, is refused.
      const auto wide = static_cast<long long>(index);
      if (wide < 0 || static_cast<unsigned long long>(wide) >= n) {
        throw Error(ErrorCode::bad_index, mesh.source,
                    "face " + std::to_string(t) + " refers to vertex " + std::to_string(wide) + " but there are only " +
                        std::to_string(n));
      }
      tri[k] = static_cast<std::uint32_t>(wide);
    }
    mesh.triangles.push_back(tri);
  }
  validate_mesh(mesh);
  return mesh;
}

}  // namespace

Mesh mesh_from_buffers(std::span<const double> xyz, std::span<const std::int64_t> indices, std::string source) {
  return from_buffers(xyz, indices, std::move(source));
}
Mesh mesh_from_buffers(std::span<const float> xyz, std::span<const std::int32_t> indices, std::string source) {
  return from_buffers(xyz, indices, std::move(source));
}
Mesh mesh_from_buffers(std::span<const float> xyz, std::span<const std::int64_t> indices, std::string source) {
  return from_buffers(xyz, indices, std::move(source));
}
Mesh mesh_from_buffers(std::span<const double> xyz, std::span<const std::int32_t> indices, std::string source) {
  return from_buffers(xyz, indices, std::move(source));
}
Mesh mesh_from_buffers(std::span<const float> xyz, std::span<const std::uint32_t> indices, std::string source) {
  return from_buffers(xyz, indices, std::move(source));
}
Mesh mesh_from_buffers(std::span<const double> xyz, std::span<const std::uint32_t> indices, std::string source) {
  return from_buffers(xyz, indices, std::move(source));
}

void validate_mesh(const Mesh& mesh) {
  const std::string& src = mesh.source.empty() ? std::string("mesh") : mesh.source;
  if (mesh.triangles.empty()) throw Error(ErrorCode::empty_mesh, src, "mesh has no triangles");
  if (mesh.triangles.size() >= 0x7fffffffu) throw Error(ErrorCode::bad_value, src, "too many triangles");
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!mesh.vertices[v].allFinite()) {
      throw Error(ErrorCode::bad_value, src, "vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
    if (mesh.vertices[v].cwiseAbs().maxCoeff() > kMaxCoordinate) {
      throw Error(ErrorCode::bad_value, src,
                  "vertex " + std::to_string(v) + " has a coordinate beyond +-1e15 (caliber's limit on coordinates)");
    }
    for (int c = 0; c < 3; ++c) {
      const double x = std::abs(mesh.vertices[v][c]);
      if (x != 0.0 && x < kMinCoordinate) throw Error(ErrorCode::bad_value, src, tiny_coordinate(v, mesh.vertices[v][c]));
    }
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const std::uint32_t index : mesh.triangles[t]) {
      if (index >= mesh.vertices.size()) {
        throw Error(ErrorCode::bad_index, src,
                    "triangle " + std::to_string(t) + " refers to vertex " + std::to_string(index) + " but there are only " +
                        std::to_string(mesh.vertices.size()));
      }
    }
  }
  if (!mesh.groups.empty()) {
    if (mesh.groups.size() != mesh.triangles.size()) {
      throw Error(ErrorCode::bad_value, src, "groups must hold one entry per triangle");
    }
    for (std::size_t t = 0; t < mesh.groups.size(); ++t) {
      if (mesh.groups[t] >= kMaxGroups) {
        throw Error(ErrorCode::bad_value, src,
                    "triangle " + std::to_string(t) + " is in group " + std::to_string(mesh.groups[t]) + "; groups are 0.." +
                        std::to_string(kMaxGroups - 1));
      }
    }
  }
}

void scale_mesh(Mesh& mesh, double factor) {
  if (!std::isfinite(factor) || factor <= 0.0) {
    throw Error(ErrorCode::bad_value, mesh.source, "scale must be a finite number > 0");
  }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d scaled = mesh.vertices[v] * factor;
    if (!scaled.allFinite() || scaled.cwiseAbs().maxCoeff() > kMaxCoordinate) {
      char f[32];
      std::snprintf(f, sizeof f, "%g", factor);
      throw Error(ErrorCode::bad_value, mesh.source,
                  std::string("scaling by ") + f + " puts vertex " + std::to_string(v) +
                      " beyond +-1e15 (caliber's limit on coordinates)");
    }
    for (int c = 0; c < 3; ++c) {
      const double x = std::abs(scaled[c]);
      if (x != 0.0 && x < kMinCoordinate) {
        char f[32];
        std::snprintf(f, sizeof f, "%g", factor);
        throw Error(ErrorCode::bad_value, mesh.source, std::string("scaled by ") + f + ", " + tiny_coordinate(v, scaled[c]));
      }
    }
  }
  for (auto& v : mesh.vertices) v *= factor;
}

namespace mesh_io {

std::string quote_token(std::string_view token) {
  constexpr std::size_t kTokenBytes = 40;
  std::string out = "'";
  append_ascii_escaped(out, token.substr(0, kTokenBytes));
  if (token.size() > kTokenBytes) out += "...";
  return out + "'";
}

}  // namespace mesh_io
}  // namespace caliber
