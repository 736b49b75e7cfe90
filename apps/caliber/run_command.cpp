// caliber run: a scene over its time steps, with a per-step summary, a final summary (the paper's
// Table 1 characteristics), an optional JSON report and an optional JSON-lines contact log.

#include <cstdio>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "caliber/engine.h"
#include "caliber/profile.h"
#include "caliber/error.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "commands.h"
#include "export_files.h"
#include "interrupt.h"
#include "json_output.h"
#include "output_file.h"
#include "progress.h"
#include "run_continuous.h"
#include "run_options.h"
#include "run_stats.h"
#include "timing.h"

namespace caliber::cli {
namespace {

nlohmann::json step_record(const StepResult& s) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const PairRecord& p : s.pair_records) {
    pairs.push_back({{"a", p.pair.a},
                     {"b", p.pair.b},
                     {"node_tests", p.stats.node_tests},
                     {"leaf_tests", p.stats.leaf_tests},
                     {"contacts", p.contacts},
                     {"limit_reached", p.limit_reached}});
  }
  const ScheduleRecord& c = *s.schedule;
  nlohmann::json schedule = {{"omega", c.omega},
                             {"kept", c.kept},
                             {"split", c.split},
                             {"carted", c.carted},
                             {"generated", c.generated},
                             {"stage_node_tests", c.stage_node_tests},
                             {"stage_pair_node_tests", c.stage_pair_node_tests},
                             {"split_node_tests", c.split_node_tests},
                             {"queue_peak", c.queue_peak},
                             {"task_node_tests", c.task_node_tests},
                             {"thread_node_tests", c.thread_node_tests},
                             {"taboo", c.taboo},
                             {"taboo_unreached_node_tests", c.taboo_unreached_node_tests},
                             {"calibrate_ms", c.calibrate_ms},
                             {"traverse_ms", c.traverse_ms},
                             {"finalize_ms", c.finalize_ms},
                             {"task_weights", c.task_weights}};
  return {{"step", s.step},
          {"time", s.time},
          {"schedule", schedule},
          {"broad_ms", s.broad_ms},
          {"narrow_ms", s.narrow_ms},
          {"reduce_ms", s.reduce_ms},
          {"step_ms", s.broad_ms + s.narrow_ms + s.reduce_ms},
          {"node_tests", s.stats.node_tests},
          {"leaf_tests", s.stats.leaf_tests},
          {"contacts", s.contacts.size()},
          {"limit_reached", s.limit_reached},
          {"pairs", pairs}};
}

nlohmann::json contacts_line(const World& world, const StepResult& s) {
  nlohmann::json list = nlohmann::json::array();
  const bool points = world.request().kind != QueryKind::interference;
  for (const Contact& c : s.contacts) {
    nlohmann::json j = {{"object_a", c.object_a},
                        {"object_b", c.object_b},
                        {"name_a", json_text(world.scene().objects[c.object_a].name)},
                        {"name_b", json_text(world.scene().objects[c.object_b].name)},
                        {"tri_a", c.tri_a},
                        {"tri_b", c.tri_b}};
    if (points) {
      j["point_a"] = json_vector(c.point_a);
      j["point_b"] = json_vector(c.point_b);
      j["normal"] = json_vector(c.normal);
      j["distance"] = c.distance;
      j["depth"] = c.depth;
    }
    list.push_back(std::move(j));
  }
  return {{"schema_version", kSchemaVersion}, {"step", s.step}, {"limit_reached", s.limit_reached}, {"contacts", list}};
}

std::string pair_name(const World& world, const ObjectPair& t) {
  return world.scene().objects[t.a].name + " / " + world.scene().objects[t.b].name;
}

/// The steps to run: the scene's, or --steps (checked by check_run_options).
int steps_of(const RunOptions& opt, int scene_steps) { return opt.steps > 0 ? opt.steps : scene_steps; }

/// The engine the options ask for (its options checked by its constructor, before the scene is
/// read or any output made). The steps' report says how the work was cut; the sweeps' has no use
/// for it.
Engine engine_of(const RunOptions& opt) {
  EngineOptions engine_options;
  engine_options.method = method_option(opt.method);
  engine_options.profile = !opt.continuous;
  engine_options.threads = opt.threads;
  engine_options.stealing_depth = opt.stealing_depth;
  engine_options.beta = opt.beta;
  engine_options.epsilon = opt.epsilon;
  engine_options.node_history = opt.node_history;
  return engine_from_options([&] { return Engine(engine_options); });
}

