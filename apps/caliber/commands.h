#pragma once
// The subcommands of the caliber program: query, run, refine and view. Each registers its options
// and returns a Runner.

#include <CLI/CLI.hpp>

#include "options.h"

namespace caliber::cli {

Runner add_query_command(CLI::App& app);
Runner add_run_command(CLI::App& app);
Runner add_refine_command(CLI::App& app);
Runner add_view_command(CLI::App& app);

}  // namespace caliber::cli
