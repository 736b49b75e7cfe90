#pragma once
// The figures of a `caliber-bench` run, drawn as SVG from the same results that write report.md:
//   speedup_<scene>.svg  speed-up against threads per method: measured thread counts solid, the
//                        load-balance simulation dashed, the linear limit dotted (log2 axes);
//   correlation.svg      estimated against effective node tests per run-time task, with Pearson's
//                        r, for the calibrated methods (log axes);
//   gantt.svg            one step's timeline per thread, one panel per method (stage, depth-first,
//                        finalization).

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace caliber::cli {

/// Writes the figures of `results` (results.json's content) into the folder `out`, each file
/// whole or not at all: a speed-up figure per scene, correlation.svg when a calibrated method has
/// correlation points, gantt.svg when the results hold a timeline. Returns the names of the files
/// written. The same results always give the same bytes. Throws caliber::Error naming a file that
/// cannot be written.
std::vector<std::string> write_bench_figures(const nlohmann::json& results, const std::filesystem::path& out);

/// The names of every figure a run with these scenes may write, for the outputs' checks.
[[nodiscard]] std::vector<std::string> bench_figure_names(const std::vector<std::string>& scene_names);

}  // namespace caliber::cli
