#pragma once
// caliber's own readers for PLY (src/mesh/ply.cpp), OFF (src/mesh/off.cpp) and OBJ
// (src/mesh/obj.cpp): load_mesh sends those formats here; assimp reads STL. The readers are
// strict: every problem is a caliber::Error naming the file, and no count is trusted before the
// bytes behind it are there.

#include <filesystem>
#include <string>
#include <string_view>

#include "caliber/mesh.h"

namespace caliber::mesh_io {

/// A token of a file, for a message: in single quotes, bytes that do not print (NUL, control
/// characters, non-ASCII) written as \xNN, at most 40 bytes of it (then "...").
[[nodiscard]] std::string quote_token(std::string_view token);

/// True when `head` (the file's first bytes) starts with the PLY magic line.
[[nodiscard]] bool looks_like_ply(const std::string& head);

/// Reads an ascii or binary PLY file: element `vertex` (x, y, z of any numeric type) and element
/// `face` (list `vertex_indices`, or `vertex_index`); other elements and properties are skipped.
/// Polygons are fanned from their first corner, in file order. Throws caliber::Error naming the
/// file on any problem; does not call validate_mesh.
[[nodiscard]] Mesh read_ply(const std::filesystem::path& path);

/// True when `head` (the file's first bytes) starts with an OFF header keyword (OFF, COFF, NOFF,
/// CNOFF, STOFF, ...).
[[nodiscard]] bool looks_like_off(const std::string& head);

/// Reads an ascii OFF file (header keyword optional; extra per-vertex and per-face values such as
/// colours are skipped). Polygons are fanned from their first corner, in file order. Throws
/// caliber::Error naming the file on any problem; does not call validate_mesh.
[[nodiscard]] Mesh read_off(const std::filesystem::path& path);

/// Reads the polygonal geometry of an OBJ file (v and f; see src/mesh/obj.cpp for what else is
/// read, ignored or refused). Material libraries are never opened. Polygons are fanned from their
/// first corner, in file order. Throws caliber::Error naming the file and line on any problem;
/// does not call validate_mesh.
[[nodiscard]] Mesh read_obj(const std::filesystem::path& path);

}  // namespace caliber::mesh_io
