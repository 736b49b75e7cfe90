// caliber's own OFF reader. assimp's OFF importer crashes (SEGV) on some malformed files (found by
// tests/fuzz/mesh_loader_fuzz.cpp, kept in tests/fuzz/regressions/mesh_loader/), clamps
// out-of-range indices and stores coordinates as floats; this one is strict and keeps doubles.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "caliber/error.h"
#include "mesh/readers.h"
#include "mesh/text_lines.h"

namespace caliber::mesh_io {
namespace {

/// "OFF" and the variants whose extra per-vertex values follow x y z: ST (texture), C (colour),
/// N (normal). "4OFF", "nOFF" (other dimensions) and binary OFF are not supported.
bool is_header(std::string_view t) {
  if (t.size() < 3 || t.substr(t.size() - 3) != "OFF") return false;
  std::string_view prefix = t.substr(0, t.size() - 3);
  if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
  if (!prefix.empty() && prefix[0] == 'C') prefix.remove_prefix(1);
  if (!prefix.empty() && prefix[0] == 'N') prefix.remove_prefix(1);
  return prefix.empty();
}

}  // namespace

bool looks_like_off(const std::string& head) {
  std::size_t i = 0;
  while (i < head.size() && std::isspace(static_cast<unsigned char>(head[i]))) ++i;
  std::size_t j = i;
  while (j < head.size() && std::isalnum(static_cast<unsigned char>(head[j]))) ++j;
  return is_header(std::string_view(head).substr(i, j - i));
}

Mesh read_off(const std::filesystem::path& file) {
  const std::string path = file.string();
  const std::string data = read_file(path);
  const auto fail = [&](const std::string& why) { throw Error(ErrorCode::unreadable, path, "cannot parse mesh: " + why); };
  const Lines lines = tokenize(data);
  const auto where = [&](std::size_t l) { return "line " + std::to_string(lines.number[l]); };
  const auto number = [&](std::size_t l, std::size_t k, const char* what) {
    const std::optional<double> v = parse_number(lines.token(l, k));
    if (!v) fail(where(l) + ": " + quote_token(lines.token(l, k)) + " is not " + what);
    return *v;
  };
  const auto count = [&](std::size_t l, std::size_t k, const char* what) -> std::uint64_t {
    const double v = number(l, k, what);
    if (!(v >= 0) || v != std::floor(v) || v > 4e9) fail(where(l) + ": " + quote_token(lines.token(l, k)) + " is not " + what);
    return static_cast<std::uint64_t>(v);
  };

  if (lines.empty()) fail("no content");
  std::size_t l = 0, k = 0;
  if (is_header(lines.token(0, 0))) {
    if (lines.count(0) > 1 && lines.token(0, 1) == "BINARY") fail("binary OFF is not supported");
    if (lines.count(0) == 1)
      l = 1;
    else
      k = 1;  // counts may follow the header on its line
  } else if (lines.token(0, 0).find("OFF") != std::string_view::npos) {
    fail("unsupported OFF variant " + quote_token(lines.token(0, 0)) +
         " (caliber reads OFF, COFF, NOFF, CNOFF, STOFF and the like, ascii)");
  }
  if (l >= lines.size()) fail("no vertex and face counts after the header (truncated file?)");
  if (lines.count(l) < k + 2) fail(where(l) + ": expected the vertex and face counts");
  const std::uint64_t nv = count(l, k, "a vertex count"), nf = count(l, k + 1, "a face count");
  ++l;
  // One line per vertex and per face: counts the file cannot hold fail before any allocation.
  if (nv + nf > lines.size() - l) {
    fail("the header announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) + " faces but only " +
         std::to_string(lines.size() - l) + " lines follow (truncated file?)");
  }
  Mesh mesh;
  mesh.source = path;
  mesh.vertices.reserve(nv);
  for (std::uint64_t v = 0; v < nv; ++v, ++l) {
    if (lines.count(l) < 3) fail(where(l) + ": vertex " + std::to_string(v) + " needs x y z");
    Eigen::Vector3d p;
    for (int c = 0; c < 3; ++c) p[c] = number(l, static_cast<std::size_t>(c), "a coordinate");
    if (!p.allFinite()) throw Error(ErrorCode::bad_value, path, "vertex " + std::to_string(v) + " has a non-finite coordinate");
    mesh.vertices.push_back(p);
  }
  std::vector<std::uint32_t> idx;
  mesh.triangles.reserve(nf);
  for (std::uint64_t f = 0; f < nf; ++f, ++l) {
    const std::uint64_t corners = count(l, 0, "a corner count");
    if (corners < 3) {
      throw Error(ErrorCode::bad_index, path,
                  "face " + std::to_string(f) + " has " + std::to_string(corners) + " corner(s); a face needs at least 3");
    }
    if (lines.count(l) < corners + 1)
      fail(where(l) + ": face " + std::to_string(f) + " lists fewer than " + std::to_string(corners) + " corners");
    idx.clear();
    for (std::uint64_t c = 0; c < corners; ++c) {
      const std::uint64_t i = count(l, static_cast<std::size_t>(c + 1), "a vertex index");
      if (i >= nv) {
        throw Error(
            ErrorCode::bad_index, path,
            "face " + std::to_string(f) + " refers to vertex " + std::to_string(i) + " but there are only " + std::to_string(nv));
      }
      idx.push_back(static_cast<std::uint32_t>(i));
    }
    for (std::size_t c = 1; c + 1 < idx.size(); ++c) mesh.triangles.push_back({idx[0], idx[c], idx[c + 1]});
  }
  if (l < lines.size()) {
    fail(where(l) + ": content after the " + std::to_string(nf) + " faces the header announces (" +
         quote_token(lines.token(l, 0)) + "...): a wrong face count?");
  }
  if (mesh.triangles.empty()) throw Error(ErrorCode::empty_mesh, path, "mesh has no triangles");
  return mesh;
}

}  // namespace caliber::mesh_io
