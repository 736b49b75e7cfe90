// caliber's own OBJ reader. assimp's OBJ importer dropped the first vertex after a byte order mark
// or an indented line (shifting every index after it), read "f +1 +2 +3" as four triangles and
// "1d2", "0x10", "2abc" as 1, 0, 2, opened the material library a file names (a FIFO blocked it
// forever) and refused a file whose library is missing. This one reads polygonal geometry only,
// exactly: every number and index as written, or an error naming the line.
//
// Read: v (x y z, then an optional weight or colour, ignored), f (corners v, v/vt, v//vn or
// v/vt/vn; 1-based, negative counts back from the last vertex so far; polygons fanned from their
// first corner, in file order); vt, vn, vp are checked and counted (faces may refer to them).
// Ignored: groups, objects, smoothing, materials and their libraries (never opened), l and p
// (no area), display attributes. Refused: free-form curves and surfaces, unknown statements.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "caliber/error.h"
#include "mesh/readers.h"
#include "mesh/text_lines.h"

namespace caliber::mesh_io {
namespace {

bool is_ignored(std::string_view keyword) {
  static const std::unordered_set<std::string_view> kIgnored = {
      "o",     "g",        "s",        "mg",         "usemtl",    "mtllib", "usemap", "maplib", "lod",
      "bevel", "c_interp", "d_interp", "shadow_obj", "trace_obj", "ctech",  "stech",  "l",      "p"};
  return kIgnored.count(keyword) > 0;
}

bool is_free_form(std::string_view keyword) {
  static const std::unordered_set<std::string_view> kFreeForm = {"cstype", "deg",  "bmat", "step", "curv", "curv2", "surf",
                                                                 "parm",   "trim", "hole", "scrv", "sp",   "end",   "con"};
  return kFreeForm.count(keyword) > 0;
}

/// The reader's state: what has been read so far, and how to fail naming the file and line.
class ObjReader {
 public:
  ObjReader(std::string path, const Lines& lines) : mPath(std::move(path)), mLines(lines) { mMesh.source = mPath; }

  Mesh read() {
    for (mLine = 0; mLine < mLines.size(); ++mLine) statement();
    // Positive indices may name vertices (texture coordinates, normals) defined further down:
    // checked once all are read.
    if (mLastTexCoord > mTexCoords || mLastNormal > mNormals) {
      const bool tex = mLastTexCoord > mTexCoords;
      throw Error(ErrorCode::bad_index, mPath,
                  std::string("a face refers to ") + (tex ? "texture coordinate " : "normal ") +
                      std::to_string(tex ? mLastTexCoord : mLastNormal) + " but the file has " +
                      std::to_string(tex ? mTexCoords : mNormals));
    }
    for (const auto& t : mMesh.triangles) {
      for (const std::uint32_t v : t) {
        if (v >= mMesh.vertices.size()) {
          throw Error(ErrorCode::bad_index, mPath,
                      "a face refers to vertex " + std::to_string(std::uint64_t{v} + 1) + " (1-based) but the file has " +
                          std::to_string(mMesh.vertices.size()));
        }
      }
    }
    if (mMesh.triangles.empty()) throw Error(ErrorCode::empty_mesh, mPath, "mesh has no triangles (no 'f' line)");
    return std::move(mMesh);
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(ErrorCode::unreadable, mPath, "cannot parse mesh: line " + std::to_string(mLines.number[mLine]) + ": " + why);
  }

  [[nodiscard]] std::string_view token(std::size_t k) const { return mLines.token(mLine, k); }

  void statement() {
    const std::string_view keyword = token(0);
    const std::size_t values = mLines.count(mLine) - 1;
    if (keyword == "v") {
      if (values < 3 || values > 7)
        fail("'v' needs x y z (then at most a weight or a colour), not " + std::to_string(values) + " values");
      Eigen::Vector3d p;
      for (std::size_t k = 1; k <= values; ++k) {
        const double x = number(k);
        if (k <= 3) p[static_cast<int>(k - 1)] = x;
      }
      if (!p.allFinite()) {
        throw Error(ErrorCode::bad_value, mPath,
                    "vertex " + std::to_string(mMesh.vertices.size() + 1) + " (line " + std::to_string(mLines.number[mLine]) +
                        ") has a non-finite coordinate");
      }
      if (mMesh.vertices.size() == std::numeric_limits<std::uint32_t>::max())
        fail("more vertices than caliber indexes (2^32 - 1)");
      mMesh.vertices.push_back(p);
    } else if (keyword == "vt" || keyword == "vn" || keyword == "vp") {
      const std::size_t need = keyword == "vn" ? 3 : 1;
      if (values < need || values > 3) fail(quote_token(keyword) + " needs " + (need == 3 ? "3 values" : "1 to 3 values"));
      for (std::size_t k = 1; k <= values; ++k) (void)number(k);
      ++(keyword == "vt" ? mTexCoords : keyword == "vn" ? mNormals : mParams);
    } else if (keyword == "f" || keyword == "fo") {
      face(values);
    } else if (is_free_form(keyword)) {
      fail("free-form curves and surfaces (" + quote_token(keyword) + ") are not supported: caliber reads polygons ('f')");
    } else if (!is_ignored(keyword)) {
      fail("unknown statement " + quote_token(keyword));
    }
  }

