// Fuzz target: caliber's OBJ reader (src/mesh/obj.cpp) alone. The input is the file's content.
// Whatever it holds, the reader answers with a mesh or a caliber::Error; a mesh it returns must
// hold what caliber::validate_mesh accepts (every index in range, coordinates finite), and its
// message must be one line.

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path path = [] {
    const std::filesystem::path shm = "/dev/shm";
    const auto dir = std::filesystem::exists(shm) ? shm : std::filesystem::temp_directory_path();
    return dir / ("caliber-obj-fuzz-" + std::to_string(::getpid()) + ".obj");
  }();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const caliber::Mesh mesh = caliber::load_mesh(path);
    for (const auto& t : mesh.triangles) {
      for (const std::uint32_t v : t) {
        if (v >= mesh.vertices.size()) __builtin_trap();  // load_mesh let an index out of range through
      }
    }
  } catch (const caliber::Error& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) __builtin_trap();  // a message of more than one line
  }
  return 0;
}
