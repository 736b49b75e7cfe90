// caliber-bench: every scene x method x thread count, repeated, medians; the paper's Table 1 and
// Table 2, the 1-thread overhead, the load-balance simulation beyond this machine's cores, the
// estimate-vs-effective correlation, a per-thread timeline, the FCL peer comparison (when
// bench_fcl_compare is built), the run's key figures in one table; report.md +
// results.json, then figures drawn by scripts/plot_bench.py (matplotlib) when it can run.

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
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
#include "caliber/profile.h"
#include "caliber/error.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "bench_records.h"
#include "bench_report.h"
#include "bench_command.h"
#include "interrupt.h"
#include "machine.h"
#include "output_file.h"
#include "progress.h"
#include "run_stats.h"
#include "timing.h"

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
  bool ceiling = true;
  double budget_s = 0.0;  // 0: no budget
  std::string log;        // the JSON-lines log (default: OUT/runs.jsonl)
  std::string from_log;   // rebuild the report from this log instead of measuring
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
  for (const Contact& c : s.contacts) {
    mix(&c.object_a, sizeof c.object_a);
    mix(&c.object_b, sizeof c.object_b);
    mix(&c.tri_a, sizeof c.tri_a);
    mix(&c.tri_b, sizeof c.tri_b);
    mix(&c.distance, sizeof c.distance);
    mix(c.point_a.data(), 3 * sizeof(double));
    mix(c.point_b.data(), 3 * sizeof(double));
    mix(c.normal.data(), 3 * sizeof(double));
  }
  return h;
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
  o.profile = true;  // the bench reports every step's schedule
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

/// The time the bench may take (--budget-s): a run starts only if its estimated time still fits,
/// so the bench ends inside the budget with every finished run in its log.
class Budget {
 public:
  explicit Budget(double seconds) : mSeconds(seconds) {}
  /// Whether work estimated at `estimate_s` seconds (a quarter more for safety) still fits.
  [[nodiscard]] bool allows(double estimate_s) const { return mSeconds <= 0.0 || elapsed_s() + 1.25 * estimate_s <= mSeconds; }
  [[nodiscard]] double elapsed_s() const { return seconds_since(mStart); }

 private:
  Clock::time_point mStart = Clock::now();
  double mSeconds;
};

/// One scene x method x thread count, and its runs so far (the last one estimates the next).
struct Config {
  const Variant* variant;
  int threads;
  double last_ms = 0.0;
};

/// Everything a bench run shares: options, scenes, methods, the log, the budget, the progress.
struct BenchRun {
  const BenchOptions& opt;
  std::vector<std::unique_ptr<World>>& worlds;
  std::vector<double> load_s;  ///< per scene: loading and building its world once
  const std::vector<Variant>& variants;
  BenchLog& log;
  Budget budget;
  Progress progress;
  std::size_t done = 0;
  bool stopped = false;
  std::vector<double> sequential_s;  ///< per scene: one sequential run, in seconds (0 until run)

  /// Whether a signal (SIGINT, SIGTERM) stopped the bench; records that it stops here, before `what`.
  bool interrupted_before(const std::string& what) {
    if (stopped) return true;
    if (!interrupted()) return false;
    stopped = true;
    progress.end();
    log.add({{"kind", "stopped"},
             {"reason", "interrupted"},
             {"signal", interrupt_name()},
             {"after_s", budget.elapsed_s()},
             {"next", what}});
    std::fprintf(stderr, "\ncaliber-bench: interrupted (%s) after %.0f s; not run: %s and what follows\n", interrupt_name(),
                 budget.elapsed_s(), what.c_str());
    return true;
  }

  /// Whether work of `estimate_s` fits and no signal stopped the bench; if not, records that the
  /// run stops here.
  bool fits(double estimate_s, const std::string& what) {
    if (interrupted_before(what)) return false;
    if (budget.allows(estimate_s)) return true;
    stopped = true;
    log.add({{"kind", "stopped"}, {"reason", "budget"}, {"after_s", budget.elapsed_s()}, {"next", what}});
    std::fprintf(stderr, "\ncaliber-bench: --budget-s %g reached after %.0f s; not run: %s and what follows\n", opt.budget_s,
                 budget.elapsed_s(), what.c_str());
    return false;
  }
};

