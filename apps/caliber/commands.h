#pragma once
// The subcommands of the caliber program: query, run, refine and view. Each registers its options
// and returns a Runner.

#include <string>
#include <string_view>
#include <utility>

#include <CLI/CLI.hpp>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/scene.h"
#include "options.h"

namespace caliber::cli {

/// Error e of the library (its source a name of the library's, "threads") as the command line's
/// option `option` ("--threads"): the same code and problem.
inline Error renamed(const Error& e, std::string option) {
  std::string_view problem = e.what();
  const std::string prefix = e.source() + ": ";
  if (problem.rfind(prefix, 0) == 0) problem.remove_prefix(prefix.size());
  return Error(e.code(), std::move(option), std::string(problem));
}

/// The method --method names (caliber::parse_method), a bad name refused as "--method: ...".
inline Method method_option(const std::string& name) {
  try {
    return parse_method(name);
  } catch (const Error& e) {
    throw renamed(e, "--method");
  }
}

/// make() (an engine made from options), an option the engine refuses named as the command line
/// spells it (--threads, not the library's "threads").
template <class Make>
auto engine_from_options(Make&& make) -> decltype(make()) {
  try {
    return make();
  } catch (const Error& e) {
    static constexpr std::pair<std::string_view, std::string_view> kNames[] = {
        {"threads", "--threads"}, {"stealing depth", "--stealing-depth"}, {"beta", "--beta"}, {"epsilon", "--epsilon"}};
    for (const auto& [library, option] : kNames) {
      if (e.source() == library) throw renamed(e, std::string(option));
    }
    throw;
  }
}

/// --steps of run and view: -1 (the scene's steps, the default) or 1 .. kMaxSceneSteps.
inline void check_steps_option(int steps) {
  if (steps == 0 || steps < -1) throw Error(ErrorCode::bad_value, "--steps", "must be a positive number of steps");
  if (steps > kMaxSceneSteps) throw Error(ErrorCode::bad_value, "--steps", "must be at most 100000000, as in a scene file");
}

Runner add_query_command(CLI::App& app);
Runner add_run_command(CLI::App& app);
Runner add_refine_command(CLI::App& app);
Runner add_view_command(CLI::App& app);

}  // namespace caliber::cli
