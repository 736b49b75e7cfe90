// The strict text readers on the files that were read wrong: OBJ (caliber's own reader since assimp
// dropped or invented vertices and triangles), OFF and PLY content past the declared counts, PLY
// faces before vertices. A valid file gives exactly its vertices and triangles; anything else is
// an error naming the file and the line.

#include <sys/stat.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/error_message.h"

#include "caliber/error.h"
#include "caliber/mesh.h"

namespace caliber {
namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

std::filesystem::path scratch() {
  const auto dir = std::filesystem::temp_directory_path() / ("caliber_text_formats_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path write(const std::string& name, const std::string& bytes) {
  const auto path = scratch() / name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

/// The error loading `name` (holding `bytes`) gives: it must name the file.
std::string error_of(const std::string& name, const std::string& bytes) {
  const auto path = write(name, bytes);
  const std::string message = test::error_message([&] { return load_mesh(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_LE(message.size(), path.string().size() + 300) << message;
  return message;
}

void expect_mesh(const Mesh& mesh, const std::vector<Eigen::Vector3d>& vertices, const Triangles& triangles) {
  ASSERT_EQ(mesh.vertices.size(), vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) EXPECT_EQ(mesh.vertices[i], vertices[i]) << "vertex " << i;
  EXPECT_EQ(mesh.triangles, triangles);
}

TEST(LoadObj, EveryValidGeometryOnlyFileIsReadExactly) {
  // What assimp read wrong: a byte order mark and indentation (it dropped the vertex), '+' signs
  // (four triangles), ".5"; then every corner form, negative indices, a missing material library
  // (never opened), usemtl without one, colours and weights after x y z, a continued line, CR LF.
  const std::string text =
      "\xEF\xBB\xBFv 0 0 0\n  v 1 0 0\n\tv 0 .5 0\r\nv 0 0 1 1.0\nv 2e0 +2 -0.25 0.5 0.5 0.5\n"
      "mtllib missing.mtl\nusemtl red\no thing\ng part\ns 1\nvt 0 0\nvt 1 0 0\nvn 0 0 1\n"
      "f +1 +2 +3\nf -5 -4 -2\nf 1/1 3/2 4/1 5/2\nf 2//1 3//1 \\\n 4//1\nf 1/2/1 2/1/1 5/2/1\nl 1 2\n# the end\n";
  const Mesh mesh = load_mesh(write("valid.obj", text));
  expect_mesh(mesh, {{0, 0, 0}, {1, 0, 0}, {0, 0.5, 0}, {0, 0, 1}, {2, 2, -0.25}},
              {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {0, 3, 4}, {1, 2, 3}, {0, 1, 4}});
}

TEST(LoadObj, FacesMayNameVerticesDefinedFurtherDown) {
  expect_mesh(load_mesh(write("later.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
              {{0, 1, 2}});
}

TEST(LoadObj, NumbersAreNumbersOnlyAsWritten) {
  const std::string rest = " 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  for (const std::string bad : {"1d2", "0x10", "2abc", "1-2", "++1", "+-1", "--1", "-", "1.0.0", "1e", ",5"}) {
    EXPECT_NE(error_of("number.obj", "v " + bad + rest).find("line 1: '" + bad + "' is not a number"), std::string::npos) << bad;
  }
  // Indices are integers: no fractions, exponents, hex or stray signs.
  const std::string three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (const std::string bad : {"1.0", "1e0", "0x1", "+-1", "1a", "2/x", "3/1/y"}) {
    const std::string message = error_of("index.obj", three + "vt 0 0\nvn 0 0 1\nf 1 2 " + bad + "\n");
    EXPECT_NE(message.find("line 6: '"), std::string::npos) << bad << ": " << message;
    EXPECT_NE(message.find("index"), std::string::npos) << bad << ": " << message;
  }
}

TEST(LoadObj, BadIndicesAndStatementsNameTheLine) {
  const std::string three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_NE(error_of("zero.obj", three + "f 1 2 0\n").find("line 4: vertex index 0 (OBJ indices start at 1"), std::string::npos);
  EXPECT_NE(
      error_of("back.obj", three + "f 1 2 -4\n").find("line 4: vertex index -4 counts back past the first (3 defined so far)"),
      std::string::npos);
  EXPECT_NE(error_of("past.obj", three + "f 1 2 4\n").find("a face refers to vertex 4 (1-based) but the file has 3"),
            std::string::npos);
  EXPECT_NE(error_of("huge.obj", three + "f 1 2 99999999999999999999\n").find("'99999999999999999999' is not a vertex index"),
            std::string::npos);
  EXPECT_NE(error_of("vt.obj", three + "vt 0 0\nf 1/1 2/1 3/2\n").find("refers to texture coordinate 2 but the file has 1"),
            std::string::npos);
  EXPECT_NE(error_of("vn.obj", three + "f 1//1 2//1 3//1\n").find("refers to normal 1 but the file has 0"), std::string::npos);
  EXPECT_NE(error_of("corner.obj", three + "f 1 2 3/\n").find("line 4: corner '3/' is not v, v/vt, v//vn or v/vt/vn"),
            std::string::npos);
  EXPECT_NE(error_of("two.obj", three + "f 1 2\n").find("line 4: a face has 2 corner(s)"), std::string::npos);
  EXPECT_NE(error_of("short_v.obj", "v 0 0\n").find("line 1: 'v' needs x y z"), std::string::npos);
  EXPECT_NE(
      error_of("curve.obj", three + "cstype bspline\ncurv 0 1 1 2\n").find("line 4: free-form curves and surfaces ('cstype')"),
      std::string::npos);
  EXPECT_NE(error_of("unknown.obj", three + "frobnicate 1\n").find("line 4: unknown statement 'frobnicate'"), std::string::npos);
  EXPECT_NE(error_of("nan.obj", "v 0 nan 0\n").find("vertex 1 (line 1) has a non-finite coordinate"), std::string::npos);
  EXPECT_NE(error_of("no_faces.obj", three).find("mesh has no triangles (no 'f' line)"), std::string::npos);
  EXPECT_NE(error_of("comments.obj", "# nothing\n\n").find("no content"), std::string::npos);
}

TEST(LoadObj, MessagesEscapeBytesThatDoNotPrint) {
  static const char kBytes[] = "v 1\0x\xff 0 0\n";
  const std::string message = error_of("bytes.obj", std::string(kBytes, sizeof kBytes - 1));
  EXPECT_NE(message.find("'1\\x00x\\xff' is not a number"), std::string::npos) << message;
  const std::string long_token = error_of("long.obj", "v " + std::string(100000, '7') + "x 0 0\n");
  EXPECT_NE(long_token.find("..."), std::string::npos) << long_token;
}

TEST(LoadObj, MaterialLibrariesAreNeverOpened) {
  // A library that is a FIFO blocked assimp forever; one that is a directory, or missing, is fine.
  const auto fifo = scratch() / "blocking.mtl";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::filesystem::create_directories(scratch() / "dir.mtl");
  const Mesh mesh = load_mesh(write("fifo.obj", "mtllib blocking.mtl dir.mtl none.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(mesh.triangles.size(), 1u);
}

TEST(LoadOff, ContentAfterTheDeclaredFacesIsAnError) {
  EXPECT_NE(error_of("extra.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 2 1 0\n")
                .find("line 7: content after the 1 faces the header announces ('3'...): a wrong face count?"),
            std::string::npos);
  EXPECT_EQ(load_mesh(write("trailing.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n# end\n  \n")).triangles.size(), 1u);
}

TEST(LoadPly, FacesMayComeBeforeVerticesAndNothingAfterTheElements) {
  const std::string faces_first =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n3 2 1 0\n0 0 0\n1 0 0\n0 1 0\n";
  expect_mesh(load_mesh(write("faces_first.ply", faces_first)), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{2, 1, 0}});
  EXPECT_NE(error_of("faces_first_range.ply", std::string(faces_first).replace(faces_first.find("3 2 1 0"), 7, "3 3 1 0"))
                .find("face 0 refers to vertex 3 but there are only 3"),
            std::string::npos);
  EXPECT_EQ(load_mesh(write("white.ply", faces_first + "\n \n")).triangles.size(), 1u);
  EXPECT_NE(error_of("extra.ply", faces_first + "3 0 1 2\n").find("after the last element the header declares"),
            std::string::npos);
  const std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty uchar x\nproperty uchar y\nproperty uchar z\n"
      "element face 1\nproperty list uchar uchar vertex_indices\nend_header\n" +
      std::string("\0\0\0\1\0\0\0\1\0\3\0\1\2", 13);
  EXPECT_EQ(load_mesh(write("binary.ply", binary)).triangles.size(), 1u);
  EXPECT_NE(error_of("binary_extra.ply", binary + "\n").find("1 bytes after the last element"), std::string::npos);
}

}  // namespace
}  // namespace caliber
