#pragma once
// What the sections of caliber-bench's report.md read from results.json (bench_report.cpp), and
// its table of key figures (report_key_figures.cpp).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace caliber::cli::report {

using Json = nlohmann::json;

/// A number as the report prints it.
inline std::string num(double x, const char* format = "%.2f") {
  char b[64];
  std::snprintf(b, sizeof b, format, x);
  return b;
}

/// Step time (ms) of a method at t threads in a scene, or NaN if not measured.
inline double step_ms(const Json& scene, const std::string& method, int t) {
  const Json& m = scene["methods"];
  if (!m.contains(method) || !m[method]["threads"].contains(std::to_string(t))) return std::nan("");
  return m[method]["threads"][std::to_string(t)]["step_ms"].get<double>();
}

/// A phase's time (ms per step) of a method at t threads in a scene, or NaN if not measured.
inline double phase_ms(const Json& scene, const std::string& method, int t, const char* phase) {
  const Json& m = scene["methods"];
  if (!m.contains(method) || !m[method]["threads"].contains(std::to_string(t))) return std::nan("");
  const Json& p = m[method]["threads"][std::to_string(t)]["phases_per_step"];
  return p.contains(phase) ? p[phase].get<double>() : std::nan("");
}

/// The methods a scene ran, in the paper's order.
inline std::vector<std::string> method_names(const Json& scene) {
  std::vector<std::string> names;
  for (const auto& [name, value] : scene["methods"].items()) names.push_back(name);
  // Keep the paper's order: sequential, exploitation, stealing, aposteriori, apriori, hybrid(+history).
  const std::vector<std::string> order = {"sequential", "exploitation", "stealing",      "aposteriori",
                                          "apriori",    "hybrid",       "hybrid+history"};
  std::vector<std::string> sorted;
  for (const std::string& o : order) {
    if (std::find(names.begin(), names.end(), o) != names.end()) sorted.push_back(o);
  }
  return sorted;
}

/// The run's key figures, per scene, in one table (each also in the report's other sections).
void write_key_figures(std::ostream& out, const Json& r);

}  // namespace caliber::cli::report