/// Where a run writes: the JSON report (streamed: what is known first, then each step as it ends,
/// then the summary, so its memory does not grow with the steps and a failure leaves only the
/// temporary file, removed), the contacts' lines and the PLY exports; each optional.
struct RunSinks {
  std::unique_ptr<OutputFile> json_out, contacts_out;
  std::unique_ptr<Exporter> exporter;
  std::optional<JsonObjectWriter> report;

  /// Every output checked, and kept apart from every input, before any work is done.
  RunSinks(const RunOptions& opt, const Scene& scene) {
    NamedFiles outputs{{"--json", opt.json}, {"--contacts", opt.contacts}};
    for (const std::string& path : export_paths(opt.exports)) outputs.emplace_back("--export", path);
    check_distinct_files(outputs, scene_inputs(opt.scene, scene));
    if (!opt.exports.dir.empty()) exporter = std::make_unique<Exporter>(opt.exports, scene.steps);
    if (!opt.json.empty()) json_out = std::make_unique<OutputFile>(opt.json, "--json");
    if (!opt.contacts.empty()) contacts_out = std::make_unique<OutputFile>(opt.contacts, "--contacts");
  }

  /// The report's header: the scene, its query and the engine.
  void open_report(const World& world, const Engine& engine) {
    if (!json_out) return;
    const Scene& sc = world.scene();
    report.emplace(json_out->stream());
    write_scene_header(*report, world, kReportSchemaVersion);
    report->member(
        "query",
        {{"kind", std::string(to_string(sc.query.kind))}, {"tolerance", sc.query.tolerance}, {"angle", sc.query.angle_deg}});
    report->member("dt", sc.dt);
    report->member("method", std::string(to_string(engine.options().method)));
    report->member("threads", engine.threads());
    report->open_array("steps");
  }

  /// What step k writes.
  void write_step(const World& world, const StepResult& s, int k) {
    if (report) report->item(step_record(s));
    if (contacts_out) contacts_out->stream() << contacts_line(world, s).dump() << '\n';
    if (exporter && exporter->wants(k)) exporter->write(world, s);
  }
};

/// The steps, until the scene's last or an interrupt: each one measured, simulated and written.
std::size_t run_steps(const World& world, Engine& engine, RunSinks& sinks, RunStats& stats, std::vector<SimulatedRun>& sims) {
  const Scene& sc = world.scene();
  const Progress progress(static_cast<std::size_t>(sc.steps));
  std::size_t limited_steps = 0;
  for (int k = 0; k < sc.steps && !interrupted(); ++k) {
    StepResult s;
    try {
      s = step(world, engine, k);
    } catch (const std::bad_alloc&) {
      throw Error(ErrorCode::out_of_memory, sc.file.string(), "out of memory while running step " + std::to_string(k));
    }
    stats.add(s);
    limited_steps += s.limit_reached ? 1 : 0;
    for (SimulatedRun& sim : sims) sim.add(s);
    sinks.write_step(world, s, k);
    char line[256];
    std::snprintf(line, sizeof line, "step %d: %zu pairs, %llu node tests, %zu contacts, %.2f ms", k, s.pair_records.size(),
                  static_cast<unsigned long long>(s.stats.node_tests), s.contacts.size(), s.broad_ms + s.narrow_ms + s.reduce_ms);
    progress.update(static_cast<std::size_t>(k + 1), line);
  }
  progress.end();
  return limited_steps;
}

