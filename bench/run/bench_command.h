#pragma once
// caliber-bench's options and run: every scene x method x thread count, the paper's tables and
// figures, measured (bench_command.cpp).

#include <CLI/CLI.hpp>

#include "options.h"

namespace caliber::cli {

/// Registers the bench's options on `app` (the program's own, not a subcommand); the Runner runs
/// the bench with them once parsed.
Runner add_bench_options(CLI::App& app);

}  // namespace caliber::cli
