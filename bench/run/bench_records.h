#pragma once
// The JSON-lines log of `caliber-bench`: one record per line, written and flushed the moment it is
// measured, so that a run cut short (a time limit, a lost machine) keeps every finished
// configuration; and results.json rebuilt from such a log, whole or partial.
//
// Records (each a JSON object with a "kind"):
//   header      machine, cpu, hardware_threads, compiler, repeat, threads, simulate, simulate_steps,
//               methods (in order), scenes [{name, file, steps}], runs_planned, budget_s
//   run         scene, method, threads, round, total_ms (all steps), phases {broad_ms, calibrate_ms,
//               traverse_ms, finalize_ms (per step), balance_speedup}
//   table1      scene, and the paper's Table 1 fields (objects, triangles, node_tests_per_step, ...)
//   ceiling     scene, copies P, copy_step_ms [one per copy]: P independent sequential copies at once
//   simulation  scene, method, cores, speedup (by node tests), and (optional) predicted_step_ms (by
//               measured time per piece) with sequential_step_ms (a sequential run of the same steps),
//               and (optional) correlation {cores, pearson, tasks, points}
//   mismatch    scene, method, threads, step: contacts that differ from sequential's
//   gantt       the per-thread timeline of one step (see bench_command.cpp)
//   fcl         report: the FCL comparison's Markdown
//   stopped     reason, after_s, next: the run ended early, reason "budget" (--budget-s) or
//               "interrupted" (with signal: "SIGINT" or "SIGTERM"), before `next`

#include <filesystem>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>

namespace caliber::cli {

/// Appends records to a JSON-lines file (truncated when opened), one line each, flushed at once.
class BenchLog {
 public:
  /// Opens (and truncates) the file. Throws caliber::Error naming it if it cannot be written.
  explicit BenchLog(std::filesystem::path file);
  /// Writes one record as a line and flushes it; keeps it in memory too.
  void add(nlohmann::json record);
  /// Every record added so far, in order.
  [[nodiscard]] const std::vector<nlohmann::json>& records() const { return mRecords; }
  /// The file.
  [[nodiscard]] const std::filesystem::path& file() const { return mFile; }

 private:
  std::filesystem::path mFile;
  std::ofstream mOut;
  std::vector<nlohmann::json> mRecords;
};

/// Reads a bench log. A last line cut in the middle (the run was killed while writing it) is
/// dropped; any other line that is not a JSON object with a "kind", or a log without a header,
/// throws caliber::Error naming the file and the line.
[[nodiscard]] std::vector<nlohmann::json> read_bench_log(const std::filesystem::path& file);

/// results.json of a bench from its records: per scene, Table 1, every method's median step time
/// per thread count (with its runs and the phases of its median run), the simulation, the
/// correlation, the machine's ceiling; the timeline, the FCL report, whether the contacts were
/// identical, and how far the run got. A scene appears once its sequential reference has run; a
/// method once one of its runs has.
[[nodiscard]] nlohmann::json results_from_records(const std::vector<nlohmann::json>& records);

}  // namespace caliber::cli
