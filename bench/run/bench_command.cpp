// caliber-bench: every scene x method x thread count, repeated, medians; the paper's Table 1 and
// Table 2, the 1-thread overhead, the load-balance simulation beyond this machine's cores, the
// estimate-vs-effective correlation, a per-thread timeline, the FCL peer comparison (when
// bench_fcl_compare is built), the run's key figures in one table; results.json, then the SVG
// figures (bench_figures.h) and report.md, both drawn from the same in-memory results.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "bench_figures.h"
#include "bench_records.h"
#include "bench_report.h"
#include "bench_command.h"
#include "bench_measure.h"
#include "interrupt.h"
#include "machine.h"
#include "output_file.h"
#include "timing.h"

namespace caliber::cli {
namespace {

using Json = nlohmann::json;

/// Powers of two up to the machine's hardware threads, and that count itself.
std::vector<int> default_threads() {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<int> t;
  for (int p = 1; p < cores; p *= 2) t.push_back(p);
  t.push_back(cores);
  return t;
}

/// "amd-epyc-2c": the CPU vendor and family and the hardware thread count, for a results folder.
std::string machine_slug() {
  std::string model = bench::cpu_model(), slug;
  for (const char* noise : {"(R)", "(TM)", "(tm)", "(r)"}) {
    for (auto p = model.find(noise); p != std::string::npos; p = model.find(noise)) model.erase(p, std::strlen(noise));
  }
  std::istringstream words(model);
  std::string w;
  int taken = 0;
  while (taken < 2 && words >> w) {
    std::transform(w.begin(), w.end(), w.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    w.erase(std::remove_if(w.begin(), w.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }), w.end());
    if (w.empty() || w == "cpu") continue;
    slug += (taken++ ? "-" : "") + w;
  }
  if (slug.empty()) slug = "machine";
  return slug + "-" + std::to_string(std::max(1u, std::thread::hardware_concurrency())) + "c";
}

/// The directory of the running program (to find bench_fcl_compare next to it).
std::filesystem::path program_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::current_path() : exe.parent_path();
}

/// Runs a shell command, returning its exit status (-1 when it could not run).
int run_command(const std::string& command) {
  const int rc = std::system(command.c_str());
  return rc == -1 ? -1 : WEXITSTATUS(rc);
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Peer comparison against FCL, by the bench program built beside this one (when FCL was found).
std::string fcl_report(const BenchOptions& opt) {
  const auto fcl_program = program_dir() / "bench_fcl_compare";
  if (!opt.fcl) return "Not run: --no-fcl.\n";
  if (!std::filesystem::exists(fcl_program))
    return "Not run: bench_fcl_compare was not built (install libfcl-dev and rebuild).\n";
  std::string scenes;
  for (const std::string& s : opt.scenes) scenes += (scenes.empty() ? "" : ",") + s;
  const auto fcl_md = std::filesystem::path(opt.out) / "fcl_compare.md";
  std::fprintf(stderr, "peer comparison: %s\n", fcl_program.c_str());
  const int rc = run_command(quote(fcl_program.string()) + " --repeat " + std::to_string(opt.fcl_repeat) + " --scenes " +
                             quote(scenes) + " --steps 0,50,100 --out " + quote(fcl_md.string()) + " > /dev/null");
  if (rc != 0 || !std::filesystem::exists(fcl_md)) return "bench_fcl_compare failed (exit " + std::to_string(rc) + ").\n";
  std::ifstream in(fcl_md);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Why the figures are not drawn: --no-figures, or a signal that stopped the bench (empty: they are).
std::string no_figures_note(bool figures) {
  if (!figures) return "Figures not drawn (--no-figures).";
  if (interrupted()) {
    return std::string("Figures not drawn: the bench was interrupted (") + interrupt_name() +
           "); `caliber-bench --from-log` draws them from its log.";
  }
  return "";
}

/// results.json, the figures and report.md in `out`, from the bench's records: the figures and
/// the report are drawn from the same results as the file.
void write_outputs(const std::vector<Json>& records, const std::filesystem::path& out, bool figures) {
  Json results = results_from_records(records);
  const auto json_path = out / "results.json";
  const auto write_json = [&] {
    OutputFile file(json_path.string(), "results.json");  // written whole, or not at all
    file.stream() << results.dump(1) << '\n';
    file.commit();
  };
  write_json();
  const std::string figures_note = no_figures_note(figures);
  if (figures_note.empty()) write_bench_figures(results, out);
  results["figures_note"] = figures_note;
  write_json();
  write_bench_report(results, out / "report.md");
  std::printf("\nwrote %s/report.md and results.json%s\n", out.string().c_str(), figures_note.empty() ? " and figures" : "");
  if (!figures_note.empty()) std::printf("%s\n", figures_note.c_str());
}

/// Every file the bench writes in `out` (scenes named `scene_names`), as (what, path) pairs.
NamedFiles bench_outputs(const std::filesystem::path& out, const std::vector<std::string>& scene_names) {
  NamedFiles files;
  std::vector<std::string> names = {"results.json", "report.md", "fcl_compare.md"};
  for (const std::string& figure : bench_figure_names(scene_names)) names.push_back(figure);
  for (const std::string& name : names) files.emplace_back("--out's " + name, (out / name).string());
  return files;
}

/// `caliber-bench --from-log FILE`: the report of a bench run from its log, whole or cut short.
int report_from_log(const BenchOptions& opt) {
  const std::filesystem::path log_file = opt.from_log;
  const std::vector<Json> records = read_bench_log(log_file);
  std::filesystem::path out = opt.out.empty() ? log_file.parent_path() : std::filesystem::path(opt.out);
  if (out.empty()) out = ".";
  std::vector<std::string> names;
  for (const Json& r : records) {
    if (r.value("kind", "") != "header" || !r.contains("scenes") || !r["scenes"].is_array()) continue;
    for (const Json& s : r["scenes"]) {
      if (s.contains("name") && s["name"].is_string()) names.push_back(s["name"].get<std::string>());
    }
  }
  check_distinct_files(bench_outputs(out, names), {{"--from-log", opt.from_log}});
  if (std::filesystem::exists(out) && !std::filesystem::is_directory(out)) {
    throw Error(ErrorCode::bad_value, "--out", "'" + out.string() + "' exists and is not a folder");
  }
  std::filesystem::create_directories(out);
  write_outputs(records, out, opt.figures);
  check_stdout();
  return interrupted() ? interrupted_exit_code() : 0;
}

/// The options completed with their defaults (the paper's four scenes, powers of two up to the
/// machine's threads) and checked.
void complete_options(BenchOptions& opt) {
  if (opt.scenes.empty()) {
    for (const char* name : {"two_large", "two_small", "funnel", "front_car"})
      opt.scenes.push_back(std::string("scenes/") + name + ".json");
    for (const std::string& s : opt.scenes) {
      if (!std::filesystem::exists(s)) {
        throw Error(ErrorCode::file_not_found, s, "no such file (run from the repository root, or name the scenes)");
      }
    }
  }
  if (opt.threads.empty()) opt.threads = default_threads();
  for (const int t : opt.threads) {
    if (t < 1 || t > 1024) throw Error(ErrorCode::bad_value, "--threads", "thread counts must be in [1, 1024]");
  }
  std::sort(opt.threads.begin(), opt.threads.end());
  opt.threads.erase(std::unique(opt.threads.begin(), opt.threads.end()), opt.threads.end());
  for (const int p : opt.simulate) {
    if (p < 1 || p > 1024) throw Error(ErrorCode::bad_value, "--simulate", "core counts must be in [1, 1024]");
  }
  if (opt.repeat < 1) throw Error(ErrorCode::bad_value, "--repeat", "must be >= 1");
  if (opt.steps < 0) throw Error(ErrorCode::bad_value, "--steps", "must be >= 1 (0: the scene's)");
  if (opt.simulate_steps < 0) throw Error(ErrorCode::bad_value, "--simulate-steps", "must be >= 1 (0: all the scene's steps)");
  if (!(opt.budget_s >= 0.0)) throw Error(ErrorCode::bad_value, "--budget-s", "must be a number of seconds >= 0 (0: no budget)");
}

/// The methods to run, each once, sequential first: the reference for every speed-up and every
/// contact check.
std::vector<Variant> variants_of(const BenchOptions& opt) {
  std::vector<Variant> variants;
  for (const std::string& m : opt.methods) {
    Variant v = parse_variant(m);
    if (std::none_of(variants.begin(), variants.end(), [&](const Variant& u) { return u.name == v.name; }))
      variants.push_back(std::move(v));
  }
  variants.erase(
      std::remove_if(variants.begin(), variants.end(), [](const Variant& v) { return v.method == Method::sequential; }),
      variants.end());
  variants.insert(variants.begin(), parse_variant("sequential"));
  return variants;
}

/// Every scene file parsed (and its meshes checked to exist) before anything is created on disk.
std::vector<Scene> scenes_of(const BenchOptions& opt) {
  std::vector<Scene> scenes;
  for (const std::string& file : opt.scenes) {
    scenes.push_back(load_scene(file));
    if (opt.steps > 0) scenes.back().steps = opt.steps;
    for (std::size_t i = 0; i + 1 < scenes.size(); ++i) {
      if (scenes[i].name == scenes.back().name) {
        throw Error(ErrorCode::bad_argument, file,
                    "scene '" + scenes.back().name + "' is given twice (each scene's outputs are named by it)");
      }
    }
  }
  return scenes;
}

/// The output folder made and the log's path: nothing the bench writes may be one of its inputs (a
/// --log naming a mesh emptied it), checked before the folder is created or the log opened.
std::filesystem::path prepare_outputs(BenchOptions& opt, const std::vector<Scene>& scenes) {
  if (opt.out.empty()) opt.out = "bench/results/" + machine_slug() + "/engine";
  if (std::filesystem::exists(opt.out) && !std::filesystem::is_directory(opt.out)) {
    throw Error(ErrorCode::bad_value, "--out", "'" + opt.out + "' exists and is not a folder");
  }
  const std::filesystem::path log_path =
      opt.log.empty() ? std::filesystem::path(opt.out) / "runs.jsonl" : std::filesystem::path(opt.log);
  NamedFiles inputs;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const NamedFiles read = scene_inputs(opt.scenes[i], scenes[i]);
    inputs.insert(inputs.end(), read.begin(), read.end());
    names.push_back(scenes[i].name);
  }
  NamedFiles outputs = bench_outputs(opt.out, names);
  outputs.insert(outputs.begin(), {opt.log.empty() ? "--out's runs.jsonl" : "--log", log_path.string()});
  check_distinct_files(outputs, inputs);
  if (std::error_code ec; !opt.log.empty() && std::filesystem::is_directory(log_path, ec)) {
    throw Error(ErrorCode::bad_argument, "--log", "'" + opt.log + "' is a folder, not a log file");  // before --out is made
  }
  std::filesystem::create_directories(opt.out);
  return log_path;
}

/// The runs planned and the progress units (steps) they take.
std::pair<std::size_t, std::size_t> planned(const BenchOptions& opt, const std::vector<std::unique_ptr<World>>& worlds,
                                            const std::vector<Variant>& variants) {
  std::size_t units = 0, runs_planned = 0;
  for (const auto& w : worlds) {
    for (const Variant& v : variants) {
      const std::size_t configs = v.method == Method::sequential ? 1 : opt.threads.size();
      runs_planned += static_cast<std::size_t>(opt.repeat) * configs;
      units += static_cast<std::size_t>(opt.repeat) * configs * static_cast<std::size_t>(w->scene().steps);
      if (v.method != Method::sequential)
        units += opt.simulate.size() * static_cast<std::size_t>(simulated_steps(opt, w->scene()));
    }
  }
  return {runs_planned, units};
}

/// The log's first record: the machine, the options, the methods and the scenes.
Json header_record(const BenchOptions& opt, const std::vector<std::unique_ptr<World>>& worlds,
                   const std::vector<Variant>& variants, std::size_t runs_planned) {
  Json header = {{"kind", "header"},
                 {"machine", bench::machine_description()},
                 {"cpu", bench::cpu_model()},
                 {"hardware_threads", static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))},
                 {"compiler", bench::compiler()},
                 {"repeat", opt.repeat},
                 {"threads", opt.threads},
                 {"simulate", opt.simulate},
                 {"simulate_steps", opt.simulate_steps},
                 {"budget_s", opt.budget_s},
                 {"runs_planned", runs_planned},
                 {"methods", Json::array()},
                 {"scenes", Json::array()}};
  for (const Variant& v : variants) header["methods"].push_back(v.name);
  for (std::size_t i = 0; i < worlds.size(); ++i) {
    header["scenes"].push_back({{"name", worlds[i]->scene().name}, {"file", opt.scenes[i]}, {"steps", worlds[i]->scene().steps}});
  }
  return header;
}