  double number(std::size_t k) const {
    const std::optional<double> v = parse_number(token(k));
    if (!v) fail(quote_token(token(k)) + " is not a number");
    return *v;
  }

  /// A 1-based OBJ reference (negative: from the end of the `defined` so far) as a 0-based index.
  std::uint64_t reference(std::string_view text, std::uint64_t defined, const char* what) const {
    const std::optional<std::int64_t> i = parse_integer(text);
    if (!i) fail(quote_token(text) + " is not a " + what + " index");
    if (*i == 0) fail(std::string(what) + " index 0 (OBJ indices start at 1; negative ones count back from the last)");
    if (*i < 0) {
      if (static_cast<std::uint64_t>(-(*i + 1)) >= defined) {
        fail(std::string(what) + " index " + std::string(text) + " counts back past the first (" + std::to_string(defined) +
             " defined so far)");
      }
      return defined - static_cast<std::uint64_t>(-(*i + 1)) - 1;
    }
    return static_cast<std::uint64_t>(*i - 1);
  }

  void face(std::size_t corners) {
    if (corners < 3) fail("a face has " + std::to_string(corners) + " corner(s); a face needs at least 3");
    mCorners.clear();
    for (std::size_t k = 1; k <= corners; ++k) {
      const std::string_view corner = token(k);
      const std::size_t s1 = corner.find('/');
      const std::uint64_t v = reference(corner.substr(0, s1), mMesh.vertices.size(), "vertex");
      if (v >= std::numeric_limits<std::uint32_t>::max())
        fail("vertex index " + std::string(corner.substr(0, s1)) + " is too large");
      if (s1 != std::string_view::npos) {
        const std::string_view rest = corner.substr(s1 + 1);
        const std::size_t s2 = rest.find('/');
        const std::string_view vt = rest.substr(0, s2);
        if (!vt.empty()) mLastTexCoord = std::max(mLastTexCoord, reference(vt, mTexCoords, "texture coordinate") + 1);
        if (s2 != std::string_view::npos) {
          const std::string_view vn = rest.substr(s2 + 1);
          if (vn.empty() || vn.find('/') != std::string_view::npos)
            fail("corner " + quote_token(corner) + " is not v, v/vt, v//vn or v/vt/vn");
          mLastNormal = std::max(mLastNormal, reference(vn, mNormals, "normal") + 1);
        } else if (vt.empty()) {
          fail("corner " + quote_token(corner) + " is not v, v/vt, v//vn or v/vt/vn");
        }
      }
      mCorners.push_back(static_cast<std::uint32_t>(v));
    }
    for (std::size_t c = 1; c + 1 < mCorners.size(); ++c) mMesh.triangles.push_back({mCorners[0], mCorners[c], mCorners[c + 1]});
  }

  std::string mPath;
  const Lines& mLines;
  std::size_t mLine = 0;
  Mesh mMesh;
  std::uint64_t mTexCoords = 0, mNormals = 0, mParams = 0;
  std::uint64_t mLastTexCoord = 0, mLastNormal = 0;  ///< the largest 1-based vt and vn a face names
  std::vector<std::uint32_t> mCorners;
};

}  // namespace

Mesh read_obj(const std::filesystem::path& file) {
  const std::string path = file.string();
  const std::string data = read_file(path);
  const Lines lines = tokenize(data, /*backslash_joins=*/true);
  if (lines.empty()) throw Error(ErrorCode::unreadable, path, "cannot parse mesh: no content");
  return ObjReader(path, lines).read();
}

}  // namespace caliber::mesh_io
