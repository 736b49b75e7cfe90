#pragma once
/// \file
/// Triangle meshes: the geometry of one rigid object, in its own (object) frame.

#include "caliber/export.h"
#include <array>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <span>
#include <string_view>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace caliber {

/// A triangle mesh in object space. Triangle ids are indices into `triangles`; loaders keep the
/// file's face order so that users and tests can refer to triangles by id.
struct Mesh {
  /// Vertex positions (object space). All finite once validated.
  std::vector<Eigen::Vector3d> vertices;
  /// Triangles as three vertex indices. Degenerate (zero-area) triangles are allowed.
  std::vector<std::array<std::uint32_t, 3>> triangles;
  /// Optional primitive group of each triangle (0..63), used by the group-compatibility test.
  /// Empty means every triangle is in group 0.
  std::vector<std::uint8_t> groups;
  /// Where the mesh came from (a file path or a generator name), used in error messages.
  std::string source;
};

/// Largest number of primitive groups (one bit each in a BVH node's mask).
inline constexpr int kMaxGroups = 64;

/// Largest magnitude caliber accepts for a vertex coordinate (after scaling), a pose translation or
/// a query tolerance. It keeps every product in the exact predicates and every float bound in the
/// BVH far from overflow, so that no input can turn into infinities and a silent wrong answer.
inline constexpr double kMaxCoordinate = 1e15;

/// Smallest magnitude caliber accepts for a non-zero vertex coordinate (after scaling), pose
/// translation or tolerance: 2^-120, about 7.5e-37. Between it and kMaxCoordinate, every product the
/// exact predicates and the closest-point routines form (up to the fourth power of a coordinate
/// difference) stays a normal double and every float bound of the BVH a normal float, so answers do
/// not depend on scale: a mesh scaled by a power of two 2^k gives the same pairs and 2^k times the
/// points and distances. Smaller values would be rounded to zero or to subnormals and answers
/// could go wrong silently, so they are refused.
inline constexpr double kMinCoordinate = 0x1p-120;

/// The formats load_mesh reads, for messages: ".off, .ply, .obj and .stl".
[[nodiscard]] CALIBER_EXPORT std::string_view supported_mesh_formats();

/// Loads a mesh, the reader chosen by the file's extension (any case) and never by its content:
/// .off, .ply and .obj by caliber's own strict readers (OBJ: polygonal geometry only; material
/// libraries are never opened), .stl (ascii and binary) by assimp's STL importer. Any other
/// extension, or none, is refused. Triangle ids follow the
/// file's face order; a polygon with n > 3 corners becomes n-2 triangles
/// fanned from its first corner, in place. Vertices are not merged or reordered.
/// Throws caliber::Error naming the file on a missing file, a parse error, a non-finite coordinate,
/// an index out of range, a face with fewer than 3 corners, or a mesh without triangles.
[[nodiscard]] CALIBER_EXPORT Mesh load_mesh(const std::filesystem::path& path);

/// A mesh from a program's own buffers: `xyz` holds the vertices as x, y, z triples (3n values),
/// `indices` the triangles as three vertex indices each (3m values). The same checks as the file
/// readers: a length that is not a multiple of 3, a negative index or one past the vertices, more
/// vertices than 32-bit ids reach, or what validate_mesh refuses, throws caliber::Error naming
/// `source` and the problem (for example "face 7 refers to vertex 12 but there are only 10").
[[nodiscard]] CALIBER_EXPORT Mesh mesh_from_buffers(std::span<const double> xyz, std::span<const std::int64_t> indices,
                                                    std::string source = "buffers");
/// See above: float vertices, 32-bit indices, and the mixes.
[[nodiscard]] CALIBER_EXPORT Mesh mesh_from_buffers(std::span<const float> xyz, std::span<const std::int32_t> indices,
                                                    std::string source = "buffers");
[[nodiscard]] CALIBER_EXPORT Mesh mesh_from_buffers(std::span<const float> xyz, std::span<const std::int64_t> indices,
                                                    std::string source = "buffers");
[[nodiscard]] CALIBER_EXPORT Mesh mesh_from_buffers(std::span<const double> xyz, std::span<const std::int32_t> indices,
                                                    std::string source = "buffers");
[[nodiscard]] CALIBER_EXPORT Mesh mesh_from_buffers(std::span<const float> xyz, std::span<const std::uint32_t> indices,
                                                    std::string source = "buffers");
[[nodiscard]] CALIBER_EXPORT Mesh mesh_from_buffers(std::span<const double> xyz, std::span<const std::uint32_t> indices,
                                                    std::string source = "buffers");

/// Checks the invariants every routine relies on: at least one triangle, finite coordinates of
/// magnitude 0 or in [kMinCoordinate, kMaxCoordinate], indices in range, groups (if any) one per triangle and below kMaxGroups.
/// Throws caliber::Error naming `mesh.source` and the first problem found.
CALIBER_EXPORT void validate_mesh(const Mesh& mesh);

/// 1-to-4 midpoint subdivision, `levels` times: triangle t becomes triangles 4t .. 4t+3 (corner at
/// vertex 0, at vertex 1, at vertex 2, then the middle one), so ids stay predictable. The surface
/// does not change, only its triangle count; groups are inherited.
[[nodiscard]] CALIBER_EXPORT Mesh refine_mesh(const Mesh& mesh, int levels);

/// Writes the mesh as OFF text to a stream (17 significant digits: the doubles come back exactly).
CALIBER_EXPORT void write_off(const Mesh& mesh, std::ostream& out);

/// Writes the mesh as an OFF file. Throws caliber::Error if the file cannot be written.
CALIBER_EXPORT void save_off(const Mesh& mesh, const std::filesystem::path& path);

/// Applies a uniform scale to every vertex (scene files scale meshes). `factor` must be finite and > 0.
CALIBER_EXPORT void scale_mesh(Mesh& mesh, double factor);

}  // namespace caliber