int run_bench(BenchOptions opt) {
  // SIGINT and SIGTERM handled from before anything is created until the outputs are in place: the
  // bench stops after the step in progress and reports what it measured.
  const InterruptGuard interrupt;
  if (!opt.from_log.empty()) return report_from_log(opt);
  const Budget budget(opt.budget_s);  // counts from here: loading the scenes is part of the run
  complete_options(opt);
  const std::vector<Variant> variants = variants_of(opt);
  std::vector<Scene> scenes = scenes_of(opt);
  const std::filesystem::path log_path = prepare_outputs(opt, scenes);
  BenchLog log(log_path);  // opened before the long work: an unwritable log fails now
  // Load every scene first: bad input fails before any long work starts.
  std::vector<std::unique_ptr<World>> worlds;
  std::vector<double> load_s;
  for (Scene& scene : scenes) {
    const auto start = Clock::now();
    worlds.push_back(std::make_unique<World>(std::move(scene)));
    load_s.push_back(seconds_since(start));
  }
  const auto [runs_planned, units] = planned(opt, worlds, variants);
  std::printf("caliber-bench on %s\n%zu scene(s), %zu method(s), threads {", bench::machine_description().c_str(), worlds.size(),
              variants.size());
  for (std::size_t i = 0; i < opt.threads.size(); ++i) std::printf("%s%d", i ? ", " : "", opt.threads[i]);
  std::printf("}, %d repeat(s); results in %s, each run logged to %s as it ends\n", opt.repeat, opt.out.c_str(),
              log_path.c_str());
  std::fflush(stdout);
  log.add(header_record(opt, worlds, variants, runs_planned));

  BenchRun b{opt, worlds, load_s, variants, log, budget, Progress(units), 0, false, {}};
  b.sequential_s.assign(worlds.size(), 0.0);
  for (std::size_t si = 0; si < worlds.size() && !b.stopped; ++si) bench_scene(b, si);
  record_gantt(b);
  if (b.fits(opt.fcl ? 60.0 : 0.0, "the FCL comparison")) log.add({{"kind", "fcl"}, {"report", fcl_report(opt)}});
  static_cast<void>(b.interrupted_before("the figures"));  // a signal during the FCL comparison: recorded
  const bool stopped = interrupted();

  write_outputs(log.records(), opt.out, opt.figures);
  const Json results = results_from_records(log.records());
  if (!results["contacts_identical"].get<bool>()) {
    std::fprintf(stderr, "caliber-bench: some method returned contacts that differ from sequential's (see above)\n");
    return 1;
  }
  check_stdout();
  return stopped ? interrupted_exit_code() : 0;
}

}  // namespace

