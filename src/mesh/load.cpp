// Mesh loading: the reader chosen by the file's extension (caliber's own for OFF, PLY and OBJ,
// assimp's for STL), keeping the file's face order as triangle ids.

#include <cstdio>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <system_error>

#include <assimp/BaseImporter.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "mesh/readers.h"
#include "util/printable.h"

namespace caliber {
namespace {

/// An importer's message as caliber reports it: bytes outside printable ASCII shown as \xNN (a
/// message may quote the file: NULs, control bytes, any encoding), and at most kMessageBytes of it
/// (a parser may quote the rest of a "one-line" file).
std::string bounded(const std::string& message) {
  constexpr std::size_t kMessageBytes = 300;
  std::string out;
  if (append_ascii_escaped(out, message, kMessageBytes) < message.size()) {
    out += "... (" + std::to_string(message.size()) + " bytes in all)";
  }
  return out;
}

void check_file(const std::filesystem::path& path) {
  if (path.empty()) throw Error(ErrorCode::bad_argument, "mesh path", "is empty");
  // Files are opened by C strings, which would end at a NUL byte: another file.
  if (path.native().find('\0') != std::string::npos)
    throw Error(ErrorCode::bad_argument, path.string(), "the path holds a NUL byte");
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) {  // a loop of links, a folder without access
    throw Error(ErrorCode::unreadable, path.string(), "cannot be read (" + ec.message() + ")");
  }
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

/// The meshes of an assimp scene, one after another, as one caliber mesh (faces fanned in place).
Mesh convert(const aiScene& scene_ref, const std::filesystem::path& path) {
  const aiScene* scene = &scene_ref;
  Mesh mesh;
  mesh.source = path.string();
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* in = scene->mMeshes[m];
    if (in == nullptr || (in->mNumVertices > 0 && in->mVertices == nullptr) || (in->mNumFaces > 0 && in->mFaces == nullptr)) {
      throw Error(ErrorCode::unreadable, path.string(), "cannot parse mesh: the importer returned an incomplete mesh");
    }
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < in->mNumVertices; ++v) {
      const aiVector3D& p = in->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw Error(ErrorCode::bad_value, path.string(), "vertex " + std::to_string(base + v) + " has a non-finite coordinate");
      }
      mesh.vertices.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices < 3) {
        throw Error(
            ErrorCode::bad_index, path.string(),
            "face " + std::to_string(f) + " has " + std::to_string(face.mNumIndices) + " corner(s); a face needs at least 3");
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
  return mesh;
}

/// STL through assimp, the importer chosen by the extension and never by sniffing the content: a
/// file is only ever read by the reader its name asks for. STL has no scene graph with transforms,
/// so the meshes' vertices are the object's.
Mesh read_with_assimp(const std::filesystem::path& path, const char* format) {
  std::lock_guard<std::mutex> lock(logger_mutex());
  Assimp::DefaultLogger::create(nullptr, Assimp::Logger::NORMAL, 0);
  auto* errors = new ErrorCollector();  // owned by the logger once attached
  Assimp::DefaultLogger::get()->attachStream(errors, Assimp::Logger::Err);
  struct KillLogger {
    ~KillLogger() { Assimp::DefaultLogger::kill(); }
  } kill_logger;

  Assimp::Importer importer;
  Assimp::BaseImporter* reader = importer.GetImporter(format);
  if (reader == nullptr)
    throw Error(ErrorCode::unreadable, path.string(), std::string("this assimp has no ") + format + " importer");
  // No post-processing: triangulation, vertex joining or sorting by primitive type would change
  // triangle ids. Polygons are fanned below, in place.
  reader->SetupProperties(&importer);
  const std::unique_ptr<aiScene> scene(reader->ReadFile(&importer, path.string(), importer.GetIOHandler()));
  if (scene == nullptr) {
    std::string why = reader->GetErrorText();
    if (why.empty()) why = "unknown error";
    throw Error(ErrorCode::unreadable, path.string(), "cannot parse mesh: " + bounded(why));
  }
  if (!errors->first().empty()) {
    throw Error(ErrorCode::unreadable, path.string(), "cannot parse mesh: " + bounded(strip_log_prefix(errors->first())));
  }
  return convert(*scene, path);
}

}  // namespace

std::string_view supported_mesh_formats() { return ".off, .ply, .obj and .stl"; }

Mesh load_mesh(const std::filesystem::path& path) {
  check_file(path);
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // The extension alone chooses the reader. OFF, PLY and OBJ: caliber's own strict readers
  // (src/mesh/readers.h); assimp crashes, hangs or reads wrong on some files of those formats.
  Mesh mesh;
  if (ext == ".off") {
    mesh = mesh_io::read_off(path);
  } else if (ext == ".ply") {
    mesh = mesh_io::read_ply(path);
  } else if (ext == ".obj") {
    mesh = mesh_io::read_obj(path);
  } else if (ext == ".stl") {
    mesh = read_with_assimp(path, ext.c_str() + 1);
  } else {
    throw Error(ErrorCode::unreadable, path.string(),
                (ext.empty() ? std::string("has no extension")
                             : "extension '" + path.extension().string() + "' is not a mesh format caliber reads") +
                    " (caliber reads " + std::string(supported_mesh_formats()) + " files, chosen by extension)");
  }
  validate_mesh(mesh);
  return mesh;
}

}  // namespace caliber
