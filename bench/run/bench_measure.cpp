// caliber-bench's measurements (bench_measure.h): each run on a fresh engine, checked against the
// sequential reference and logged as it ends; the machine's ceiling; the load-balance simulation.

#include "bench_measure.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <numeric>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "caliber/profile.h"
#include "caliber/scene.h"
#include "run_stats.h"

namespace caliber::cli {
namespace {

using Json = nlohmann::json;

/// One scene x method x thread count, and its runs so far (the last one estimates the next).
struct Config {
  const Variant* variant;
  int threads;
  double last_ms = 0.0;
};

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

EngineOptions engine_options(const Variant& v, int threads) {
  EngineOptions o;
  o.profile = true;  // the bench reports every step's schedule
  o.method = v.method;
  o.node_history = v.node_history;
  o.threads = threads;
  return o;
}

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
               {"pairs_per_step", stats.mean_pairs()},
               {"distinct_pairs", stats.distinct_pairs()},
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

}  // namespace

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

}  // namespace caliber::cli
