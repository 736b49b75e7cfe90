#pragma once
// report.md of `caliber-bench`, from the run's results.json.

#include <filesystem>

#include <nlohmann/json.hpp>

namespace caliber::cli {

/// Writes the Markdown report (tables, measured figures, peer comparison, figure links) of a bench run.
/// Throws caliber::Error if the file cannot be written.
void write_bench_report(const nlohmann::json& results, const std::filesystem::path& file);

}  // namespace caliber::cli