/// The summary printed at the end; returns the simulated speed-ups by core count.
nlohmann::json print_summary(const RunOptions& opt, const World& world, const Engine& engine, const RunStats& stats,
                             const std::vector<SimulatedRun>& sims) {
  const auto [heavy, heavy_share] = stats.heaviest_pair();
  const auto [second, second_share] = stats.second_heaviest_pair();
  std::printf("\nsummary over %zu steps\n", stats.steps());
  std::printf("  step time          median %.2f ms, mean %.2f ms\n", stats.median_step_ms(), stats.mean_step_ms());
  std::printf("  objects            %zu\n", world.object_count());
  std::printf("  triangles          %zu\n", world.triangle_count());
  std::printf("  node tests / step  %.0f\n", stats.mean_node_tests());
  std::printf("  contacts / step    %.1f (steps with contacts: %zu of %zu)\n", stats.mean_contacts(), stats.steps_with_contacts(),
              stats.steps());
  std::printf("  pairs / step       %.1f (distinct pairs over the run: %zu)\n", stats.mean_pairs(), stats.distinct_pairs());
  std::printf("  heaviest pair      %s: %.1f %% of node tests\n", pair_name(world, heavy).c_str(), 100.0 * heavy_share);
  if (stats.distinct_pairs() > 1) {
    std::printf("  second heaviest    %s: %.1f %% of node tests\n", pair_name(world, second).c_str(), 100.0 * second_share);
  }
  nlohmann::json simulated = nlohmann::json::object();
  if (!opt.simulate.empty()) {
    std::printf("  simulated speed-up (%s; node tests, list scheduling on P virtual cores):\n   ",
                std::string(to_string(engine.options().method)).c_str());
    for (std::size_t p = 0; p < opt.simulate.size(); ++p) {
      const double speedup = sims[p].speedup();
      std::printf(" P=%d: %.2fx", opt.simulate[p], speedup);
      simulated[std::to_string(opt.simulate[p])] = speedup;
    }
    std::printf("\n");
  }
  return simulated;
}

/// The report's summary and its end.
void close_report(RunSinks& sinks, const World& world, const RunStats& stats, const nlohmann::json& simulated, bool stopped) {
  if (!sinks.report) return;
  const auto [heavy, heavy_share] = stats.heaviest_pair();
  const auto [second, second_share] = stats.second_heaviest_pair();
  sinks.report->close_array();
  sinks.report->member("summary", {{"steps", stats.steps()},
                                   {"objects", world.object_count()},
                                   {"triangles", world.triangle_count()},
                                   {"median_step_ms", stats.median_step_ms()},
                                   {"mean_step_ms", stats.mean_step_ms()},
                                   {"node_tests_per_step", stats.mean_node_tests()},
                                   {"contacts_per_step", stats.mean_contacts()},
                                   {"pairs_per_step", stats.mean_pairs()},
                                   {"distinct_pairs", stats.distinct_pairs()},
                                   {"steps_with_contacts", stats.steps_with_contacts()},
                                   {"heaviest_pair", {{"a", heavy.a}, {"b", heavy.b}, {"share", heavy_share}}},
                                   {"second_heaviest_pair", {{"a", second.a}, {"b", second.b}, {"share", second_share}}},
                                   {"simulated_speedup", simulated}});
  if (stopped) sinks.report->member("interrupted", true);
  sinks.report->close();
  sinks.json_out->commit();
}

