// caliber bench: every scene x method x thread count, repeated, medians; the paper's Table 1 and
// Table 2, the 1-thread overhead, the load-balance simulation beyond this machine's cores, the
// estimate-vs-effective correlation, a per-thread timeline, the FCL peer comparison (when
// bench_fcl_compare is built), the targets checked against what was measured; report.md +
// results.json, then figures drawn by scripts/plot_bench.py (matplotlib) when it can run.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "bench_report.h"
#include "commands.h"
#include "machine.h"
#include "progress.h"

namespace caliber::cli {
namespace {

using Json = nlohmann::json;

struct BenchOptions {
  std::vector<std::string> scenes;
  std::vector<std::string> methods = {"sequential", "exploitation", "stealing", "aposteriori", "apriori", "hybrid"};
  std::vector<int> threads;
  std::vector<int> simulate = {4, 8, 16, 32, 64};
  int repeat = 3;
  int steps = 0;           // 0: the scene's
  int simulate_steps = 0;  // steps replayed per simulated core count (0: all the scene's)
  int fcl_repeat = 3;
  std::string out;
  bool figures = true;
  bool fcl = true;
};

/// A method name as the bench knows it: the six methods, and "hybrid+history" (node history on).
struct Variant {
  std::string name;
  Method method;
  bool node_history;
};

Variant parse_variant(const std::string& name) {
  if (name == "hybrid+history") return {name, Method::hybrid, true};
  return {name, parse_method(name), false};
}

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

/// FNV-1a over a step's contacts, to check that every method returns the sequential answer.
std::uint64_t contacts_hash(const StepResult& s) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&](const void* data, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  for (const SceneContact& c : s.contacts) {
    mix(&c.object_a, sizeof c.object_a);
    mix(&c.object_b, sizeof c.object_b);
    mix(&c.contact.tri_a, sizeof c.contact.tri_a);
    mix(&c.contact.tri_b, sizeof c.contact.tri_b);
    mix(&c.contact.distance, sizeof c.contact.distance);
    mix(c.contact.point_a.data(), 3 * sizeof(double));
    mix(c.contact.point_b.data(), 3 * sizeof(double));
    mix(c.contact.normal.data(), 3 * sizeof(double));
  }
  return h;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double pearson(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  if (n < 3) return 0.0;
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n, my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return (sxx > 0 && syy > 0) ? sxy / std::sqrt(sxx * syy) : 0.0;
}

/// Steps replayed for the load-balance simulation of a scene.
int simulated_steps(const BenchOptions& opt, const Scene& scene) {
  return opt.simulate_steps > 0 ? std::min(opt.simulate_steps, scene.steps) : scene.steps;
}

EngineOptions engine_options(const Variant& v, int threads) {
  EngineOptions o;
  o.method = v.method;
  o.node_history = v.node_history;
  o.threads = threads;
  return o;
}

/// The directory of the running program (to find bench_fcl_compare and scripts/ next to it).
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

/// Debian's python3 (where python3-matplotlib installs), before whatever python3 is first on PATH.
std::string python() { return std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3"; }

std::string quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

int run_bench(BenchOptions opt) {
  if (opt.scenes.empty()) {
    for (const char* name : {"two_large", "two_small", "funnel", "front_car"}) opt.scenes.push_back(std::string("scenes/") + name + ".json");
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
  std::vector<Variant> variants;
  for (const std::string& m : opt.methods) {
    Variant v = parse_variant(m);
    if (std::none_of(variants.begin(), variants.end(), [&](const Variant& u) { return u.name == v.name; })) variants.push_back(std::move(v));
  }
  // Sequential first, exactly once: the reference for every speed-up and every contact check.
  variants.erase(std::remove_if(variants.begin(), variants.end(), [](const Variant& v) { return v.method == Method::sequential; }),
                 variants.end());
  variants.insert(variants.begin(), parse_variant("sequential"));
  if (opt.out.empty()) opt.out = "bench/results/" + machine_slug();
  std::filesystem::create_directories(opt.out);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  // Load every scene first: bad input fails before any long work starts.
  std::vector<std::unique_ptr<World>> worlds;
  for (const std::string& file : opt.scenes) {
    Scene scene = load_scene(file);
    if (opt.steps > 0) scene.steps = opt.steps;
    worlds.push_back(std::make_unique<World>(std::move(scene)));
  }
  std::size_t units = 0;
  for (const auto& w : worlds) {
    for (const Variant& v : variants) {
      units += static_cast<std::size_t>(opt.repeat) * (v.method == Method::sequential ? 1 : opt.threads.size()) *
               static_cast<std::size_t>(w->scene().steps);
      if (v.method != Method::sequential) units += opt.simulate.size() * static_cast<std::size_t>(simulated_steps(opt, w->scene()));
    }
  }
  std::printf("caliber bench on %s\n%zu scene(s), %zu method(s), threads {", bench::machine_description().c_str(), worlds.size(),
              variants.size());
  for (std::size_t i = 0; i < opt.threads.size(); ++i) std::printf("%s%d", i ? ", " : "", opt.threads[i]);
  std::printf("}, %d repeat(s); results in %s\n", opt.repeat, opt.out.c_str());
  std::fflush(stdout);
  const Progress progress(units);
  std::size_t done = 0;
  bool mismatch = false;

  Json results = {{"machine", bench::machine_description()},
                  {"cpu", bench::cpu_model()},
                  {"hardware_threads", cores},
                  {"compiler", bench::compiler()},
                  {"repeat", opt.repeat},
                  {"threads", opt.threads},
                  {"simulate", opt.simulate},
                  {"simulate_steps", opt.simulate_steps},
                  {"scenes", Json::array()}};
  for (std::size_t si = 0; si < worlds.size(); ++si) {
    const World& world = *worlds[si];
    const Scene& sc = world.scene();
    Json scene_json = {{"name", sc.name}, {"file", opt.scenes[si]}, {"steps", sc.steps}, {"methods", Json::object()}};
    std::vector<std::uint64_t> reference_hash;
    double sequential_ms = 0.0;
    // Measured runs in rounds: round r runs every configuration once, so that a slow spell of a
    // shared machine spreads over all of them instead of landing on one configuration's repeats.
    // Sequential comes first in every round (it is the reference for the contact check).
    struct Config {
      const Variant* variant;
      int threads;
      std::vector<double> totals;
      std::vector<Json> phases;  // per run, in round order
    };
    std::vector<Config> configs;
    for (const Variant& v : variants) {
      for (const int t : v.method == Method::sequential ? std::vector<int>{1} : opt.threads) configs.push_back(Config{&v, t, {}, {}});
    }
    for (int r = 0; r < opt.repeat; ++r) {
      for (Config& c : configs) {
        const Variant& v = *c.variant;
        const int t = c.threads;
        Engine engine(world, engine_options(v, t));
        RunStats stats;
        double total = 0.0, calibrate = 0.0, traverse = 0.0, finalize = 0.0, broad = 0.0;
        // The load-balance simulation of this very run: its tasks' node tests list-scheduled on as
        // many virtual cores as it has threads (what the cut allows, whatever the clock says).
        double sim_work = 0.0, sim_span = 0.0;
        for (int k = 0; k < sc.steps; ++k) {
          const StepResult s = engine.step(k);
          const double ms = s.broad_ms + s.narrow_ms + s.reduce_ms;
          total += ms;
          broad += s.broad_ms;
          calibrate += s.schedule.calibrate_ms;
          traverse += s.schedule.traverse_ms;
          finalize += s.schedule.finalize_ms;
          if (v.method != Method::sequential && s.stats.node_tests > 0) {
            const double w = static_cast<double>(s.stats.node_tests);
            sim_work += w;
            sim_span += w / simulated_speedup(s, v.method, t);
          }
          const std::uint64_t h = contacts_hash(s);
          if (v.method == Method::sequential && r == 0) {
            reference_hash.push_back(h);
            stats.add(s);
          } else if (reference_hash.size() > static_cast<std::size_t>(k) && reference_hash[k] != h) {
            mismatch = true;
            std::fprintf(stderr, "\nMISMATCH: %s, %s on %d threads, step %d: contacts differ from sequential's\n", sc.name.c_str(),
                         v.name.c_str(), t, k);
          }
          ++done;
          if (progress.terminal() || k + 1 == sc.steps) {  // plain output: one line per run
            char line[200];
            std::snprintf(line, sizeof line, "%s: round %d/%d, %s x%d, step %d", sc.name.c_str(), r + 1, opt.repeat, v.name.c_str(), t, k);
            progress.update(done, line);
          }
        }
        c.totals.push_back(total);
        if (v.method == Method::sequential && r == 0) {
          const auto [heavy, heavy_share] = stats.heaviest_pair();
          const auto [second, second_share] = stats.second_heaviest_pair();
          scene_json["table1"] = {{"objects", world.object_count()},
                                  {"triangles", world.triangle_count()},
                                  {"node_tests_per_step", stats.mean_node_tests()},
                                  {"contacts_per_step", stats.mean_contacts()},
                                  {"pairs_per_step", stats.mean_tasks()},
                                  {"candidate_pairs", stats.candidate_pairs()},
                                  {"heaviest_pair_share", heavy_share},
                                  {"second_pair_share", second_share},
                                  {"exploitation_bound", heavy_share > 0 ? 1.0 / heavy_share : 1.0}};
        }
        {
          c.phases.push_back({{"broad_ms", broad / sc.steps},
                      {"calibrate_ms", calibrate / sc.steps},
                      {"traverse_ms", traverse / sc.steps},
                      {"finalize_ms", finalize / sc.steps},
                      {"balance_speedup", sim_span > 0 ? sim_work / sim_span : 1.0}});
        }
      }
    }
    for (const Variant& v : variants) {
      Json method_json = {{"threads", Json::object()}};
      for (const Config& c : configs) {
        if (c.variant != &v) continue;
        const double step_ms = median(c.totals) / sc.steps;
        if (v.method == Method::sequential) sequential_ms = step_ms;
        // The phases of the median run (the lower middle one for an even count), so that they add up
        // to the reported step time and not to a run that met a slow spell.
        std::vector<std::size_t> order(c.totals.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return c.totals[x] < c.totals[y]; });
        const Json& phases = c.phases[order[(order.size() - 1) / 2]];
        method_json["threads"][std::to_string(c.threads)] = {{"step_ms", step_ms}, {"runs_ms", c.totals}, {"phases_per_step", phases}};
      }
      // The load-balance simulation: tasks cut for P threads (the engine runs P threads here, so
      // calibration targets P), node tests list-scheduled on P virtual cores.
      if (v.method != Method::sequential) {
        Json simulated = Json::object();
        Json correlation = Json::object();
        for (const int p : opt.simulate) {
          Engine engine(world, engine_options(v, p));
          double work = 0.0, span = 0.0;
          std::vector<double> estimated, effective;
          const int steps = simulated_steps(opt, sc);
          for (int k = 0; k < steps; ++k) {
            const StepResult s = engine.step(k);
            const double w = static_cast<double>(s.stats.node_tests);
            work += w;
            span += w / simulated_speedup(s, v.method, p);
            if (p == 8 || p == opt.simulate.front()) {
              const auto& r = s.schedule;
              for (std::size_t i = 0; i < r.task_weights.size() && i < r.task_node_tests.size(); ++i) {
                estimated.push_back(r.task_weights[i]);
                effective.push_back(static_cast<double>(r.task_node_tests[i]));
              }
            }
            ++done;
            if (progress.terminal() || k + 1 == steps) {
              char line[200];
              std::snprintf(line, sizeof line, "%s: %s simulated on %d cores, step %d", sc.name.c_str(), v.name.c_str(), p, k);
              progress.update(done, line);
            }
          }
          simulated[std::to_string(p)] = span > 0 ? work / span : 1.0;
          if (!estimated.empty() && (p == 8 || correlation.empty())) {
            // Keep at most 4000 points for the figure (evenly spaced); r uses all of them.
            Json points = Json::array();
            const std::size_t stride = std::max<std::size_t>(1, estimated.size() / 4000);
            for (std::size_t i = 0; i < estimated.size(); i += stride) points.push_back({estimated[i], effective[i]});
            correlation = {{"cores", p}, {"pearson", pearson(estimated, effective)}, {"tasks", estimated.size()}, {"points", points}};
          }
        }
        method_json["simulated_speedup"] = simulated;
        if (!correlation.empty()) method_json["correlation"] = correlation;
      }
      scene_json["methods"][v.name] = method_json;
    }
    scene_json["sequential_step_ms"] = sequential_ms;
    results["scenes"].push_back(scene_json);
  }

  // Timeline of one step (Gantt): exploitation vs hybrid on front_car (or the last scene), at the
  // highest measured thread count.
  {
    std::size_t si = worlds.size() - 1;
    for (std::size_t i = 0; i < worlds.size(); ++i) {
      if (worlds[i]->scene().name == "front_car") si = i;
    }
    const World& world = *worlds[si];
    const int t = opt.threads.back();
    const int step = world.scene().steps / 2;
    Json gantt = {{"scene", world.scene().name}, {"threads", t}, {"step", step}, {"methods", Json::object()}};
    for (const char* name : {"exploitation", "hybrid"}) {
      EngineOptions o = engine_options(parse_variant(name), t);
      o.timeline = true;
      Engine engine(world, o);
      StepResult s;
      for (int k = 0; k <= step; ++k) s = engine.step(k);  // hybrid needs the previous steps' history
      Json spans = Json::array();
      for (const TaskSpan& span : s.schedule.timeline) {
        spans.push_back({span.thread, span.start_ms, span.end_ms,
                         span.phase == TaskSpan::Phase::stage ? "stage" : span.phase == TaskSpan::Phase::traverse ? "traverse" : "finalize"});
      }
      gantt["methods"][name] = {{"narrow_ms", s.narrow_ms}, {"spans", spans}};
    }
    results["gantt"] = gantt;
  }

  // Peer comparison against FCL, by the bench program built beside this one (when FCL was found).
  std::string fcl_report;
  const auto fcl_program = program_dir() / "bench_fcl_compare";
  if (opt.fcl && std::filesystem::exists(fcl_program)) {
    std::string scenes;
    for (const std::string& s : opt.scenes) scenes += (scenes.empty() ? "" : ",") + s;
    const auto fcl_md = std::filesystem::path(opt.out) / "fcl_compare.md";
    std::fprintf(stderr, "peer comparison: %s\n", fcl_program.c_str());
    const int rc = run_command(quote(fcl_program.string()) + " --repeat " + std::to_string(opt.fcl_repeat) + " --scenes " +
                               quote(scenes) + " --steps 0,50,100 --out " + quote(fcl_md.string()) + " > /dev/null");
    if (rc == 0 && std::filesystem::exists(fcl_md)) {
      std::ifstream in(fcl_md);
      std::stringstream ss;
      ss << in.rdbuf();
      fcl_report = ss.str();
    } else {
      fcl_report = "bench_fcl_compare failed (exit " + std::to_string(rc) + ").\n";
    }
  } else {
    fcl_report = "Not run: " + std::string(opt.fcl ? "bench_fcl_compare was not built (install libfcl-dev and rebuild)" : "--no-fcl") + ".\n";
  }
  results["fcl_report"] = fcl_report;
  results["contacts_identical"] = !mismatch;

  const auto json_path = std::filesystem::path(opt.out) / "results.json";
  {
    std::ofstream out(json_path);
    if (!out) throw Error(ErrorCode::unreadable, json_path.string(), "cannot be opened for writing");
    out << results.dump(1) << '\n';
  }

  // Figures: scripts/plot_bench.py (matplotlib), found next to the build folder or here.
  std::string figures_note;
  if (opt.figures) {
    std::filesystem::path script;
    for (const auto& candidate : {program_dir() / ".." / "scripts" / "plot_bench.py", std::filesystem::path("scripts/plot_bench.py")}) {
      if (std::filesystem::exists(candidate)) {
        script = candidate;
        break;
      }
    }
    if (script.empty()) {
      figures_note = "Figures not drawn: scripts/plot_bench.py not found.";
    } else if (run_command(python() + " " + quote(script.string()) + " " + quote(opt.out)) != 0) {
      figures_note = "Figures not drawn: `python3 scripts/plot_bench.py` failed (is python3-matplotlib installed?).";
    }
  } else {
    figures_note = "Figures not drawn (--no-figures).";
  }
  results["figures_note"] = figures_note;
  {
    std::ofstream out(json_path);
    out << results.dump(1) << '\n';
  }
  write_bench_report(results, std::filesystem::path(opt.out) / "report.md");
  std::printf("\nwrote %s/report.md and results.json%s\n", opt.out.c_str(), figures_note.empty() ? " and figures" : "");
  if (!figures_note.empty()) std::printf("%s\n", figures_note.c_str());
  if (mismatch) {
    std::fprintf(stderr, "caliber bench: some method returned contacts that differ from sequential's (see above)\n");
    return 1;
  }
  return 0;
}

}  // namespace

Runner add_bench_command(CLI::App& app) {
  auto opt = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench", "Every scene x method x thread count: the paper's tables and figures, measured");
  cmd->add_option("SCENES", opt->scenes, "Scene files (default: scenes/{two_large,two_small,funnel,front_car}.json)");
  cmd->add_option("--methods", opt->methods, "Methods (and hybrid+history); sequential is always run as the reference")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Thread counts (default: powers of two up to the machine's cores, and the cores)")
      ->delimiter(',');
  cmd->add_option("--repeat", opt->repeat, "Runs per configuration; the median is reported")->capture_default_str();
  cmd->add_option("--steps", opt->steps, "Steps per run (default: the scene's)");
  cmd->add_option("--simulate", opt->simulate, "Virtual core counts for the load-balance simulation")->delimiter(',')->capture_default_str();
  cmd->add_option("--simulate-steps", opt->simulate_steps, "Steps replayed per simulated core count (0: all)")->capture_default_str();
  cmd->add_option("--out", opt->out, "Output folder (default: bench/results/<machine>)");
  cmd->add_option("--fcl-repeat", opt->fcl_repeat, "Runs per FCL comparison")->capture_default_str();
  cmd->add_flag("!--no-figures", opt->figures, "Do not run scripts/plot_bench.py");
  cmd->add_flag("!--no-fcl", opt->fcl, "Do not run the FCL peer comparison");
  return [cmd, opt]() { return cmd->parsed() ? run_bench(*opt) : -1; };
}

}  // namespace caliber::cli