Runner add_bench_options(CLI::App& app) {
  auto opt = std::make_shared<BenchOptions>();
  CLI::App* cmd = &app;
  cmd->add_option("SCENES", opt->scenes, "Scene files (default: scenes/{two_large,two_small,funnel,front_car}.json)");
  cmd->add_option("--methods", opt->methods, "Methods (and hybrid+history); sequential is always run as the reference")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Thread counts (default: powers of two up to the machine's cores, and the cores)")
      ->delimiter(',');
  cmd->add_option("--repeat", opt->repeat, "Runs per configuration; the median is reported")->capture_default_str();
  cmd->add_option("--steps", opt->steps, "Steps per run (default: the scene's)");
  cmd->add_option("--simulate", opt->simulate, "Virtual core counts for the load-balance simulation")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--simulate-steps", opt->simulate_steps, "Steps replayed per simulated core count (0: all)")
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "Output folder (default: bench/results/<machine>/engine)");
  cmd->add_option("--fcl-repeat", opt->fcl_repeat, "Runs per FCL comparison")->capture_default_str();
  cmd->add_flag("!--no-figures", opt->figures, "Do not draw the SVG figures");
  cmd->add_flag("!--no-fcl", opt->fcl, "Do not run the FCL peer comparison");
  cmd->add_flag("!--no-ceiling", opt->ceiling,
                "Do not measure the machine's ceiling (P independent sequential copies at once, for each thread count P > 1)");
  cmd->add_option("--budget-s", opt->budget_s,
                  "Time budget in seconds: a run starts only if its estimated time still fits, and the report covers what ran "
                  "(0: none)")
      ->capture_default_str();
  cmd->add_option("--log", opt->log,
                  "JSON-lines log, one record per finished run, written as measured (default: OUT/runs.jsonl)");
  cmd->add_option("--from-log", opt->from_log,
                  "Measure nothing: rebuild results.json, the figures and report.md from a bench log (a run cut short "
                  "included), into --out or the log's folder");
  return [opt]() { return run_bench(*opt); };
}

}  // namespace caliber::cli
