#pragma once
// What the programs' command lines share: an option check with a plain message, and a command
// registered on an app and run if it was the one given.

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace caliber::cli {

/// An option check with a plain message (CLI11's own number checks print their range's limits as
/// 300-digit numbers): a whole number >= `least`.
inline CLI::Validator at_least(long long least) {
  return CLI::Validator(
      [least](std::string& text) -> std::string {
        long long value = 0;
        return CLI::detail::lexical_cast(text, value) && value >= least
                   ? std::string()
                   : "must be a whole number >= " + std::to_string(least) + ", not " + text;
      },
      "N >= " + std::to_string(least));
}

/// A subcommand: registered on the app, then run if it was the one parsed.
using Runner = std::function<int()>;

}  // namespace caliber::cli
