// caliber refine: 1-to-4 midpoint subdivision of a mesh, written as OFF.

#include <cstdio>
#include <memory>
#include <string>

#include "caliber/mesh.h"
#include "commands.h"

namespace caliber::cli {

Runner add_refine_command(CLI::App& app) {
  struct Options {
    std::string in, out;
    int levels = 1;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("refine", "Subdivide every triangle into 4, K times, and write an OFF file");
  cmd->add_option("IN", opt->in, "Input mesh (OFF, OBJ, STL or PLY)")->required();
  cmd->add_option("OUT", opt->out, "Output OFF file")->required();
  cmd->add_option("--levels,-l", opt->levels, "Subdivision levels (each multiplies the triangles by 4)")
      ->capture_default_str()
      ->check(CLI::Range(0, 8));
  return [cmd, opt]() {
    if (!cmd->parsed()) return -1;
    const Mesh in = load_mesh(opt->in);
    const Mesh out = refine_mesh(in, opt->levels);
    save_off(out, opt->out);
    std::printf("%s: %zu triangles -> %s: %zu triangles\n", opt->in.c_str(), in.triangles.size(), opt->out.c_str(),
                out.triangles.size());
    return 0;
  };
}

}  // namespace caliber::cli