/// One measured run: every step of the scene on a fresh engine; its record, and the contact check
/// against the sequential reference (`reference` is filled by the first sequential run). Nothing
/// when the budget ran out during the run (a run not measured before is estimated from its own
/// first steps: after each step, the rest of the run must still fit).
std::optional<Json> measure_run(BenchRun& b, const World& world, const Variant& v, int t, int round,
                                std::vector<std::uint64_t>& reference) {
  const Scene& sc = world.scene();
  Engine engine(engine_options(v, t));
  RunStats stats;
  double total = 0.0, calibrate = 0.0, traverse = 0.0, finalize = 0.0, broad = 0.0;
  // The load-balance simulation of this very run: its tasks' node tests list-scheduled on as many
  // virtual cores as it has threads (what the cut allows, whatever the clock says).
  SimulatedRun simulated(v.method, t);
  const bool is_reference = v.method == Method::sequential && reference.empty();
  const auto run_start = Clock::now();
  for (int k = 0; k < sc.steps; ++k) {
    if (k > 0 && !b.fits(seconds_since(run_start) / k * (sc.steps - k),
                         sc.name + " round " + std::to_string(round + 1) + " " + v.name + " x" + std::to_string(t))) {
      return std::nullopt;
    }
    const StepResult s = step(world, engine, k);
    total += s.broad_ms + s.narrow_ms + s.reduce_ms;
    broad += s.broad_ms;
    calibrate += s.schedule->calibrate_ms;
    traverse += s.schedule->traverse_ms;
    finalize += s.schedule->finalize_ms;
    simulated.add(s);
    const std::uint64_t h = contacts_hash(s);
    if (is_reference) {
      reference.push_back(h);
      stats.add(s);
    } else if (reference.size() > static_cast<std::size_t>(k) && reference[k] != h) {
      b.log.add({{"kind", "mismatch"}, {"scene", sc.name}, {"method", v.name}, {"threads", t}, {"step", k}});
      std::fprintf(stderr, "\nMISMATCH: %s, %s on %d threads, step %d: contacts differ from sequential's\n", sc.name.c_str(),
                   v.name.c_str(), t, k);
    }
    ++b.done;
    if (b.progress.terminal() || k + 1 == sc.steps) {  // plain output: one line per run
      char line[200];
      std::snprintf(line, sizeof line, "%s: round %d/%d, %s x%d, step %d", sc.name.c_str(), round + 1, b.opt.repeat,
                    v.name.c_str(), t, k);
      b.progress.update(b.done, line);
    }
  }
  if (is_reference) {
    const auto [heavy, heavy_share] = stats.heaviest_pair();
    const auto [second, second_share] = stats.second_heaviest_pair();
    b.log.add({{"kind", "table1"},
               {"scene", sc.name},
               {"objects", world.object_count()},
               {"triangles", world.triangle_count()},
               {"node_tests_per_step", stats.mean_node_tests()},
               {"contacts_per_step", stats.mean_contacts()},
               {"pairs_per_step", stats.mean_tasks()},
               {"candidate_pairs", stats.candidate_pairs()},
               {"heaviest_pair_share", heavy_share},
               {"second_pair_share", second_share},
               {"exploitation_bound", heavy_share > 0 ? 1.0 / heavy_share : 1.0}});
  }
  const double steps = sc.steps;
  return Json{{"kind", "run"},
              {"scene", sc.name},
              {"method", v.name},
              {"threads", t},
              {"round", round},
              {"total_ms", total},
              {"phases",
               {{"broad_ms", broad / steps},
                {"calibrate_ms", calibrate / steps},
                {"traverse_ms", traverse / steps},
                {"finalize_ms", finalize / steps},
                {"balance_speedup", simulated.speedup()}}}};
}

