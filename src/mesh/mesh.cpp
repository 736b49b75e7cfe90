#include <cmath>
#include <cstdio>
#include <string>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "mesh/readers.h"

namespace caliber {
namespace {

std::string tiny_coordinate(std::size_t v, double x) {
  char value[32];
  std::snprintf(value, sizeof value, "%.3g", x);
  return "vertex " + std::to_string(v) + " has a coordinate of magnitude " + value +
         ", below 2^-120 (about 7.5e-37), the smallest non-zero coordinate caliber's exact predicates take; "
         "scale the mesh up (coordinates 0 or between 7.5e-37 and 1e15 are accepted)";
}

}  // namespace

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
      throw Error(ErrorCode::bad_value, mesh.source,
                  "scaling by " + std::to_string(factor) + " puts vertex " + std::to_string(v) +
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
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      out += hex;
    }
  }
  if (token.size() > 40) out += "...";
  return out + "'";
}

}  // namespace mesh_io
}  // namespace caliber
