// The engine: one traversal (narrow/traversal.h), several ways to cut and schedule it.
//   sequential    the initial tasks one after another on the calling thread
//   exploitation  a parallel loop over the initial tasks, one task per pair
//   stealing      every pair's CD tree split recursively into tasks down to a depth, then
//                 traversed depth first; oneTBB's scheduler steals the pieces
// Threads are reached only through parallel/executor.h (oneTBB, or std::thread for TSan).
// All of them end with the same per-pair finalization and the same reduction, so the contacts
// do not depend on the method or the thread count.

#include "caliber/engine.h"

#include <algorithm>
#include <numeric>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <queue>
#include <string>
#include <thread>

#include "caliber/error.h"
#include "narrow/pair_context.h"
#include "parallel/executor.h"
#include "narrow/traversal.h"
#include "tasks/calibration.h"
#include "tasks/weights.h"

namespace caliber {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

/// One worker's output for a step: candidates and work per pair, and its traversal stack.
struct WorkerSlots {
  narrow::TraversalScratch scratch;
  std::vector<std::vector<narrow::Candidate>> candidates;  ///< per pair
  std::vector<QueryStats> stats;                           ///< per pair
  std::vector<std::uint64_t> pieces;                       ///< stealing: node tests of each depth-first piece
  std::uint64_t split_node_tests = 0;                      ///< stealing: node tests above the cut-off

  void reset(std::size_t pairs) {
    candidates.resize(pairs);
    stats.assign(pairs, QueryStats{});
    for (auto& c : candidates) c.clear();
    pieces.clear();
    split_node_tests = 0;
  }
};

using Workers = parallel::PerThread<WorkerSlots>;

/// Optional record of who ran what when (EngineOptions::timeline), for Gantt charts.
struct Timeline {
  bool on = false;
  Clock::time_point origin;
  parallel::PerThread<std::vector<TaskSpan>> spans;

  /// Runs f(), recording its span on this thread when the timeline is on.
  template <class F>
  void record(TaskSpan::Phase phase, F&& f) {
    if (!on) {
      f();
      return;
    }
    const auto start = Clock::now();
    f();
    const auto end = Clock::now();
    const int thread = std::max(parallel::current_thread_index(), 0);
    spans.local().push_back(TaskSpan{thread, std::chrono::duration<double, std::milli>(start - origin).count(),
                                     std::chrono::duration<double, std::milli>(end - origin).count(), phase});
  }

  /// Starts a step: clears the spans and sets the time origin.
  void begin(bool enabled) {
    on = enabled;
    spans.for_each([](std::vector<TaskSpan>& s) { s.clear(); });
    origin = Clock::now();
  }

  /// All spans, sorted by thread then start.
  std::vector<TaskSpan> collect() {
    std::vector<TaskSpan> all;
    spans.for_each([&](const std::vector<TaskSpan>& s) { all.insert(all.end(), s.begin(), s.end()); });
    std::sort(all.begin(), all.end(), [](const TaskSpan& a, const TaskSpan& b) {
      return a.thread != b.thread ? a.thread < b.thread : a.start_ms < b.start_ms;
    });
    return all;
  }
};

/// This thread's slots, sized for `pairs` (a thread that joins mid-step starts with empty slots).
WorkerSlots& local_slots(Workers& workers, std::size_t pairs) {
  WorkerSlots& w = workers.local();
  if (w.stats.size() != pairs) w.reset(pairs);
  return w;
}

/// Per pair, in parallel: `start` seeds the pair's candidates and counts (work done outside the
/// workers' slots), every worker's slots are added, and the pair goes through the one finalization.
template <class Start>
void finalize_pairs(const std::vector<narrow::PairContext>& contexts, Workers& workers, std::vector<QueryResult>& results,
                    Timeline& timeline, Start start) {
  const std::size_t n = contexts.size();
  const std::vector<WorkerSlots*> slots = workers.all();
  // A pair's finalization costs about its candidate count: most candidates first, to the next free
  // thread (ties by pair index; the order changes who runs what, never the results).
  std::vector<std::size_t> candidates(n, 0), order(n);
  for (const WorkerSlots* w : slots) {
    if (w->stats.size() != n) continue;
    for (std::size_t i = 0; i < n; ++i) candidates[i] += w->candidates[i].size();
  }
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return candidates[x] > candidates[y]; });
  parallel::for_each_in_order(n, [&](std::size_t k) {
    const std::size_t i = order[k];
    timeline.record(TaskSpan::Phase::finalize, [&] {
      std::vector<narrow::Candidate> all;
      QueryStats stats;
      start(i, all, stats);
      all.reserve(all.size() + candidates[i]);
      for (const WorkerSlots* w : slots) {
        if (w->stats.size() != n) continue;
        all.insert(all.end(), w->candidates[i].begin(), w->candidates[i].end());
        stats.node_tests += w->stats[i].node_tests;
        stats.leaf_tests += w->stats[i].leaf_tests;
      }
      results[i] = narrow::finalize(contexts[i], all, stats, /*parallel=*/true);
    });
  });
}

}  // namespace