/// The machine's own ceiling at `copies` threads: that many independent sequential copies of the
/// scene run at once, each with its own world and engine (nothing shared), and each copy's time per
/// step. Against one copy alone, what memory bandwidth, shared caches and clock boost leave of
/// `copies` x before any scheduling.
std::vector<double> measure_ceiling(const Scene& scene, int copies) {
  std::vector<double> ms(static_cast<std::size_t>(copies), 0.0);
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(copies));
  std::mutex mutex;
  std::condition_variable ready;
  int loaded = 0;
  std::vector<std::thread> threads;
  for (int i = 0; i < copies; ++i) {
    threads.emplace_back([&, i] {
      try {
        World world(scene);  // its own copy of every model
        EngineOptions options;
        options.method = Method::sequential;
        options.threads = 1;
        Engine engine(options);
        {
          std::unique_lock<std::mutex> lock(mutex);
          ++loaded;
          ready.notify_all();
          ready.wait(lock, [&] { return loaded >= copies; });  // all start stepping together
        }
        const auto start = Clock::now();
        for (int k = 0; k < scene.steps && !interrupted(); ++k) static_cast<void>(step(world, engine, k));
        ms[static_cast<std::size_t>(i)] = 1000.0 * seconds_since(start) / scene.steps;
      } catch (...) {
        errors[static_cast<std::size_t>(i)] = std::current_exception();
        std::lock_guard<std::mutex> lock(mutex);
        loaded += copies;  // nobody waits for a copy that failed
        ready.notify_all();
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return ms;
}

/// The load-balance simulation of every method but sequential at each simulated core count: tasks
/// cut for P threads (EngineOptions::plan_threads) and run on one thread, their node tests and
/// their measured times list-scheduled on P virtual cores (speed-up by node tests, and the step
/// time predicted by predicted_step_ms, against a sequential run of the same steps); and the
/// estimate's correlation at P = 8 (or the first P).
void simulate_scene(BenchRun& b, const World& world, double sequential_s) {
  const Scene& sc = world.scene();
  const int steps = simulated_steps(b.opt, sc);
  // The sequential time of the very steps replayed (the measured runs may cover more steps, and
  // steps differ in cost): what a predicted step time is a speed-up against.
  if (!b.fits(sequential_s * steps / sc.steps, sc.name + " sequential, the simulation's steps")) return;
  double sequential_ms = 0.0;
  {
    Engine engine(engine_options(Variant{"sequential", Method::sequential, false}, 1));
    for (int k = 0; k < steps; ++k) {
      const StepResult s = step(world, engine, k);
      sequential_ms += (s.broad_ms + s.narrow_ms + s.reduce_ms) / steps;
    }
  }
  for (const Variant& v : b.variants) {
    if (v.method == Method::sequential) continue;
    bool correlated = false;
    for (const int p : b.opt.simulate) {
      if (!b.fits(sequential_s * steps / sc.steps, sc.name + " " + v.name + " simulated on " + std::to_string(p) + " cores"))
        return;
      // The cut made for P threads, run on one thread with its timeline: each piece timed
      // undisturbed (this machine may have fewer cores than P), replayed on P virtual cores both
      // by node tests and by measured time.
      EngineOptions options = engine_options(v, 1);
      options.plan_threads = p;
      options.timeline = true;
      Engine engine(options);
      SimulatedRun simulated(v.method, p);
      std::vector<double> estimated, effective;
      for (int k = 0; k < steps; ++k) {
        if (b.interrupted_before(sc.name + " " + v.name + " simulated on " + std::to_string(p) + " cores, step " +
                                 std::to_string(k)))
          return;
        const StepResult s = step(world, engine, k);
        simulated.add(s);
        if (p == 8 || p == b.opt.simulate.front()) {
          const auto& r = *s.schedule;
          for (std::size_t i = 0; i < r.task_weights.size() && i < r.task_node_tests.size(); ++i) {
            estimated.push_back(r.task_weights[i]);
            effective.push_back(static_cast<double>(r.task_node_tests[i]));
          }
        }
        ++b.done;
        if (b.progress.terminal() || k + 1 == steps) {
          char line[200];
          std::snprintf(line, sizeof line, "%s: %s simulated on %d cores, step %d", sc.name.c_str(), v.name.c_str(), p, k);
          b.progress.update(b.done, line);
        }
      }
      Json record = {{"kind", "simulation"},
                     {"scene", sc.name},
                     {"method", v.name},
                     {"cores", p},
                     {"speedup", simulated.speedup()},
                     {"predicted_step_ms", simulated.predicted_ms()},
                     {"sequential_step_ms", sequential_ms}};
      if (!estimated.empty() && (p == 8 || !correlated)) {
        // Keep at most 4000 points for the figure (evenly spaced); r uses all of them.
        Json points = Json::array();
        const std::size_t stride = std::max<std::size_t>(1, estimated.size() / 4000);
        for (std::size_t i = 0; i < estimated.size(); i += stride) points.push_back({estimated[i], effective[i]});
        record["correlation"] = {
            {"cores", p}, {"pearson", pearson(estimated, effective)}, {"tasks", estimated.size()}, {"points", points}};
        correlated = true;
      }
      b.log.add(record);
    }
  }
}

/// Every measured run of one scene, in rounds: round r runs every configuration once, so that a
/// slow spell of a shared machine spreads over all of them instead of landing on one
/// configuration's repeats. Sequential comes first (the reference for the contact check); then
/// the machine's ceiling at each thread count, then the simulation.
void bench_scene(BenchRun& b, std::size_t si) {
  const World& world = *b.worlds[si];
  const Scene& sc = world.scene();
  std::vector<Config> configs;
  for (const Variant& v : b.variants) {
    for (const int t : v.method == Method::sequential ? std::vector<int>{1} : b.opt.threads)
      configs.push_back(Config{&v, t, 0.0});
  }
  std::vector<std::uint64_t> reference;
  for (int r = 0; r < b.opt.repeat; ++r) {
    for (Config& c : configs) {
      // A configuration not run yet is estimated at sequential's time (one thread, no calibration).
      const double estimate = c.last_ms > 0 ? c.last_ms : configs.front().last_ms;
      if (!b.fits(estimate / 1000.0,
                  sc.name + " round " + std::to_string(r + 1) + " " + c.variant->name + " x" + std::to_string(c.threads))) {
        return;
      }
      const std::optional<Json> record = measure_run(b, world, *c.variant, c.threads, r, reference);
      if (!record) return;
      c.last_ms = (*record)["total_ms"].get<double>();
      b.log.add(*record);
    }
  }
  const double sequential_s = configs.front().last_ms / 1000.0;
  b.sequential_s[si] = sequential_s;
  if (b.opt.ceiling) {
    for (const int t : b.opt.threads) {
      if (t < 2) continue;
      // Each copy loads and builds its own world, then all step at once.
      if (!b.fits(b.load_s[si] + 1.5 * sequential_s, sc.name + " ceiling at " + std::to_string(t) + " copies")) return;
      std::fprintf(stderr, "%s: the machine's ceiling, %d sequential copies at once\n", sc.name.c_str(), t);
      const std::vector<double> copy_ms = measure_ceiling(sc, t);  // cut short by a signal: not recorded
      if (b.interrupted_before(sc.name + " ceiling at " + std::to_string(t) + " copies")) return;
      b.log.add({{"kind", "ceiling"}, {"scene", sc.name}, {"copies", t}, {"copy_step_ms", copy_ms}});
    }
  }
  simulate_scene(b, world, sequential_s);
}

/// Timeline of one step (Gantt): exploitation vs hybrid on front_car (or the last scene), at the
/// highest measured thread count.
void record_gantt(BenchRun& b) {
  std::size_t si = b.worlds.size() - 1;
  for (std::size_t i = 0; i < b.worlds.size(); ++i) {
    if (b.worlds[i]->scene().name == "front_car") si = i;
  }
  // Two engines step half the scene each, at the most threads: less than one sequential run.
  if (!b.fits(b.sequential_s[si], "the timeline")) return;
  const World& world = *b.worlds[si];
  const int t = b.opt.threads.back();
  const int step = world.scene().steps / 2;
  Json gantt = {{"kind", "gantt"}, {"scene", world.scene().name}, {"threads", t}, {"step", step}, {"methods", Json::object()}};
  for (const char* name : {"exploitation", "hybrid"}) {
    EngineOptions o = engine_options(parse_variant(name), t);
    o.timeline = true;
    Engine engine(o);
    StepResult s;
    for (int k = 0; k <= step && !interrupted(); ++k) s = caliber::step(world, engine, k);  // hybrid needs the history
    Json spans = Json::array();
    for (const TaskSpan& span : s.schedule->timeline) {
      spans.push_back({span.thread, span.start_ms, span.end_ms,
                       span.phase == TaskSpan::Phase::stage      ? "stage"
                       : span.phase == TaskSpan::Phase::traverse ? "traverse"
                                                                 : "finalize"});
    }
    gantt["methods"][name] = {{"narrow_ms", s.narrow_ms}, {"spans", spans}};
  }
  if (b.interrupted_before("the timeline")) return;  // cut short: not recorded
  b.log.add(gantt);
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

/// results.json, the figures (scripts/plot_bench.py, matplotlib) and report.md in `out`, from the
/// bench's records.
void write_outputs(const std::vector<Json>& records, const std::filesystem::path& out, bool figures) {
  Json results = results_from_records(records);
  const auto json_path = out / "results.json";
  const auto write_json = [&] {
    OutputFile file(json_path.string(), "results.json");  // written whole, or not at all
    file.stream() << results.dump(1) << '\n';
    file.commit();
  };
  write_json();
  std::string figures_note = no_figures_note(figures);
  if (figures_note.empty()) {
    std::filesystem::path script;
    for (const auto& candidate :
         {program_dir() / ".." / "scripts" / "plot_bench.py", std::filesystem::path("scripts/plot_bench.py")}) {
      if (std::filesystem::exists(candidate)) {
        script = candidate;
        break;
      }
    }
    if (script.empty()) {
      figures_note = "Figures not drawn: scripts/plot_bench.py not found.";
    } else if (run_command(python() + " " + quote(script.string()) + " " + quote(out.string())) != 0) {
      figures_note = "Figures not drawn: `python3 scripts/plot_bench.py` failed (is python3-matplotlib installed?).";
    }
  }
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
  for (const std::string& figure : {std::string("correlation"), std::string("gantt")}) {
    names.insert(names.end(), {figure + ".png", figure + ".svg"});
  }
  for (const std::string& s : scene_names) names.insert(names.end(), {"speedup_" + s + ".png", "speedup_" + s + ".svg"});
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

int run_bench(BenchOptions opt) {
  // SIGINT and SIGTERM handled from before anything is created until the outputs are in place: the
  // bench stops after the step in progress and reports what it measured.
  const InterruptGuard interrupt;
  if (!opt.from_log.empty()) return report_from_log(opt);
  const Budget budget(opt.budget_s);  // counts from here: loading the scenes is part of the run
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
  std::vector<Variant> variants;
  for (const std::string& m : opt.methods) {
    Variant v = parse_variant(m);
    if (std::none_of(variants.begin(), variants.end(), [&](const Variant& u) { return u.name == v.name; }))
      variants.push_back(std::move(v));
  }
  // Sequential first, exactly once: the reference for every speed-up and every contact check.
  variants.erase(
      std::remove_if(variants.begin(), variants.end(), [](const Variant& v) { return v.method == Method::sequential; }),
      variants.end());
  variants.insert(variants.begin(), parse_variant("sequential"));
  // Every scene file parsed (and its meshes checked to exist) before anything is created on disk.
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
  if (opt.out.empty()) opt.out = "bench/results/" + machine_slug() + "/engine";
  if (std::filesystem::exists(opt.out) && !std::filesystem::is_directory(opt.out)) {
    throw Error(ErrorCode::bad_value, "--out", "'" + opt.out + "' exists and is not a folder");
  }
  const std::filesystem::path log_path =
      opt.log.empty() ? std::filesystem::path(opt.out) / "runs.jsonl" : std::filesystem::path(opt.log);
  // Nothing the bench writes may be one of its inputs (a --log naming a mesh emptied it): checked
  // before the folder is created or the log opened.
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
  BenchLog log(log_path);  // opened before the long work: an unwritable log fails now
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  // Load every scene first: bad input fails before any long work starts.
  std::vector<std::unique_ptr<World>> worlds;
  std::vector<double> load_s;
  for (Scene& scene : scenes) {
    const auto start = Clock::now();
    worlds.push_back(std::make_unique<World>(std::move(scene)));
    load_s.push_back(seconds_since(start));
  }
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
  std::printf("caliber-bench on %s\n%zu scene(s), %zu method(s), threads {", bench::machine_description().c_str(), worlds.size(),
              variants.size());
  for (std::size_t i = 0; i < opt.threads.size(); ++i) std::printf("%s%d", i ? ", " : "", opt.threads[i]);
  std::printf("}, %d repeat(s); results in %s, each run logged to %s as it ends\n", opt.repeat, opt.out.c_str(),
              log_path.c_str());
  std::fflush(stdout);

  Json header = {{"kind", "header"},
                 {"machine", bench::machine_description()},
                 {"cpu", bench::cpu_model()},
                 {"hardware_threads", cores},
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
  log.add(header);

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
  cmd->add_flag("!--no-figures", opt->figures, "Do not run scripts/plot_bench.py");
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
