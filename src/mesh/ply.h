#pragma once
// caliber's own PLY reader (src/mesh/ply.cpp): load_mesh sends PLY files here instead of assimp.

#include <filesystem>
#include <string>

#include "caliber/mesh.h"

namespace caliber::mesh_io {

/// True when `head` (the file's first bytes) starts with the PLY magic line.
[[nodiscard]] bool looks_like_ply(const std::string& head);

/// Reads an ascii or binary PLY file: element `vertex` (x, y, z of any numeric type) and element
/// `face` (list `vertex_indices`, or `vertex_index`); other elements and properties are skipped.
/// Polygons are fanned from their first corner, in file order. Throws caliber::Error naming the
/// file on any problem; does not call validate_mesh.
[[nodiscard]] Mesh read_ply(const std::filesystem::path& path);

}  // namespace caliber::mesh_io
