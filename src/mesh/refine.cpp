// Midpoint subdivision and OFF output.

#include <fstream>
#include <map>
#include <utility>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "util/memory.h"

namespace caliber {
namespace {

Mesh refine_once(const Mesh& in) {
  Mesh out;
  out.source = in.source;
  out.vertices = in.vertices;
  out.triangles.reserve(4 * in.triangles.size());
  if (!in.groups.empty()) out.groups.reserve(4 * in.groups.size());
  // One midpoint per edge (by vertex indices), so shared edges stay shared.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
  const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const auto key = std::minmax(a, b);
    const auto [it, inserted] = midpoints.try_emplace({key.first, key.second}, 0u);
    if (inserted) {
      it->second = static_cast<std::uint32_t>(out.vertices.size());
      out.vertices.push_back(0.5 * (in.vertices[key.first] + in.vertices[key.second]));
    }
    return it->second;
  };
  for (std::size_t t = 0; t < in.triangles.size(); ++t) {
    const auto [a, b, c] = in.triangles[t];
    const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    out.triangles.push_back({a, ab, ca});
    out.triangles.push_back({ab, b, bc});
    out.triangles.push_back({ca, bc, c});
    out.triangles.push_back({ab, bc, ca});
    if (!in.groups.empty()) out.groups.insert(out.groups.end(), 4, in.groups[t]);
  }
  return out;
}

}  // namespace

Mesh refine_mesh(const Mesh& mesh, int levels) {
  if (levels < 0 || levels > 8) throw Error(ErrorCode::bad_value, "refine", "levels must be in [0, 8]");
  validate_mesh(mesh);  // indices and groups are read as given: a hand-built mesh is checked first
  const std::uint64_t triangles = std::uint64_t{mesh.triangles.size()} << (2 * levels);
  if (triangles >= 0x7fffffffu) {
    throw Error(ErrorCode::bad_value, mesh.source,
                "refining this mesh " + std::to_string(levels) + " times makes " + std::to_string(triangles) +
                    " triangles, more than caliber's limit of 2^31 - 1");
  }
  // The last level holds its input and its output (12 bytes a triangle, 24 a vertex, about half a
  // vertex a triangle) and a map entry per edge (about 64 bytes, 3/8 of an edge per new triangle).
  const double needed = static_cast<double>(triangles) * (12.0 + 12.0 + 0.375 * 64.0 + 0.25 * 24.0) +
                        static_cast<double>(mesh.vertices.size()) * 24.0;
  const std::uint64_t available = util::available_memory();
  if (levels > 0 && needed > static_cast<double>(available)) {
    throw Error(ErrorCode::out_of_memory, mesh.source,
                "refining this mesh " + std::to_string(levels) + " times makes " + std::to_string(triangles) +
                    " triangles and needs about " + util::format_bytes(needed) + ", more than the " +
                    util::format_bytes(static_cast<double>(available)) + " of memory available");
  }
  Mesh out = mesh;
  for (int i = 0; i < levels; ++i) out = refine_once(out);
  return out;
}

void write_off(const Mesh& mesh, std::ostream& out) {
  out.precision(17);
  out << "OFF\n" << mesh.vertices.size() << ' ' << mesh.triangles.size() << " 0\n";
  for (const auto& v : mesh.vertices) out << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : mesh.triangles) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

void save_off(const Mesh& mesh, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw Error(ErrorCode::unreadable, path.string(), "cannot be opened for writing");
  write_off(mesh, out);
  out.flush();
  if (!out) throw Error(ErrorCode::unreadable, path.string(), "write failed");
}

}  // namespace caliber
