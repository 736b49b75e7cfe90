#pragma once
// The subcommands of the caliber program. Each registers its options and returns an exit code.

#include <functional>

#include <CLI/CLI.hpp>

namespace caliber::cli {

/// A subcommand: registered on the app, then run if it was the one parsed.
using Runner = std::function<int()>;

Runner add_query_command(CLI::App& app);
Runner add_run_command(CLI::App& app);
Runner add_refine_command(CLI::App& app);
Runner add_bench_command(CLI::App& app);
Runner add_view_command(CLI::App& app);

}  // namespace caliber::cli
