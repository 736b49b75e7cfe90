#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/scene.h"

#include "support/error_message.h"

#include "caliber/error.h"
#include "caliber/mesh.h"

namespace caliber {
namespace {

const std::filesystem::path kData = CALIBER_TEST_DATA;

/// The tetrahedron of tests/data as every format stores it: vertex positions of each triangle.
void expect_tetra(const Mesh& mesh) {
  ASSERT_EQ(mesh.triangles.size(), 4u);
  const Eigen::Vector3d want[4][3] = {{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}},
                                      {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}},
                                      {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                                      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int t = 0; t < 4; ++t) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mesh.vertices[mesh.triangles[t][k]], want[t][k]) << "triangle " << t;
  }
}

TEST(LoadMesh, OffKeepsFaceOrder) { expect_tetra(load_mesh(kData / "tetra.off")); }
TEST(LoadMesh, PlyKeepsFaceOrder) { expect_tetra(load_mesh(kData / "tetra.ply")); }
TEST(LoadMesh, AsciiStlKeepsFaceOrder) { expect_tetra(load_mesh(kData / "tetra_ascii.stl")); }
TEST(LoadMesh, BinaryStlKeepsFaceOrder) { expect_tetra(load_mesh(kData / "tetra_binary.stl")); }

TEST(LoadMesh, PolygonsAreFannedInPlace) {
  const Mesh mesh = load_mesh(kData / "quad_fan.off");
  ASSERT_EQ(mesh.triangles.size(), 4u);  // pentagon -> 3 triangles, then the triangle
  const Eigen::Vector3d p[6] = {{0, 0, 0}, {2, 0, 0}, {3, 1, 0}, {1, 3, 0}, {-1, 1, 0}, {0, 0, 5}};
  const int want[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 1, 5}};
  for (int t = 0; t < 4; ++t) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mesh.vertices[mesh.triangles[t][k]], p[want[t][k]]) << "triangle " << t;
  }
}

