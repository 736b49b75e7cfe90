// Mesh loading through assimp, keeping the file's face order as triangle ids.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <mutex>
#include <string>
#include <system_error>

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "mesh/readers.h"

namespace caliber {
namespace {

void check_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    throw Error(ErrorCode::file_not_found, path.string(), "no such file");
  }
  if (std::filesystem::is_directory(status)) {
    throw Error(ErrorCode::unreadable, path.string(), "is a directory, not a mesh file");
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw Error(ErrorCode::unreadable, path.string(), "is not a regular file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::unreadable, path.string(), "cannot be opened for reading");
  if (in.peek() == std::ifstream::traits_type::eof()) {
    throw Error(ErrorCode::unreadable, path.string(), "file is empty");
  }
}

/// Collects the errors assimp logs. Some importers only log a problem and go on (the OFF importer
/// clamps an out-of-range vertex index to the last vertex): any logged error fails the load.
class ErrorCollector : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    if (mFirst.empty()) mFirst = message;
    while (!mFirst.empty() && (mFirst.back() == '\n' || mFirst.back() == '\r')) mFirst.pop_back();
  }
  [[nodiscard]] const std::string& first() const { return mFirst; }

 private:
  std::string mFirst;
};

/// assimp's logger is process-wide: loads are serialized so each collects its own errors.
std::mutex& logger_mutex() {
  static std::mutex mutex;
  return mutex;
}

/// Strips assimp's "Error, T0: " style prefix from a logged message.
std::string strip_log_prefix(const std::string& message) {
  const auto colon = message.find(": ");
  return (message.rfind("Error", 0) == 0 && colon != std::string::npos) ? message.substr(colon + 2) : message;
}

}  // namespace

Mesh load_mesh(const std::filesystem::path& path) {
  check_file(path);
  {
    std::ifstream in(path, std::ios::binary);
    std::string head(64, '\0');
    in.read(head.data(), 64);
    head.resize(static_cast<std::size_t>(in.gcount()));
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    // PLY and OFF: caliber's own readers (src/mesh/readers.h); assimp crashes or hangs on some bad
    // files of both formats. Everything else goes to assimp.
    if (mesh_io::looks_like_ply(head) || mesh_io::looks_like_off(head) || ext == ".ply" || ext == ".off") {
      Mesh mesh = (mesh_io::looks_like_ply(head) || (ext == ".ply" && !mesh_io::looks_like_off(head))) ? mesh_io::read_ply(path)
                                                                                                      : mesh_io::read_off(path);
      validate_mesh(mesh);
      return mesh;
    }
  }
  std::lock_guard<std::mutex> lock(logger_mutex());
  Assimp::DefaultLogger::create(nullptr, Assimp::Logger::NORMAL, 0);
  auto* errors = new ErrorCollector();  // owned by the logger once attached
  Assimp::DefaultLogger::get()->attachStream(errors, Assimp::Logger::Err);
  struct KillLogger {
    ~KillLogger() { Assimp::DefaultLogger::kill(); }
  } kill_logger;

  Assimp::Importer importer;
  // No post-processing: triangulation, vertex joining or sorting by primitive type would change
  // triangle ids. Polygons are fanned below, in place.
  const aiScene* scene = importer.ReadFile(path.string(), 0);
  if (scene == nullptr) {
    std::string why = importer.GetErrorString();
    if (why.empty()) why = "unknown error";
    throw Error(ErrorCode::unreadable, path.string(), "cannot parse mesh: " + why);
  }
  if (!errors->first().empty()) {
    throw Error(ErrorCode::unreadable, path.string(), "cannot parse mesh: " + strip_log_prefix(errors->first()));
  }
  Mesh mesh;
  mesh.source = path.string();
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* in = scene->mMeshes[m];
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < in->mNumVertices; ++v) {
      const aiVector3D& p = in->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw Error(ErrorCode::bad_value, path.string(),
                    "vertex " + std::to_string(base + v) + " has a non-finite coordinate");
      }
      mesh.vertices.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices < 3) {
        throw Error(ErrorCode::bad_index, path.string(),
                    "face " + std::to_string(f) + " has " + std::to_string(face.mNumIndices) +
                        " corner(s); a face needs at least 3");
      }
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= in->mNumVertices) {
          throw Error(ErrorCode::bad_index, path.string(),
                      "face " + std::to_string(f) + " refers to vertex " + std::to_string(face.mIndices[k]) +
                          " but there are only " + std::to_string(in->mNumVertices));
        }
      }
      for (unsigned k = 1; k + 1 < face.mNumIndices; ++k) {
        mesh.triangles.push_back({base + face.mIndices[0], base + face.mIndices[k], base + face.mIndices[k + 1]});
      }
    }
  }
  validate_mesh(mesh);
  return mesh;
}

}  // namespace caliber
