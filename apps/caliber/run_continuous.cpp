// caliber run --continuous: each step's motion to the next swept (World::sweep), the pairs that
// touch between steps printed with when, and with --json a report streamed interval by interval.

#include "run_continuous.h"

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/sweep.h"
#include "caliber/world.h"
#include "interrupt.h"
#include "json_output.h"
#include "output_file.h"
#include "progress.h"
#include "timing.h"

namespace caliber::cli {
namespace {

/// One pair's sweep in the report: when it touches (as a share of the step and in seconds from the
/// start), and at a contact the closest triangles and their points (world coordinates).
nlohmann::json pair_record(const World& world, int k, const PairSweep& p) {
  const auto& objects = world.scene().objects;
  const bool contact = p.result.status == SweepStatus::contact;
  nlohmann::json j = {{"a", p.pair.a},
                      {"b", p.pair.b},
                      {"name_a", json_text(objects[p.pair.a].name)},
                      {"name_b", json_text(objects[p.pair.b].name)},
                      {"status", contact ? "contact" : "undecided"},
                      {"time", p.result.time},
                      {"seconds", (k + p.result.time) * world.scene().dt},
                      {"queries", p.result.queries}};
  if (contact) {
    j["tri_a"] = p.result.closest.tri_a;
    j["tri_b"] = p.result.closest.tri_b;
    j["point_a"] = json_vector(p.result.closest.point_a);
    j["point_b"] = json_vector(p.result.closest.point_b);
    j["distance"] = p.result.closest.distance;
  }
  return j;
}

void print_pairs(const World& world, int k, const std::vector<PairSweep>& pairs) {
  const std::vector<SceneObject>& objects = world.scene().objects;
  for (std::size_t i = 0; i < pairs.size() && i <= 20; ++i) {
    if (i == 20) {
      std::printf("  step %d -> %d: and %zu more pairs\n", k, k + 1, pairs.size() - 20);
      break;
    }
    const PairSweep& p = pairs[i];
    const bool contact = p.result.status == SweepStatus::contact;
    std::printf("  step %d -> %d: %s / %s %s t = %.6f s (%.6f of the step)", k, k + 1, objects[p.pair.a].name.c_str(),
                objects[p.pair.b].name.c_str(), contact ? "touch at" : "undecided: free up to",
                (k + p.result.time) * world.scene().dt, p.result.time);
    if (contact) std::printf(", triangles %u and %u", p.result.closest.tri_a, p.result.closest.tri_b);
    std::printf("\n");
  }
}

}  // namespace

int run_continuous(const ContinuousOptions& opt, Engine& engine, Scene scene) {
  SweepRequest request;
  request.tolerance = opt.tolerance;
  validate_sweep_request(request);
  // SIGINT and SIGTERM handled from before the report is opened until it is in place.
  const InterruptGuard interrupt;
  std::unique_ptr<OutputFile> json_out;
  if (!opt.json.empty()) {
    check_distinct_files({{"--json", opt.json}}, scene_inputs(opt.scene_file, scene));
    json_out = std::make_unique<OutputFile>(opt.json, "--json");
  }
  const World world(std::move(scene));
  const Scene& sc = world.scene();
  std::printf("scene %s: %zu objects, %d steps of %g s: sweeping each step's motion to the next, method %s on %d thread(s)\n",
              sc.name.c_str(), world.object_count(), sc.steps, sc.dt, std::string(to_string(engine.options().method)).c_str(),
              engine.threads());
  // Streamed like run's report: the header, each interval as it ends, then the summary.
  std::optional<JsonObjectWriter> report;
  if (json_out) {
    report.emplace(json_out->stream());
    write_scene_header(*report, world, kSchemaVersion);
    report->member("continuous", {{"tolerance", opt.tolerance}, {"max_queries", request.max_queries}});
    report->member("dt", sc.dt);
    report->member("method", std::string(to_string(engine.options().method)));
    report->member("threads", engine.threads());
    report->open_array("intervals");
  }
  const int intervals = std::max(sc.steps - 1, 0);
  const Progress progress(static_cast<std::size_t>(intervals));
  std::size_t touched = 0, undecided = 0;
  int done = 0;
  double first = -1.0;
  for (int k = 0; k < intervals && !interrupted(); ++k, ++done) {
    const auto start = Clock::now();
    const std::vector<PairSweep> pairs = world.sweep(k, engine, request);
    const double ms = ms_since(start);
    nlohmann::json listed = nlohmann::json::array();
    for (const PairSweep& p : pairs) {
      const bool contact = p.result.status == SweepStatus::contact;
      (contact ? touched : undecided) += 1;
      if (contact && (first < 0.0 || k + p.result.time < first)) first = k + p.result.time;
      if (report) listed.push_back(pair_record(world, k, p));
    }
    if (report) report->item({{"step", k}, {"sweep_ms", ms}, {"pairs", std::move(listed)}});
    print_pairs(world, k, pairs);
    std::fflush(stdout);  // the pairs before the progress line (stderr)
    char line[160];
    std::snprintf(line, sizeof line, "step %d -> %d: %zu pairs not free, %.2f ms", k, k + 1, pairs.size(), ms);
    progress.update(static_cast<std::size_t>(k + 1), line);
  }
  progress.end();
  const bool stopped = interrupted();
  if (stopped) {
    std::printf("\ninterrupted (%s) after %d of %d step intervals: writing what was measured\n", interrupt_name(), done,
                intervals);
  }
  std::printf("\nsummary over %d step intervals\n", done);
  std::printf("  pairs that touch    %zu (undecided: %zu)\n", touched, undecided);
  if (first >= 0.0) std::printf("  first contact      at step %.6f (t = %.6f s)\n", first, first * sc.dt);
  if (report) {
    report->close_array();
    nlohmann::json summary = {{"intervals", done}, {"pairs_touching", touched}, {"pairs_undecided", undecided}};
    summary["first_contact_step"] = first >= 0.0 ? nlohmann::json(first) : nlohmann::json(nullptr);
    report->member("summary", summary);
    if (stopped) report->member("interrupted", true);
    report->close();
    json_out->commit();
  }
  check_stdout();
  return stopped ? interrupted_exit_code() : 0;
}

}  // namespace caliber::cli