std::string_view to_string(Method method) {
  switch (method) {
    case Method::sequential: return "sequential";
    case Method::exploitation: return "exploitation";
    case Method::stealing: return "stealing";
    case Method::aposteriori: return "aposteriori";
    case Method::apriori: return "apriori";
    case Method::hybrid: return "hybrid";
  }
  return "unknown";
}

Method parse_method(std::string_view name) {
  if (name == "sequential") return Method::sequential;
  if (name == "exploitation") return Method::exploitation;
  if (name == "stealing") return Method::stealing;
  if (name == "aposteriori") return Method::aposteriori;
  if (name == "apriori") return Method::apriori;
  if (name == "hybrid") return Method::hybrid;
  throw Error(ErrorCode::bad_value, "method",
              "unknown method '" + std::string(name) +
                  "' (expected sequential, exploitation, stealing, aposteriori, apriori or hybrid)");
}

struct Engine::Impl {
  explicit Impl(int threads) : executor(threads) {}
  parallel::Executor executor;
  Workers workers;
  /// Temporal state: node tests of each object pair at its last step. Changes only how work is cut.
  std::map<Task, std::uint64_t> history;
  /// A posteriori: the triangle pairs each object pair reported at its last step.
  std::map<Task, std::vector<TrianglePair>> reported;
  /// Hybrid with node history: node tests of the subtrees the weight-driven stage popped, per pair.
  std::map<Task, tasks::NodeCounts> node_counts;
  /// Who ran what when, this step (EngineOptions::timeline).
  Timeline timeline;
};

Engine::Engine(const World& world, const EngineOptions& options) : mWorld(world), mOptions(options) {
  if (mOptions.threads < 0 || mOptions.threads > 1024) {
    throw Error(ErrorCode::bad_value, "threads", "must be between 1 and 1024 (0: one per hardware thread)");
  }
  if (mOptions.stealing_depth < 0) throw Error(ErrorCode::bad_value, "stealing depth", "must be >= 0");
  if (!(mOptions.beta > 0.0) || !std::isfinite(mOptions.beta)) throw Error(ErrorCode::bad_value, "beta", "must be a finite number > 0");
  if (!(mOptions.epsilon >= 0.0) || !std::isfinite(mOptions.epsilon)) {
    throw Error(ErrorCode::bad_value, "epsilon", "must be a finite number >= 0");
  }
  if (mOptions.taboo_cap < 1) throw Error(ErrorCode::bad_value, "taboo cap", "must be >= 1");
  if (mOptions.threads == 0) mOptions.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (mOptions.method == Method::sequential) mOptions.threads = 1;
  mImpl = std::make_unique<Impl>(mOptions.threads);
}

Engine::~Engine() = default;

int Engine::threads() const { return mOptions.threads; }

