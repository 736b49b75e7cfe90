// Model memory and build time: for each mesh, the bytes a built model holds a triangle
// (Model::memory_bytes: mesh, normals, BVH, wide tree, adjacency) and the median build time on
// one thread over R builds (the upper of the two middle ones for an even R): build_model's whole
// call, the mesh's copy into the model included. Public API only, so the same source measures
// any version. Mesh files given replace the default five (--meshes names where those lie).
//   bench_model_memory [--meshes DIR] [--builds R] [MESH...]   (default: the five Embree pairs' meshes)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/model.h"

namespace {

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_model_memory: %s\n", message.c_str());
  std::exit(2);
}

struct Options {
  std::string meshes = CALIBER_BENCH_MESHES;
  int builds = 7;
  std::vector<std::string> files;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--meshes" || arg == "--builds") {
      if (i + 1 >= argc) fail(arg + " needs a value");
      const std::string value = argv[++i];
      if (arg == "--meshes") {
        o.meshes = value;
        continue;
      }
      char* end = nullptr;
      const long r = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || *end != '\0' || r < 1 || r > 1000) fail("--builds needs an integer in 1..1000, got " + value);
      o.builds = static_cast<int>(r);
    } else if (!arg.empty() && arg[0] == '-') {
      fail("unknown option " + arg + " (options: --meshes DIR --builds R, then mesh files)");
    } else {
      o.files.push_back(arg);
    }
  }
  if (o.files.empty()) {
    for (const char* name : {"bunny00.off", "armadillo.off", "refined_elephant.off", "turbine.off", "blade.off"})
      o.files.push_back(o.meshes + "/" + name);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::printf("| mesh | triangles | bytes a triangle | build ms, 1 thread (median of %d) |\n|---|---|---|---|\n", o.builds);
  for (const std::string& file : o.files) {
    try {
      const caliber::Mesh mesh = caliber::load_mesh(file);
      caliber::BuildOptions options;
      options.threads = 1;
      std::vector<double> ms;
      double bytes = 0.0;
      for (int r = 0; r < o.builds; ++r) {
        const auto start = std::chrono::steady_clock::now();
        const auto model = caliber::build_model(mesh, options);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        bytes = static_cast<double>(model->memory_bytes()) / static_cast<double>(model->triangle_count());
      }
      std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
      const std::string name = file.substr(file.find_last_of('/') + 1);
      std::printf("| %s | %zu | %.1f | %.1f |\n", name.c_str(), mesh.triangles.size(), bytes, ms[ms.size() / 2]);
    } catch (const std::exception& e) {
      const std::string what = e.what();  // (caliber's errors name the file already)
      fail(what.find(file) != std::string::npos ? what : file + ": " + what);
    }
  }
  return 0;
}
