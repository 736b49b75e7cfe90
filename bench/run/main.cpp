// caliber-bench: the benchmark of the six methods as a program of its own (the same as
// `caliber bench`, which the caliber program keeps as a thin entry to this code).
// Exit codes: 0 success, 2 bad input (message on stderr), 130 and 143 stopped by SIGINT or SIGTERM
// (what was measured is reported), 1 unexpected internal error or contacts that differ.

#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "caliber/error.h"
#include "commands.h"

int main(int argc, char** argv) {
  CLI::App app{"caliber-bench: every method on every scene, medians, report.md and results.json"};
  app.require_subcommand(1);
  const caliber::cli::Runner bench = caliber::cli::add_bench_command(app);
  // `caliber-bench bench ...` reads oddly: the options go straight after the program's name.
  std::vector<std::string> args{argv[0], "bench"};
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> argp;
  for (std::string& a : args) argp.push_back(a.data());
  try {
    app.parse(static_cast<int>(argp.size()), argp.data());
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "caliber-bench: " << e.what() << "\n";
    return 2;
  }
  try {
    return bench();
  } catch (const caliber::Error& e) {
    std::cerr << "caliber-bench: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "caliber-bench: out of memory (the input needs more memory than this machine or its limits give)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "caliber-bench: internal error: " << e.what() << "\n";
    return 1;
  }
}