namespace {

/// Stealing: tests CD-tree node n of pair `pair` and, above the cut-off depth, spawns one task per
/// child; from the cut-off down, one depth-first traversal. The node tests made are exactly those
/// of a single depth-first traversal of the whole tree.
void steal(const narrow::PairContext& ctx, std::size_t pair, std::size_t pairs, narrow::NodePair n, int depth, int cutoff,
           Workers& workers, Timeline& timeline) {
  {
    WorkerSlots& w = local_slots(workers, pairs);
    if (depth >= cutoff) {
      timeline.record(TaskSpan::Phase::traverse, [&] {
        const std::uint64_t before = w.stats[pair].node_tests;
        narrow::traverse_depth_first(ctx, n, w.scratch, w.candidates[pair], w.stats[pair]);
        w.pieces.push_back(w.stats[pair].node_tests - before);
      });
      return;
    }
    ++w.stats[pair].node_tests;
    ++w.split_node_tests;
    if (!ctx.node_test(n.a, n.b)) return;
    const BvhNode& a = ctx.a().nodes[n.a];
    const BvhNode& b = ctx.b().nodes[n.b];
    if (a.is_leaf() && b.is_leaf()) {
      ++w.stats[pair].leaf_tests;
      ctx.leaf_test(a.index, b.index, w.candidates[pair]);
      return;
    }
  }
  narrow::NodePair kids[4];
  const int count = narrow::cd_children(ctx.a(), ctx.b(), n, kids);
  parallel::TaskGroup group;
  for (int i = 1; i < count; ++i) {
    const narrow::NodePair kid = kids[i];
    group.run([&ctx, pair, pairs, kid, depth, cutoff, &workers, &timeline] {
      steal(ctx, pair, pairs, kid, depth + 1, cutoff, workers, timeline);
    });
  }
  steal(ctx, pair, pairs, kids[0], depth + 1, cutoff, workers, timeline);
  group.wait();
}

}  // namespace

