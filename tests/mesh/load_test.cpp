#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

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
TEST(LoadMeshErrors, IndexOutOfRange) { expect_error(kData / "bad/index_range.off", ErrorCode::unreadable, "out of range"); }
TEST(LoadMeshErrors, FaceWithTwoCorners) { expect_error(kData / "bad/two_corners.off", ErrorCode::bad_index, "2 corner"); }
TEST(LoadMeshErrors, NoTriangles) { expect_error(kData / "bad/no_faces.off", ErrorCode::unreadable, "no valid faces"); }

TEST(LoadMeshErrors, OtherFormats) {
  expect_error(kData / "bad/index_range.obj", ErrorCode::unreadable, "out of range");
  expect_error(kData / "bad/index_range.ply", ErrorCode::bad_index, "refers to vertex 9");
  expect_error(kData / "bad/nan.obj", ErrorCode::bad_value, "non-finite");
  expect_error(kData / "bad/no_faces.obj", ErrorCode::empty_mesh, "no triangles");
  expect_error(kData / "bad/truncated_ascii.stl", ErrorCode::unreadable, "cannot parse");
}

TEST(LoadMeshErrors, TruncatedOff) {
  // assimp reads the missing face as one with no corners; either way it must be an error, not a mesh.
  EXPECT_THROW((void)load_mesh(kData / "bad/truncated.off"), Error);
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

}  // namespace
}  // namespace caliber
