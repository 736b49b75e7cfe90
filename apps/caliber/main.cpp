// caliber: command-line front-end of the library.
//   caliber query A B [...]      two meshes, one query
//   caliber run SCENE [...]      a scene over its time steps
//   caliber refine IN OUT -l K   1-to-4 subdivision
//   caliber view SCENE --out F   an HTML page showing the scene's steps, contacts and tasks
// Exit codes: 0 success, 2 bad input or not enough memory for it (message on stderr), 130 and 143
// a long command (run, view, refine) stopped by SIGINT or SIGTERM (what it measured is
// written, and no temporary file is left), 1 unexpected internal error.

#include <iostream>
#include <string>
#include <new>
#include <vector>

#include <CLI/CLI.hpp>

#include "caliber/error.h"
#include "caliber/version.h"
#include "commands.h"
#include "interrupt.h"

int main(int argc, char** argv) {
  CLI::App app{"caliber: exact collision detection between rigid triangle meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("caliber ") + caliber::kVersion);
  const std::vector<caliber::cli::Runner> commands = {caliber::cli::add_query_command(app), caliber::cli::add_run_command(app),
                                                      caliber::cli::add_refine_command(app), caliber::cli::add_view_command(app)};
  // An empty value is refused, not read as 0 or as no output file ("--tolerance ''", "--json ''").
  const CLI::Validator non_empty(
      [](std::string& value) { return value.empty() ? std::string("must not be empty") : std::string(); }, "", "NONEMPTY");
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) {
    for (CLI::Option* option : command->get_options([](CLI::Option*) { return true; })) {
      if (option->get_type_size() != 0 && !option->get_positional()) option->check(non_empty);
      if (option->get_type_size() != 0) caliber::cli::check_number_syntax(*option);
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "caliber: " << e.what() << "\n";
    return 2;
  }
  try {
    for (const auto& command : commands) {
      const int rc = command();
      if (rc >= 0) return rc;
    }
  } catch (const caliber::cli::Stopped& e) {
    std::cerr << "caliber: " << e.what() << "\n";
    return caliber::cli::interrupted_exit_code();
  } catch (const caliber::Error& e) {
    std::cerr << "caliber: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "caliber: out of memory (the input needs more memory than this machine or its limits give)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "caliber: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