void Engine::run_calibrated(const std::vector<Task>& tasks, const std::vector<narrow::PairContext>& contexts,
                            std::vector<QueryResult>& results, ScheduleRecord& record) {
  const std::size_t n = tasks.size();
  const int threads = mOptions.threads;
  auto& workers = mImpl->workers;  // already reset for this step by Engine::step
  auto phase = Clock::now();

  // 1. Weights of the initial tasks. A priori: the root's geometric estimate. Hybrid: the pair's node
  //    tests at the previous step, and node weights rescaled by N(t-1) / w~root(t); a pair with no
  //    history is rescaled by the ratio measured over the pairs that have one (1 if none has).
  std::vector<double> root(n), weight(n), scale(n, 1.0);
  parallel::parallel_for_each(0, n, [&](std::size_t i) { root[i] = tasks::apriori_weight(contexts[i], {0, 0}); });
  if (mOptions.method == Method::hybrid || mOptions.method == Method::aposteriori) {
    double measured = 0.0, estimated = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto it = mImpl->history.find(tasks[i]);
      if (it != mImpl->history.end() && it->second > 0) {
        measured += static_cast<double>(it->second);
        estimated += root[i];
      }
    }
    const double fallback = estimated > 0.0 ? measured / estimated : 1.0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto it = mImpl->history.find(tasks[i]);
      scale[i] = (it != mImpl->history.end() && it->second > 0) ? static_cast<double>(it->second) / root[i] : fallback;
    }
  }
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    weight[i] = scale[i] * root[i];
    total += weight[i];
  }
  const double omega = tasks::caliber_threshold(total, mOptions.beta, threads);
  const double eps = mOptions.epsilon * omega;
  record.omega = omega;

  // 2. Keep, split or cart each initial task; the weight-driven stage of the split ones in parallel.
  std::vector<tasks::RunTask> run;
  std::vector<tasks::Root> cart;
  std::vector<std::size_t> to_split;
  for (std::size_t i = 0; i < n; ++i) {
    const tasks::Root whole{static_cast<std::uint32_t>(i), narrow::NodePair{0, 0}, false, weight[i]};
    switch (tasks::classify(weight[i], omega, eps)) {
      case tasks::Verdict::keep: run.push_back(tasks::RunTask{{whole}, weight[i]}); ++record.kept; break;
      case tasks::Verdict::cart: cart.push_back(whole); break;
      case tasks::Verdict::split: to_split.push_back(i); break;
    }
  }
  record.split = to_split.size();
  std::vector<tasks::SplitResult> splits(to_split.size());
  std::vector<narrow::Taboo> taboos;
  if (mOptions.method == Method::aposteriori) {
    // Sub-task roots from last step's summary tree; nothing is tested here. A task without
    // reported pairs last step cannot be split (the metric's known blind spot) and runs whole.
    std::vector<tasks::PosterioriSplit> chosen(to_split.size());
    parallel::parallel_for_each(0, to_split.size(), [&](std::size_t s) {
      const std::size_t i = to_split[s];
      const auto it = mImpl->reported.find(tasks[i]);
      if (it == mImpl->reported.end()) return;
      const auto summary = tasks::build_summary(contexts[i].a(), contexts[i].b(), it->second);
      chosen[s] = tasks::split_aposteriori(summary, static_cast<std::uint32_t>(i), weight[i], omega, eps,
                                           static_cast<std::size_t>(mOptions.taboo_cap));
      chosen[s].rest = chosen[s].taboo.empty() ? weight[i] : chosen[s].rest;
    });
    for (std::size_t s = 0; s < to_split.size(); ++s) {
      const auto pair = static_cast<std::uint32_t>(to_split[s]);
      tasks::PosterioriSplit& ps = chosen[s];
      tasks::Root original{pair, narrow::NodePair{0, 0}, false, ps.rest};
      if (!ps.taboo.empty()) {
        original.taboo = static_cast<std::int32_t>(taboos.size());
        narrow::Taboo taboo;
        taboo.nodes = ps.taboo;
        taboo.reached.assign(ps.taboo.size(), 0);
        taboos.push_back(std::move(taboo));
        for (std::vector<tasks::Root>* list : {&ps.roots, &ps.cart}) {
          for (tasks::Root& r : *list) {
            r.owner = original.taboo;
            r.slot = taboos.back().find(r.node);
          }
        }
      }
      run.push_back(tasks::RunTask{{original}, original.weight});
      for (const tasks::Root& r : ps.roots) run.push_back(tasks::RunTask{{r}, r.weight});
      cart.insert(cart.end(), ps.cart.begin(), ps.cart.end());
      record.taboo += ps.taboo.size();
    }
    to_split.clear();
    splits.clear();
  } else {
    const bool history = mOptions.method == Method::hybrid && mOptions.node_history;
    parallel::parallel_for_each(0, to_split.size(), [&](std::size_t s) {
      const std::size_t i = to_split[s];
      const tasks::NodeCounts* measured = nullptr;
      if (history) {
        const auto it = mImpl->node_counts.find(tasks[i]);
        if (it != mImpl->node_counts.end()) measured = &it->second;
      }
      mImpl->timeline.record(TaskSpan::Phase::stage, [&] {
        splits[s] = tasks::split_task(contexts[i], static_cast<std::uint32_t>(i), weight[i], scale[i], omega, eps, measured);
      });
    });
  }
  for (tasks::SplitResult& s : splits) {
    for (const tasks::Root& r : s.roots) run.push_back(tasks::RunTask{{r}, r.weight});
    cart.insert(cart.end(), s.cart.begin(), s.cart.end());
    record.stage_node_tests += s.stats.node_tests;
    record.stage_task_node_tests.push_back(s.stats.node_tests);
    record.queue_peak = std::max(record.queue_peak, s.queue_peak);
  }
  record.carted = cart.size();
  for (tasks::RunTask& t : tasks::merge_cart(std::move(cart), omega)) run.push_back(std::move(t));
  // Heaviest first, so that the parallel loop does not end on a heavy straggler.
  std::stable_sort(run.begin(), run.end(), [](const tasks::RunTask& x, const tasks::RunTask& y) { return x.weight > y.weight; });
  record.generated = run.size();

  record.calibrate_ms = ms_since(phase);
  phase = Clock::now();
  // 3. Every run-time task depth first, by one thread; then per pair, the same finalization.
  record.task_node_tests.assign(run.size(), 0);
  record.task_weights.resize(run.size());
  std::vector<std::size_t> split_of(n, SIZE_MAX);
  for (std::size_t s = 0; s < to_split.size(); ++s) split_of[to_split[s]] = s;
  std::vector<std::vector<std::uint64_t>> stage_root_tests(splits.size());
  for (std::size_t s = 0; s < splits.size(); ++s) stage_root_tests[s].assign(splits[s].stage.size(), 0);
  std::vector<std::vector<std::uint64_t>> sub_tests(taboos.size());
  for (std::size_t t = 0; t < taboos.size(); ++t) sub_tests[t].assign(taboos[t].nodes.size(), 0);
  // Heaviest first, each to the next free thread: the list schedule the simulation replays.
  parallel::for_each_in_order(run.size(), [&](std::size_t t) {
    mImpl->timeline.record(TaskSpan::Phase::traverse, [&] {
      WorkerSlots& w = local_slots(workers, n);
      std::uint64_t tests = 0;
      for (const tasks::Root& root_ref : run[t].roots) {
        QueryStats& stats = w.stats[root_ref.pair];
        const std::uint64_t before = stats.node_tests;
        narrow::traverse_depth_first(contexts[root_ref.pair], root_ref.node, w.scratch, w.candidates[root_ref.pair], stats,
                                     root_ref.tested, root_ref.taboo >= 0 ? &taboos[root_ref.taboo] : nullptr);
        tests += stats.node_tests - before;
        if (root_ref.owner >= 0) sub_tests[root_ref.owner][root_ref.slot] = stats.node_tests - before;
        if (root_ref.stage >= 0) stage_root_tests[split_of[root_ref.pair]][root_ref.stage] = stats.node_tests - before;
      }
      record.task_node_tests[t] = tests;
      record.task_weights[t] = run[t].weight;
    });
  });
  record.traverse_ms = ms_since(phase);
  phase = Clock::now();
  for (std::size_t t = 0; t < taboos.size(); ++t) {
    for (std::size_t k = 0; k < taboos[t].nodes.size(); ++k) {
      if (!taboos[t].reached[k]) record.taboo_unreached_node_tests += sub_tests[t][k];
    }
  }
  if (mOptions.method == Method::hybrid && mOptions.node_history) {
    for (std::size_t s = 0; s < splits.size(); ++s) {
      mImpl->node_counts[tasks[to_split[s]]] = tasks::subtree_counts(splits[s].stage, stage_root_tests[s]);
    }
  }
  finalize_pairs(contexts, workers, results, mImpl->timeline, [&](std::size_t i, std::vector<narrow::Candidate>& all, QueryStats& stats) {
    if (split_of[i] == SIZE_MAX) return;
    const tasks::SplitResult& s = splits[split_of[i]];
    all = s.candidates;
    stats = s.stats;
  });
  record.finalize_ms = ms_since(phase);
}

