// caliber refine: 1-to-4 midpoint subdivision of a mesh, written as OFF.

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <new>
#include <string>

#include "caliber/mesh.h"
#include "caliber/error.h"
#include "commands.h"
#include "interrupt.h"
#include "output_file.h"

namespace caliber::cli {

Runner add_refine_command(CLI::App& app) {
  struct Options {
    std::string in, out;
    int levels = 1;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("refine", "Subdivide every triangle into 4, K times, and write an OFF file");
  cmd->add_option("IN", opt->in, "Input mesh (OFF, OBJ, STL or PLY)")->required();
  cmd->add_option("OUT", opt->out, "Output OFF file (its name ends in .off)")->required();
  cmd->add_option("--levels,-l", opt->levels, "Subdivision levels (each multiplies the triangles by 4)")
      ->capture_default_str()
      ->check(CLI::Range(0, 8));
  return [cmd, opt]() {
    if (!cmd->parsed()) return -1;
    std::string ext = std::filesystem::path(opt->out).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".off") throw Error(ErrorCode::bad_argument, "OUT", "must name an .off file: refine writes OFF");
    check_distinct_files({{"OUT", opt->out}}, {{"IN", opt->in}});
    const InterruptGuard interrupt;  // from before OUT's temporary file is made until it is in place or removed
    OutputFile file(opt->out, "OUT");
    const Mesh in = load_mesh(opt->in);
    Mesh out;
    try {
      out = refine_mesh(in, opt->levels);
    } catch (const std::bad_alloc&) {
      throw Error(ErrorCode::out_of_memory, opt->in, "out of memory while refining it " + std::to_string(opt->levels) + " times");
    }
    write_off(out, file.stream());
    if (interrupted()) {  // one step only: nothing partial to keep, and the temporary file is removed
      std::printf("interrupted (%s): %s not written\n", interrupt_name(), opt->out.c_str());
      return interrupted_exit_code();
    }
    file.commit();
    std::printf("%s: %zu triangles -> %s: %zu triangles\n", opt->in.c_str(), in.triangles.size(), opt->out.c_str(),
                out.triangles.size());
    check_stdout();
    return 0;
  };
}

}  // namespace caliber::cli