TEST(LoadMesh, ObjFansQuadsInPlace) {
  const Mesh mesh = load_mesh(kData / "tetra.obj");
  ASSERT_EQ(mesh.triangles.size(), 5u);
  // f 1 3 5 2 -> (1 3 5), (1 5 2); then f 1 2 4.
  EXPECT_EQ(mesh.vertices[mesh.triangles[0][2]], Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(mesh.vertices[mesh.triangles[1][1]], Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(mesh.vertices[mesh.triangles[1][2]], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(mesh.vertices[mesh.triangles[2][2]], Eigen::Vector3d(0, 0, 1));
}

TEST(MeshFromBuffers, EveryTypeGivesTheFilesMesh) {
  const Mesh file = load_mesh(kData / "tetra.off");
  std::vector<double> xyz;
  std::vector<float> xyz_f;
  for (const Eigen::Vector3d& v : file.vertices) {
    for (int k = 0; k < 3; ++k) {
      xyz.push_back(v[k]);
      xyz_f.push_back(static_cast<float>(v[k]));
    }
  }
  std::vector<std::int64_t> i64;
  std::vector<std::int32_t> i32;
  std::vector<std::uint32_t> u32;
  for (const auto& t : file.triangles) {
    for (const std::uint32_t v : t) {
      i64.push_back(v);
      i32.push_back(static_cast<std::int32_t>(v));
      u32.push_back(v);
    }
  }
  for (const Mesh& m : {mesh_from_buffers(std::span<const double>(xyz), std::span<const std::int64_t>(i64)),
                        mesh_from_buffers(std::span<const double>(xyz), std::span<const std::int32_t>(i32)),
                        mesh_from_buffers(std::span<const double>(xyz), std::span<const std::uint32_t>(u32))}) {
    EXPECT_EQ(m.vertices, file.vertices);
    EXPECT_EQ(m.triangles, file.triangles);
  }
  const Mesh f = mesh_from_buffers(std::span<const float>(xyz_f), std::span<const std::int32_t>(i32), "robot link");
  EXPECT_EQ(f.triangles, file.triangles);
  EXPECT_EQ(f.source, "robot link");
  for (std::size_t v = 0; v < f.vertices.size(); ++v) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(f.vertices[v][k], static_cast<double>(xyz_f[3 * v + static_cast<std::size_t>(k)]));
  }
  EXPECT_EQ(mesh_from_buffers(std::span<const float>(xyz_f), std::span<const std::int64_t>(i64)).triangles, file.triangles);
  EXPECT_EQ(mesh_from_buffers(std::span<const float>(xyz_f), std::span<const std::uint32_t>(u32)).triangles, file.triangles);
}

TEST(MeshFromBuffers, BadBuffersAreErrorsNamingTheSource) {
  const std::vector<double> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const auto message = [](auto&& call) { return test::error_message(call); };
  const std::vector<std::int64_t> past = {0, 1, 3};
  EXPECT_EQ(message([&] { return mesh_from_buffers(std::span<const double>(xyz), std::span<const std::int64_t>(past), "link"); }),
            "link: face 0 refers to vertex 3 but there are only 3");
  const std::vector<std::int32_t> negative = {0, -1, 2};
  EXPECT_EQ(
      message([&] { return mesh_from_buffers(std::span<const double>(xyz), std::span<const std::int32_t>(negative), "link"); }),
      "link: face 0 refers to vertex -1 but there are only 3");
  const std::vector<std::int64_t> two = {0, 1};
  EXPECT_NE(message([&] {
              return mesh_from_buffers(std::span<const double>(xyz), std::span<const std::int64_t>(two), "link");
            }).find("link: the index buffer holds 2 values"),
            std::string::npos);
  const std::vector<double> ragged = {0, 0, 0, 1};
  const std::vector<std::int64_t> tri = {0, 1, 2};
  EXPECT_NE(message([&] {
              return mesh_from_buffers(std::span<const double>(ragged), std::span<const std::int64_t>(tri), "link");
            }).find("the vertex buffer holds 4 values"),
            std::string::npos);
  const std::vector<float> nan = {0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0};
  EXPECT_NE(message([&] {
              return mesh_from_buffers(std::span<const float>(nan), std::span<const std::int64_t>(tri), "link");
            }).find("link: "),
            std::string::npos)
      << "validate_mesh's checks hold: a NaN is refused";
  EXPECT_THROW((void)mesh_from_buffers(std::span<const float>(nan), std::span<const std::int64_t>(tri)), Error);
  EXPECT_THROW((void)mesh_from_buffers(std::span<const double>(xyz), std::span<const std::int64_t>()), Error) << "no triangle";
}

TEST(LoadMesh, DegenerateTrianglesAreKept) {
  const Mesh mesh = load_mesh(kData / "degenerate_only.off");
  EXPECT_EQ(mesh.triangles.size(), 1u);
}

/// Loading `file` throws caliber::Error with `code`, naming the file and containing `words`.
void expect_error(const std::filesystem::path& file, ErrorCode code, const std::string& words) {
  try {
    (void)load_mesh(file);
    FAIL() << "no error for " << file;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(LoadMeshErrors, MissingFile) { expect_error(kData / "no_such_mesh.off", ErrorCode::file_not_found, "no such file"); }
TEST(LoadMeshErrors, Directory) { expect_error(kData / "bad", ErrorCode::unreadable, "directory"); }
TEST(LoadMeshErrors, EmptyFile) { expect_error(kData / "bad/empty.off", ErrorCode::unreadable, "empty"); }
TEST(LoadMeshErrors, Garbage) { expect_error(kData / "bad/garbage.off", ErrorCode::unreadable, "cannot parse"); }
TEST(LoadMeshErrors, TruncatedBinaryStl) { expect_error(kData / "bad/truncated.stl", ErrorCode::unreadable, "cannot parse"); }
TEST(LoadMeshErrors, NonFiniteCoordinate) { expect_error(kData / "bad/nan.off", ErrorCode::bad_value, "non-finite"); }
TEST(LoadMeshErrors, IndexOutOfRange) {
  expect_error(kData / "bad/index_range.off", ErrorCode::bad_index, "face 1 refers to vertex 9 but there are only 4");
}
TEST(LoadMeshErrors, FaceWithTwoCorners) { expect_error(kData / "bad/two_corners.off", ErrorCode::bad_index, "2 corner"); }
TEST(LoadMeshErrors, NoTriangles) { expect_error(kData / "bad/no_faces.off", ErrorCode::empty_mesh, "no triangles"); }

TEST(LoadMeshErrors, OtherFormats) {
  expect_error(kData / "bad/index_range.obj", ErrorCode::bad_index, "a face refers to vertex 7 (1-based) but the file has 3");
  expect_error(kData / "bad/index_range.ply", ErrorCode::bad_index, "refers to vertex 9");
  expect_error(kData / "bad/nan.obj", ErrorCode::bad_value, "non-finite");
  expect_error(kData / "bad/no_faces.obj", ErrorCode::empty_mesh, "no triangles");
  expect_error(kData / "bad/truncated_ascii.stl", ErrorCode::unreadable, "cannot parse");
}

TEST(LoadMeshErrors, APathWithANulByteIsRefusedNotCutThere) {
  // Files are opened by C strings: the path would end at the NUL, and tetra.off would be read.
  const std::string path = (kData / "tetra.off").string() + std::string("\0.bogus", 7);
  for (const bool scene : {false, true}) {
    try {
      if (scene) {
        (void)load_scene(path);
      } else {
        (void)load_mesh(path);
      }
      FAIL() << "a path with a NUL byte was opened";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.code(), ErrorCode::bad_argument) << what;
      EXPECT_NE(what.find("tetra.off\\x00.bogus: the path holds a NUL byte"), std::string::npos) << what;
    }
  }
}

TEST(LoadMeshErrors, TruncatedOff) {
  expect_error(kData / "bad/truncated.off", ErrorCode::unreadable, "but only 3 lines follow (truncated file?)");
}

TEST(LoadOff, VariantsCommentsColoursAndDoubles) {
  const auto write = [](const std::string& name, const std::string& text) {
    const auto path = std::filesystem::temp_directory_path() / ("caliber_off_test_" + name + ".off");
    std::ofstream(path, std::ios::binary) << text;
    return path;
  };
  // Counts on the header line, comments, a colour after each face, CRLF, doubles kept as doubles.
  const Mesh m = load_mesh(write("coff",
                                 "COFF 4 2 0 # counts here\r\n0.1 0 0 255 0 0 255\r\n1 0 0 0 255 0 255\r\n"
                                 "1 1 0 0 0 255 255\r\n# comment line\r\n0 1 0 9 9 9 9\r\n3 0 1 2 1 0 0\r\n3 0 2 3\r\n"));
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.vertices[0].x(), 0.1) << "a double, not a float";
  EXPECT_EQ(m.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
  // No header keyword at all: counts first.
  EXPECT_EQ(load_mesh(write("bare", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).triangles.size(), 1u);
  expect_error(write("binary", "OFF BINARY\n"), ErrorCode::unreadable, "binary OFF is not supported");
  expect_error(write("4off", "4OFF\n1 1 0\n0 0 0 0\n"), ErrorCode::unreadable, "unsupported OFF variant '4OFF'");
  expect_error(write("huge", "OFF\n4000000000 1 0\n0 0 0\n"), ErrorCode::unreadable, "truncated");
  expect_error(write("short_face", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n"), ErrorCode::unreadable,
               "line 6: face 0 lists fewer than 3 corners");
  expect_error(write("word", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"), ErrorCode::unreadable,
               "line 4: 'x' is not a coordinate");
  expect_error(write("negative", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"), ErrorCode::unreadable,
               "'-1' is not a vertex index");
  expect_error(write("vertex", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"), ErrorCode::unreadable, "vertex 1 needs x y z");
  // The input that made assimp's OFF importer crash (tests/fuzz/regressions/mesh_loader/).
  expect_error(write("fuzz", "OFF\n# a pentagon\n3  2 0\n0 0 0\n2 0 0\n3 1 0\n1 3 0\nOFF\n"), ErrorCode::bad_index,
               "face 0 has 1 corner(s)");
}

TEST(ValidateMesh, ReportsProblemsOfHandBuiltMeshes) {
  Mesh mesh;
  mesh.source = "hand-built";
  EXPECT_THROW(validate_mesh(mesh), Error);  // no triangles
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 3}};
  EXPECT_THROW(validate_mesh(mesh), Error);  // index out of range
  mesh.triangles = {{0, 1, 2}};
  EXPECT_NO_THROW(validate_mesh(mesh));
  mesh.vertices[1].x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(validate_mesh(mesh), Error);
  mesh.vertices[1].x() = 1;
  mesh.groups = {64};
  EXPECT_THROW(validate_mesh(mesh), Error);
  mesh.groups = {3};
  EXPECT_NO_THROW(validate_mesh(mesh));
}

TEST(LoadMesh, CgalMeshesLoad) {
  const std::filesystem::path dir = CALIBER_MESH_DATA;
  if (!std::filesystem::exists(dir / "armadillo.off")) GTEST_SKIP() << "run scripts/fetch_meshes.sh first";
  const Mesh mesh = load_mesh(dir / "armadillo.off");
  EXPECT_EQ(mesh.triangles.size(), 52000u);
}

namespace ply {

/// Writes `header` + `body` to a file in the temp dir and returns its path.
std::filesystem::path write(const std::string& name, const std::string& bytes) {
  const auto path = std::filesystem::temp_directory_path() / ("caliber_ply_test_" + name + ".ply");
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

/// Writes `bytes` to a file of that name (its extension chooses the reader) in the temp dir.
std::filesystem::path write_named(const std::string& name, const std::string& bytes) {
  const auto path = std::filesystem::temp_directory_path() / ("caliber_load_test_" + name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

template <class T>
std::string raw(T value, bool big_endian) {
  std::string b(sizeof(T), '\0');
  std::memcpy(b.data(), &value, sizeof(T));
  if (big_endian) std::reverse(b.begin(), b.end());
  return b;
}

/// The tetrahedron as binary PLY, with double coordinates, an extra vertex property and an extra
/// element, in either byte order.
std::string binary_tetra(bool big) {
  std::string s = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\ncomment made by a test\nelement vertex 4\nproperty double x\nproperty double y\n"
                  "property double z\nproperty uchar red\nelement face 4\nproperty list uchar uint vertex_indices\n"
                  "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  const double v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& p : v) s += raw(p[0], big) + raw(p[1], big) + raw(p[2], big) + raw<std::uint8_t>(200, big);
  const std::uint32_t f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& t : f) s += raw<std::uint8_t>(3, big) + raw(t[0], big) + raw(t[1], big) + raw(t[2], big);
  return s + raw<std::int32_t>(0, big) + raw<std::int32_t>(1, big);
}

}  // namespace ply

TEST(LoadPly, BinaryBothByteOrdersDoublesAndExtraProperties) {
  expect_tetra(load_mesh(ply::write("le", ply::binary_tetra(false))));
  expect_tetra(load_mesh(ply::write("be", ply::binary_tetra(true))));
  // A binary body whose first byte is '\n' (assimp skips it and shifts everything).
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty uchar x\nproperty uchar y\n"
      "property uchar z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  s += std::string("\n\0\0", 3) + std::string("\0\n\0", 3) + std::string("\0\0\n", 3);
  s += ply::raw<std::uint8_t>(3, false) + ply::raw<std::int32_t>(0, false) + ply::raw<std::int32_t>(1, false) +
       ply::raw<std::int32_t>(2, false);
  const Mesh m = load_mesh(ply::write("newline_body", s));
  ASSERT_EQ(m.vertices.size(), 3u);
  EXPECT_EQ(m.vertices[0], Eigen::Vector3d(10, 0, 0));
  EXPECT_EQ(m.vertices[2], Eigen::Vector3d(0, 0, 10));
}

TEST(LoadPly, AsciiWithCrLfQuadsAndPlusSigns) {
  const Mesh m = load_mesh(ply::write("quad",
                                      "ply\r\nformat ascii 1.0\r\nelement vertex 4\r\nproperty float x\r\n"
                                      "property float y\r\nproperty float z\r\nelement face 1\r\n"
                                      "property list uchar int vertex_index\r\nend_header\r\n"
                                      "0 0 0\r\n+1 0 0\r\n1 1 0\r\n0 1 0.5e0\r\n4 0 1 2 3\r\n"));
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(m.vertices[3].z(), 0.5);
}

TEST(LoadMeshErrors, AnImportersMessageIsBounded) {
  // assimp's STL reader quotes the token it cannot parse, here the rest of a 200,000-byte line.
  const std::filesystem::path file =
      ply::write_named("long_token.stl", "solid x\n facet normal 0 0 1\n outer loop\n vertex " + std::string(200000, 'q'));
  try {
    (void)load_mesh(file);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_LT(what.size(), 600u) << "a message of a few hundred bytes, not the file";
    EXPECT_NE(what.find("cannot parse mesh: "), std::string::npos) << what;
    EXPECT_NE(what.find("... (200"), std::string::npos) << "says how much was cut: " << what;
  }
}

TEST(LoadPly, BadFilesFailClearly) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(load_mesh(ply::write("ok", head + "end_header\n" + body)).triangles.size(), 1u);
  // assimp hangs on this one (found by the fuzzer; also in tests/fuzz/regressions/mesh_loader/).
  expect_error(ply::write("no_end", head), ErrorCode::unreadable, "no 'end_header'");
  expect_error(ply::write("no_end_body", head + body), ErrorCode::unreadable, "header line 9: unknown header keyword '0'");
  expect_error(ply::write("huge_count",
                          "ply\nformat ascii 1.0\nelement vertex 100000000\nproperty float x\nproperty float y\n"
                          "property float z\nend_header\n0 0 0\n"),
               ErrorCode::unreadable, "more than the file holds");
  expect_error(ply::write("no_props", "ply\nformat ascii 1.0\nelement junk 1000000000000000000\nend_header\n"),
               ErrorCode::unreadable, "no properties");
  expect_error(ply::write("truncated", head + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1"), ErrorCode::unreadable, "truncated");
  expect_error(ply::write("word", head + "end_header\n0 0 zero\n1 0 0\n0 1 0\n3 0 1 2\n"), ErrorCode::unreadable,
               "'zero' is not a number");
  expect_error(ply::write("nan", head + "end_header\n0 0 nan\n1 0 0\n0 1 0\n3 0 1 2\n"), ErrorCode::bad_value, "non-finite");
  expect_error(ply::write("two", head + "end_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"), ErrorCode::bad_index, "2 corner");
  expect_error(ply::write("range", head + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"), ErrorCode::bad_index,
               "refers to vertex 7");
  expect_error(ply::write("huge_index", head + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1e300\n"), ErrorCode::bad_index,
               "refers to vertex 1e+300 but there are only 3");
  expect_error(ply::write("negative_index", head + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"), ErrorCode::bad_index,
               "refers to vertex -1 but");
  expect_error(ply::write("fraction", head + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1.5\n"), ErrorCode::unreadable,
               "not an integer");
  expect_error(ply::write("format", "ply\nformat binary_middle_endian 1.0\nend_header\n"), ErrorCode::unreadable,
               "unknown format");
  expect_error(ply::write("keyword", "ply\nformat ascii 1.0\nelemnt vertex 3\nend_header\n"), ErrorCode::unreadable,
               "unknown header keyword 'elemnt'");
  expect_error(ply::write("points",
                          "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                          "property float z\nend_header\n0 0 0\n"),
               ErrorCode::empty_mesh, "no triangles");
  std::string list =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty uchar x\nproperty uchar y\n"
      "property uchar z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  list += std::string(9, '\0') + ply::raw<std::uint32_t>(4000000000u, false) + ply::raw<std::int32_t>(0, false);
  expect_error(ply::write("long_list", list), ErrorCode::unreadable, "list longer than the rest of the file");
}

}  // namespace
}  // namespace caliber
