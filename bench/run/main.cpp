// caliber-bench: the benchmark of the six methods (bench_command.cpp), a program of its own beside
// the caliber program.
// Exit codes: 0 success, 2 bad input (message on stderr), 130 and 143 stopped by SIGINT or SIGTERM
// (what was measured is reported), 1 unexpected internal error or contacts that differ.

#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "bench_command.h"
#include "caliber/error.h"
#include "interrupt.h"

int main(int argc, char** argv) {
  CLI::App app{"caliber-bench: every scene x method x thread count: the paper's tables and figures, measured"};
  const caliber::cli::Runner bench = caliber::cli::add_bench_options(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "caliber-bench: " << e.what() << "\n";
    return 2;
  }
  try {
    return bench();
  } catch (const caliber::cli::Stopped& e) {  // a signal before any work (a pipe without a reader)
    std::cerr << "caliber-bench: " << e.what() << "\n";
    return caliber::cli::interrupted_exit_code();
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
