#pragma once
// The subcommands of the caliber program: query, run, refine and view. Each registers its options
// and returns a Runner.

#include <string>
#include <string_view>
#include <utility>

#include <CLI/CLI.hpp>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "options.h"

namespace caliber::cli {

/// The method --method names (caliber::parse_method), a bad name refused as "--method: ...".
inline Method method_option(const std::string& name) {
  try {
    return parse_method(name);
  } catch (const Error& e) {
    const std::string_view what = e.what();
    const std::string_view prefix = "method: ";
    throw Error(e.code(), "--method", std::string(what.substr(what.rfind(prefix, 0) == 0 ? prefix.size() : 0)));
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
    const std::string_view what = e.what();
    for (const auto& [library, option] : kNames) {
      if (e.source() == library && what.size() > library.size() + 2) {
        throw Error(e.code(), std::string(option), std::string(what.substr(library.size() + 2)));
      }
    }
    throw;
  }
}

Runner add_query_command(CLI::App& app);
Runner add_run_command(CLI::App& app);
Runner add_refine_command(CLI::App& app);
Runner add_view_command(CLI::App& app);

}  // namespace caliber::cli