int run_scene(const RunOptions& opt) {
  check_run_options(opt);
  Engine engine = engine_of(opt);
  Scene scene = load_scene(opt.scene);
  scene.steps = steps_of(opt, scene.steps);
  if (opt.continuous) return run_continuous({opt.scene, opt.sweep_tolerance, opt.json}, engine, std::move(scene));
  if (opt.max_pairs != 0) scene.query.max_pairs = opt.max_pairs;
  // SIGINT and SIGTERM handled from before the first output is made until every one is in place.
  const InterruptGuard interrupt;
  RunSinks sinks(opt, scene);
  const auto load_start = Clock::now();
  const World world(std::move(scene));
  const double load_ms = ms_since(load_start);
  const Scene& sc = world.scene();
  std::printf("scene %s: %zu objects (%zu distinct models), %zu triangles, %d steps of %g s, %s query (d = %g, angle %g)\n",
              sc.name.c_str(), world.object_count(), world.distinct_models(), world.triangle_count(), sc.steps, sc.dt,
              std::string(to_string(sc.query.kind)).c_str(), sc.query.tolerance, sc.query.angle_deg);
  std::printf("loaded and built in %.1f ms; method %s on %d thread(s)\n", load_ms,
              std::string(to_string(engine.options().method)).c_str(), engine.threads());
  std::fflush(stdout);
  sinks.open_report(world, engine);
  RunStats stats;
  std::vector<SimulatedRun> sims;  // the load-balance simulation, over the whole run
  for (const int p : opt.simulate) sims.emplace_back(engine.options().method, p);
  const std::size_t limited_steps = run_steps(world, engine, sinks, stats, sims);
  const bool stopped = interrupted();
  if (stopped) {
    std::printf("\ninterrupted (%s) after %zu of %d steps: writing what was measured\n", interrupt_name(), stats.steps(),
                sc.steps);
  }
  if (sinks.contacts_out) sinks.contacts_out->commit();
  if (sinks.exporter) sinks.exporter->commit();
  if (limited_steps > 0) {
    std::printf("\n%zu of %zu steps reached max_pairs %zu (%s) on some pair: their contacts may be partial\n", limited_steps,
                stats.steps(), sc.query.max_pairs, opt.max_pairs != 0 ? "--max-pairs" : "the scene's query");
  }
  close_report(sinks, world, stats, print_summary(opt, world, engine, stats, sims), stopped);
  check_stdout();
  return stopped ? interrupted_exit_code() : 0;
}

}  // namespace

Runner add_run_command(CLI::App& app) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Run a scene over its time steps");
  cmd->add_option("SCENE", opt->scene, "Scene file (JSON, see docs/scenes.md)")->required();
  cmd->add_option("--steps", opt->steps, "Run this many steps instead of the scene's")
      ->check(at_least(1));  // -1, the default, stands for the scene's steps: not a value to give
  cmd->add_option("--method", opt->method, "sequential | exploitation | stealing | aposteriori | apriori | hybrid")
      ->capture_default_str();
  cmd->add_option("--beta", opt->beta, "Calibration: overthreading factor (Omega = total weight / (beta * threads))")
      ->capture_default_str();
  cmd->add_option("--epsilon", opt->epsilon, "Calibration: tolerance on Omega, as a fraction of Omega")->capture_default_str();
  cmd->add_flag("--node-history", opt->node_history,
                "Hybrid: weigh CD nodes by the node tests their subtrees took at the previous step (not in the paper)");
  cmd->add_option("--simulate-cores", opt->simulate, "Virtual core counts for the load-balance simulation")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Threads (0: every hardware thread the process may use; 1: this thread alone)")
      ->capture_default_str();
  cmd->add_option("--stealing-depth", opt->stealing_depth, "Stealing: CD-tree depth below which a subtree runs serially")
      ->capture_default_str();
  cmd->add_option("--json", opt->json, "Write a per-step JSON report to this file");
  cmd->add_option("--contacts", opt->contacts, "Write each step's contacts, one JSON line per step, to this file");
  cmd->add_option("--max-pairs", opt->max_pairs,
                  "Per object pair and step, report at most N triangle pairs: at N it stops and the step says "
                  "so (0: the scene's query.max_pairs, or no limit)")
      ->check(at_least(0))
      ->capture_default_str();
  cmd->add_option("--export", opt->exports.dir, "Write PLY files of chosen steps into this folder (docs/exports.md)");
  cmd->add_option("--export-steps", opt->exports.steps, "The steps --export writes")->delimiter(',')->capture_default_str();
  cmd->add_option("--bvh-depth", opt->exports.bvh_depth, "--export also writes every BVH's boxes down to this depth (-1: none)")
      ->capture_default_str();
  cmd->add_flag("--continuous", opt->continuous,
                "Sweep each step's motion to the next (continuous collision detection): report the pairs that touch "
                "between steps, and when, instead of each step's contacts");
  cmd->add_option("--sweep-tolerance", opt->sweep_tolerance,
                  "--continuous: the distance at which two objects touch (0: 1e-6 of the larger one's radius)")
      ->capture_default_str();
  return [cmd, opt]() {
    if (!cmd->parsed()) return -1;
    for (const CLI::Option* o : cmd->get_options()) {
      if (o->count() > 0) opt->given.push_back(o->get_name());
    }
    return run_scene(*opt);
  };
}

}  // namespace caliber::cli