double list_schedule_makespan(const std::vector<std::uint64_t>& costs, int cores) {
  if (cores < 1) throw Error(ErrorCode::bad_value, "cores", "must be >= 1");
  std::priority_queue<double, std::vector<double>, std::greater<>> loads;
  for (int c = 0; c < cores; ++c) loads.push(0.0);
  double makespan = 0.0;
  for (const std::uint64_t cost : costs) {
    const double load = loads.top() + static_cast<double>(cost);
    loads.pop();
    loads.push(load);
    makespan = std::max(makespan, load);
  }
  return makespan;
}

double simulated_speedup(const StepResult& step, Method method, int cores) {
  const ScheduleRecord& r = step.schedule;
  const double total = static_cast<double>(step.stats.node_tests);
  if (total <= 0.0 || method == Method::sequential) return 1.0;
  double makespan = 0.0;
  switch (method) {
    case Method::sequential: return 1.0;
    case Method::exploitation: makespan = list_schedule_makespan(r.task_node_tests, cores); break;
    case Method::stealing:
      makespan = list_schedule_makespan(r.task_node_tests, cores) + static_cast<double>(r.split_node_tests) / cores;
      break;
    case Method::aposteriori:
    case Method::apriori:
    case Method::hybrid:
      makespan = list_schedule_makespan(r.stage_task_node_tests, cores) + list_schedule_makespan(r.task_node_tests, cores);
      break;
  }
  return makespan > 0.0 ? total / makespan : 1.0;
}

