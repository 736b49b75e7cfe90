// Fuzz target: the mesh loaders (OFF, OBJ, PLY, STL through assimp), then a BVH build and a
// contact query of the mesh against itself, so that whatever a loader lets through (huge, tiny,
// degenerate coordinates) also goes through the BVH and the exact predicates.
// Input: first byte picks the file's extension (the format, or one caliber refuses), the rest is
// the file's content.

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"
#include "fuzz_target.h"

namespace {

const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path shm = "/dev/shm";
    auto d = (std::filesystem::exists(shm) ? shm : std::filesystem::temp_directory_path()) /
             ("caliber-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  // The four formats, the same in capitals, and names caliber must refuse whatever they hold (no
  // extension, formats assimp knows but caliber does not read).
  static const char* const kExtensions[] = {".off", ".obj", ".ply", ".stl", "",     ".ase",
                                            ".dae", ".OFF", ".PLY", ".nff", ".raw", ".smd"};
  const std::filesystem::path path = scratch_dir() / (std::string("input") + kExtensions[data[0] % 12]);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const caliber::Mesh mesh = caliber::load_mesh(path);
    if (mesh.triangles.size() > 5000) return 0;  // keep each run short; big meshes are tested elsewhere
    const auto model = caliber::build_model(mesh);
    const caliber::Pose shifted = caliber::Pose::from_values(0.01, 0.02, -0.01, 1, 0.01, 0, 0);
    const caliber::QueryRequest request{caliber::QueryKind::contact, 0.01, 30.0, nullptr};
    (void)caliber::query(*model, caliber::Pose{}, *model, shifted, request);
  } catch (const caliber::Error&) {
    // the documented answer to bad input
  }
  return 0;
}
