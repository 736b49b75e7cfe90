#include "caliber/procedural.h"

#include <numbers>
#include <cmath>
#include <string>

#include "caliber/error.h"

namespace caliber {
namespace {

/// Triangles over a (rows+1) x (cols+1) vertex grid starting at `base`; the last column wraps
/// to the first when `wrap` is set.
void grid_triangles(Mesh& mesh, std::uint32_t base, int rows, int cols, bool wrap) {
  const int stride = wrap ? cols : cols + 1;
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const int jn = wrap ? (j + 1) % cols : j + 1;
      const auto v00 = base + static_cast<std::uint32_t>(i * stride + j);
      const auto v01 = base + static_cast<std::uint32_t>(i * stride + jn);
      const auto v10 = base + static_cast<std::uint32_t>((i + 1) * stride + j);
      const auto v11 = base + static_cast<std::uint32_t>((i + 1) * stride + jn);
      mesh.triangles.push_back({v00, v10, v11});
      mesh.triangles.push_back({v00, v11, v01});
    }
  }
}

void require(bool ok, const std::string& what) {
  if (!ok) throw Error(ErrorCode::bad_value, "procedural mesh", what);
}

/// A generated mesh's vertices stay within 2^27, far below the 32-bit ids' limit (its int loops
/// cannot overflow) and within memory a test or a scene can ask for.
bool vertex_count_within(double vertices) { return vertices <= 134217728.0; }

}  // namespace

Mesh make_sphere(double radius, int rings, int segments) {
  require(radius > 0.0 && rings >= 2 && segments >= 3, "sphere needs radius > 0, rings >= 2, segments >= 3");
  require(std::isfinite(radius) && vertex_count_within(static_cast<double>(rings + 1) * segments),
          "sphere needs a finite radius and at most 2^27 vertices");
  Mesh mesh;
  mesh.source = "sphere";
  for (int i = 0; i <= rings; ++i) {
    const double phi = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double theta = 2.0 * std::numbers::pi * j / segments;
      mesh.vertices.emplace_back(radius * std::sin(phi) * std::cos(theta), radius * std::sin(phi) * std::sin(theta),
                                 radius * std::cos(phi));
    }
  }
  // Pole rows hold repeated vertices: their triangles are degenerate, kept on purpose (the
  // library must handle zero-area triangles everywhere).
  grid_triangles(mesh, 0, rings, segments, true);
  return mesh;
}

Mesh make_torus(double major, double minor, int rings, int segments) {
  require(major > minor && minor > 0.0 && rings >= 3 && segments >= 3, "torus needs major > minor > 0, rings, segments >= 3");
  require(std::isfinite(major) && vertex_count_within(static_cast<double>(rings + 1) * segments),
          "torus needs finite radii and at most 2^27 vertices");
  Mesh mesh;
  mesh.source = "torus";
  for (int i = 0; i <= rings; ++i) {
    const double u = 2.0 * std::numbers::pi * (i % rings) / rings;
    for (int j = 0; j < segments; ++j) {
      const double v = 2.0 * std::numbers::pi * j / segments;
      const double r = major + minor * std::cos(v);
      mesh.vertices.emplace_back(r * std::cos(u), r * std::sin(u), minor * std::sin(v));
    }
  }
  grid_triangles(mesh, 0, rings, segments, true);
  return mesh;
}

Mesh make_box(double hx, double hy, double hz, int divisions) {
  require(hx > 0.0 && hy > 0.0 && hz > 0.0 && divisions >= 1, "box needs positive half-extents and divisions >= 1");
  require(std::isfinite(hx) && std::isfinite(hy) && std::isfinite(hz) &&
              vertex_count_within(6.0 * (static_cast<double>(divisions) + 1) * (static_cast<double>(divisions) + 1)),
          "box needs finite half-extents and at most 2^27 vertices");
  Mesh mesh;
  mesh.source = "box";
  const Eigen::Vector3d half(hx, hy, hz);
  // Each face: a normal axis, its sign, and two in-plane axes ordered so the winding faces outward.
  for (int axis = 0; axis < 3; ++axis) {
    for (const int sign : {1, -1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
      for (int i = 0; i <= divisions; ++i) {
        for (int j = 0; j <= divisions; ++j) {
          Eigen::Vector3d p;
          p[axis] = sign * half[axis];
          const double su = -1.0 + 2.0 * i / divisions, sv = -1.0 + 2.0 * j / divisions;
          p[u] = su * half[u];
          p[v] = (sign > 0 ? sv : -sv) * half[v];
          mesh.vertices.push_back(p);
        }
      }
      // grid rows advance along u, columns along v: (u x v) = axis, outward for sign > 0.
      const std::size_t first = mesh.triangles.size();
      grid_triangles(mesh, base, divisions, divisions, false);
      (void)first;
    }
  }
  return mesh;
}

Mesh make_plate(double half_size, double thickness, int divisions) {
  require(half_size > 0.0 && thickness > 0.0 && divisions >= 1, "plate needs positive size, thickness and divisions");
  Mesh mesh = make_box(half_size, half_size, 0.5 * thickness, divisions);
  mesh.source = "plate";
  return mesh;
}

}  // namespace caliber
