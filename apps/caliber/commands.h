#pragma once
// The subcommands of the caliber program. Each registers its options and returns an exit code.

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace caliber::cli {

/// Option checks with plain messages (CLI11's own number checks print their range's limits as
/// 300-digit numbers): a whole number >= 1, and a whole number >= 0.
inline const CLI::Validator kAtLeastOne(
    [](std::string& text) -> std::string {
      long long value = 0;
      return CLI::detail::lexical_cast(text, value) && value >= 1 ? std::string() : "must be a whole number >= 1, not " + text;
    },
    "N >= 1");
inline const CLI::Validator kAtLeastZero(
    [](std::string& text) -> std::string {
      long long value = 0;
      return CLI::detail::lexical_cast(text, value) && value >= 0 ? std::string() : "must be a whole number >= 0, not " + text;
    },
    "N >= 0");

/// A subcommand: registered on the app, then run if it was the one parsed.
using Runner = std::function<int()>;

Runner add_query_command(CLI::App& app);
Runner add_run_command(CLI::App& app);
Runner add_refine_command(CLI::App& app);
Runner add_bench_command(CLI::App& app);
Runner add_view_command(CLI::App& app);

}  // namespace caliber::cli