StepResult Engine::step(int k) {
  StepResult out;
  out.step = k;
  out.time = k * mWorld.scene().dt;
  auto start = Clock::now();
  const std::vector<Pose> poses = mWorld.poses_at(k);
  const std::vector<Task> tasks = mWorld.broad_phase(poses);
  out.broad_ms = ms_since(start);

  start = Clock::now();
  std::vector<narrow::PairContext> contexts;
  contexts.reserve(tasks.size());
  for (const Task& t : tasks) {
    contexts.emplace_back(mWorld.model(t.a), poses[t.a], mWorld.model(t.b), poses[t.b], mWorld.request());
  }
  std::vector<QueryResult> results(tasks.size());
  const auto n = tasks.size();
  auto& workers = mImpl->workers;
  workers.for_each([n](WorkerSlots& w) { w.reset(n); });
  auto& timeline = mImpl->timeline;
  timeline.begin(mOptions.timeline);
  const auto run_pair = [&](std::size_t i) {
    timeline.record(TaskSpan::Phase::traverse, [&] {
      WorkerSlots& w = local_slots(workers, n);
      narrow::traverse_depth_first(contexts[i], narrow::NodePair{0, 0}, w.scratch, w.candidates[i], w.stats[i]);
      results[i] = narrow::finalize(contexts[i], w.candidates[i], w.stats[i]);
    });
  };

  switch (mOptions.method) {
    case Method::sequential:
      for (std::size_t i = 0; i < n; ++i) run_pair(i);
      break;
    case Method::exploitation:
      mImpl->executor.execute([&] {
        parallel::parallel_for(0, n, 1, [&](std::size_t lo, std::size_t hi) {
          for (std::size_t i = lo; i != hi; ++i) run_pair(i);
        });
      });
      break;
    case Method::stealing: {
      mImpl->executor.execute([&] {
        parallel::TaskGroup group;
        for (std::size_t i = 0; i < n; ++i) {
          group.run([&, i] { steal(contexts[i], i, n, narrow::NodePair{0, 0}, 0, mOptions.stealing_depth, workers, timeline); });
        }
        group.wait();
        out.schedule.traverse_ms = ms_since(start);
        const auto finalize_start = Clock::now();
        finalize_pairs(contexts, workers, results, timeline, [](std::size_t, std::vector<narrow::Candidate>&, QueryStats&) {});
        out.schedule.finalize_ms = ms_since(finalize_start);
        workers.for_each([&](const WorkerSlots& w) {
          out.schedule.task_node_tests.insert(out.schedule.task_node_tests.end(), w.pieces.begin(), w.pieces.end());
          out.schedule.split_node_tests += w.split_node_tests;
        });
        // Pieces were collected per worker; sort them so the record does not depend on who ran what.
        std::sort(out.schedule.task_node_tests.begin(), out.schedule.task_node_tests.end(), std::greater<>());
      });
      break;
    }
    case Method::aposteriori:
    case Method::apriori:
    case Method::hybrid:
      mImpl->executor.execute([&] { run_calibrated(tasks, contexts, results, out.schedule); });
      break;
  }
  if (mOptions.method == Method::aposteriori) {
    for (std::size_t i = 0; i < n; ++i) mImpl->reported[tasks[i]] = results[i].pairs;
  }
  workers.for_each([&](const WorkerSlots& w) {
    if (w.stats.size() != n) return;
    std::uint64_t tests = 0;
    for (const QueryStats& st : w.stats) tests += st.node_tests;
    if (tests > 0) out.schedule.thread_node_tests.push_back(tests);
  });
  std::sort(out.schedule.thread_node_tests.begin(), out.schedule.thread_node_tests.end(), std::greater<>());
  if (mOptions.method == Method::sequential || mOptions.method == Method::exploitation) {
    for (const QueryResult& r : results) out.schedule.task_node_tests.push_back(r.stats.node_tests);
  }
  for (std::size_t i = 0; i < n; ++i) mImpl->history[tasks[i]] = results[i].stats.node_tests;
  if (mOptions.timeline) out.schedule.timeline = timeline.collect();
  out.narrow_ms = ms_since(start);

  start = Clock::now();
  gather_step(tasks, results, out);
  out.reduce_ms = ms_since(start);
  return out;
}

}  // namespace caliber
