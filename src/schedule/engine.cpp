// The engine: one traversal (narrow/traversal.h), several ways to cut and schedule it.
//   sequential    the pairs one after another, on one thread          (plan: whole pairs)
//   exploitation  the pairs handed out in order to the threads         (plan: whole pairs)
//   aposteriori, apriori, hybrid   task calibration                    (plan: plans/plan.h)
//   stealing      every pair's CD tree split recursively into jobs     (its own runner)
// Every plan goes through one runner (schedule/runner.h); threads are reached only through
// parallel/executor.h. All methods end with the same per-pair finalization and the same
// reduction, so the contacts do not depend on the method or the thread count.

#include "caliber/engine.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <new>
#include <numeric>
#include <tuple>
#include <string>
#include <thread>

#include "caliber/error.h"
#include "caliber/profile.h"
#include "mesh/pose_check.h"
#include "narrow/finalize.h"
#include "narrow/pair_context.h"
#include "parallel/executor.h"
#include "schedule/engine_impl.h"
#include "schedule/runner.h"
#include "schedule/workers.h"
#include "plans/plan.h"
#include "plans/validate.h"
#include "util/assert.h"
#include "util/timing.h"

namespace caliber {

std::string_view to_string(Method method) {
  switch (method) {
    case Method::sequential:
      return "sequential";
    case Method::exploitation:
      return "exploitation";
    case Method::stealing:
      return "stealing";
    case Method::aposteriori:
      return "aposteriori";
    case Method::apriori:
      return "apriori";
    case Method::hybrid:
      return "hybrid";
  }
  return "unknown";
}

Method parse_method(std::string_view name) {
  for (const Method m :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    if (name == to_string(m)) return m;
  }
  throw Error(
      ErrorCode::bad_value, "method",
      "unknown method '" + std::string(name) + "' (expected sequential, exploitation, stealing, aposteriori, apriori or hybrid)");
}

void validate_frame(const Frame& frame) {
  const std::size_t n = frame.models.size();
  if (frame.poses.size() != n) {
    throw Error(ErrorCode::bad_argument, "frame",
                std::to_string(n) + " models but " + std::to_string(frame.poses.size()) + " poses (one per object)");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!frame.models[i]) throw Error(ErrorCode::bad_argument, "frame", "object " + std::to_string(i) + " has no model");
    // Checked here, once per object: the contexts are then made in parallel and cannot throw.
    try {
      validate_pose_named(frame.poses[i], [&] { return "pose of object " + std::to_string(i); });
    } catch (const Error& e) {
      throw Error(e.code(), "frame", e.what());
    }
  }
  for (std::size_t k = 0; k < frame.pairs.size(); ++k) {
    const ObjectPair& p = frame.pairs[k];
    if (p.a >= p.b || p.b >= n) {
      throw Error(ErrorCode::bad_argument, "frame",
                  "pair " + std::to_string(k) + " (" + std::to_string(p.a) + ", " + std::to_string(p.b) +
                      ") must name two objects a < b < " + std::to_string(n));
    }
    if (k > 0 && !(frame.pairs[k - 1] < p)) {
      throw Error(ErrorCode::bad_argument, "frame", "pairs must be sorted and distinct (pair " + std::to_string(k) + ")");
    }
    // A contact query needs both models built with adjacency: refused before any work (the names
    // made only then).
    const Model& ma = *frame.models[p.a];
    const Model& mb = *frame.models[p.b];
    if (frame.request.kind == QueryKind::contact && (!ma.has_adjacency() || !mb.has_adjacency())) {
      narrow::check_contact_models(frame.request, ma, mb, "object " + std::to_string(p.a) + "'s model",
                                   "object " + std::to_string(p.b) + "'s model");
    }
  }
  validate_request(frame.request);  // a distance query may be unbounded: the frame names its pairs
}

Engine::Engine(const EngineOptions& options) : mOptions(options) {
  if (mOptions.threads < 0 || mOptions.threads > 1024) {
    throw Error(ErrorCode::bad_value, "threads", "must be between 0 and 1024 (0: the arena caliber is called from)");
  }
  if (mOptions.plan_threads < 0 || mOptions.plan_threads > 1024) {
    throw Error(ErrorCode::bad_value, "plan threads", "must be between 1 and 1024 (0: the engine's threads)");
  }
  if (mOptions.stealing_depth < 0) throw Error(ErrorCode::bad_value, "stealing depth", "must be >= 0");
  if (!(mOptions.beta > 0.0) || !std::isfinite(mOptions.beta))
    throw Error(ErrorCode::bad_value, "beta", "must be a finite number > 0");
  if (!(mOptions.epsilon >= 0.0) || !std::isfinite(mOptions.epsilon)) {
    throw Error(ErrorCode::bad_value, "epsilon", "must be a finite number >= 0");
  }
  if (mOptions.taboo_cap < 1) throw Error(ErrorCode::bad_value, "taboo cap", "must be >= 1");
  mImpl = std::make_unique<Impl>(mOptions.method == Method::sequential ? 1 : mOptions.threads,
                                 mOptions.method == Method::sequential ? nullptr : mOptions.host);
}

Engine::~Engine() = default;

int Engine::threads() const { return mImpl->executor.threads(); }

void Engine::forget() {
  const schedule::OneCallAtATime hold(mImpl->busy, "forget");
  mImpl->history = plans::History{};
  mImpl->broad = broad::State{};
}

void Engine::find_pairs(Frame& frame, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored) {
  const schedule::OneCallAtATime hold(mImpl->busy, "find_pairs");
  validate_request(frame.request);
  if (frame.request.kind == QueryKind::distance && frame.request.tolerance == kUnbounded) {
    throw Error(ErrorCode::bad_value, "tolerance",
                "a distance query without one reaches every pair: find_pairs needs a tolerance to bound its reach");
  }
  mImpl->executor.execute(
      [&] { broad::find_pairs(mImpl->broad, frame.models, frame.poses, reach(frame.request), fixed, ignored, frame.pairs); });
}

namespace {

/// Below this many counts (threads x pairs) or pairs, a step's bookkeeping runs on the calling
/// thread: handing it to the engine's threads costs more than it saves.
constexpr std::size_t kParallelSums = 1u << 14;

/// Empties a record, its vectors keeping their storage (no allocation once they have grown).
void reset_keeping_storage(ScheduleRecord& r) {
  ScheduleRecord fresh;
  const auto keep = [](auto& from, auto& to) {
    from.clear();
    to = std::move(from);
  };
  keep(r.stage_pair_node_tests, fresh.stage_pair_node_tests);
  keep(r.stage_levels, fresh.stage_levels);
  keep(r.stage_level_pair, fresh.stage_level_pair);
  keep(r.stage_serial_ms, fresh.stage_serial_ms);
  keep(r.task_node_tests, fresh.task_node_tests);
  keep(r.task_weights, fresh.task_weights);
  keep(r.thread_node_tests, fresh.thread_node_tests);
  keep(r.timeline, fresh.timeline);
  keep(r.task_roots, fresh.task_roots);
  r = std::move(fresh);
}

/// After a step: what the temporal methods keep of each pair for the next one.
void remember(const EngineOptions& options, const std::vector<ObjectPair>& pairs, const std::vector<QueryResult>& results,
              const plans::Plan& plan, const std::vector<std::vector<std::uint64_t>>& stage_root_tests, plans::History& history) {
  // Only what the method reads next step: the other methods keep nothing per pair.
  if (options.method != Method::hybrid && options.method != Method::aposteriori && options.method != Method::stealing) return;
  history.node_tests.reset(pairs);
  for (std::size_t i = 0; i < pairs.size(); ++i) history.node_tests.value(i) = results[i].stats.node_tests;
  if (options.method == Method::aposteriori) {
    history.reported.reset(pairs);
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      std::vector<TrianglePair>& reported = history.reported.value(i);
      reported.clear();
      for (const Contact& c : results[i].contacts) reported.push_back(TrianglePair{c.tri_a, c.tri_b});
    }
  }
  if (options.method == Method::hybrid && options.node_history) {
    history.node_counts.clear();
    for (std::size_t s = 0; s < plan.splits.size(); ++s) {
      history.node_counts[pairs[plan.split_pairs[s]]] = plans::subtree_counts(plan.splits[s].stage, stage_root_tests[s]);
    }
  }
}

}  // namespace

schedule::PairsRun Engine::Impl::run_pairs(const EngineOptions& options, Method method, const std::vector<ObjectPair>& pairs,
                                           const QueryRequest& request, const plans::History& plan_history,
                                           const std::function<void(std::size_t, void*)>& make, std::vector<QueryResult>& results,
                                           ScheduleRecord& record, std::span<const double> nearest) {
  const std::size_t n = pairs.size();
  results.assign(n, QueryResult{});
  schedule::StepState state{{}, workers, timeline, results, options.threads > 1, nullptr, {}, pairs.data(), ++runs};
  // A limit's count, or a distance query's nearest so far, shared by the pieces of a split pair.
  std::unique_ptr<narrow::PairShared[]> shared;
  if (request.max_pairs != 0 || request.kind == QueryKind::distance) {
    shared = std::make_unique<narrow::PairShared[]>(n);
    for (std::size_t i = 0; i < n; ++i) {
      shared[i].max = request.max_pairs;
      if (!nearest.empty()) shared[i].nearest.store(nearest[i], std::memory_order_relaxed);
    }
    state.shared = shared.get();
  }
  schedule::PairsRun run;
  const int cut_threads = options.plan_threads > 0 ? options.plan_threads : options.threads;
  executor.execute([&] {
    // The contexts are made on the executor's threads, inside the call's first parallel region.
    state.contexts = contexts.build(n, make);
    if (method == Method::stealing) {
      schedule::run_stealing(options.stealing_depth, cut_threads, pairs, plan_history, state, record);
    } else {
      const auto planning = util::Clock::now();
      // Cut for one thread, the calibrated methods have nothing to balance either: a task per pair.
      if (method == Method::sequential || method == Method::exploitation || cut_threads <= 1) {
        run.plan = plans::plan_pairs(n);
      } else {
        run.plan = plans::plan_calibrated(
            options, pairs, state.contexts, plan_history,
            [&](std::size_t pair, const std::function<void()>& stage) { timeline.record(TaskSpan::Phase::stage, pair, stage); });
      }
      record.calibrate_ms = util::ms_since(planning);
      CALIBER_ASSERT(plans::plan_problem(run.plan, n).empty(), "a plan keeps its invariants (plans/validate.h)");
      run.stage_root_tests = schedule::run_plan(run.plan, state, record);
    }
    // Each thread's node tests: its slots summed, in parallel when there are many (threads x pairs
    // counts in all; a job per thread costs more than a few thousand additions).
    const std::vector<schedule::WorkerSlots*> slots = workers.all();
    std::vector<std::uint64_t> tests(slots.size(), 0);
    const auto sum = [&](std::size_t k) {
      if (!state.current(*slots[k])) return;
      for (const QueryStats& st : slots[k]->stats) tests[k] += st.node_tests;
    };
    if (slots.size() * n < kParallelSums) {
      for (std::size_t k = 0; k < slots.size(); ++k) sum(k);
    } else {
      parallel::parallel_for_each(0, slots.size(), sum);
    }
    for (const std::uint64_t t : tests) {
      if (t > 0) record.thread_node_tests.push_back(t);
    }
    std::sort(record.thread_node_tests.begin(), record.thread_node_tests.end(), std::greater<>());
  });
  run.candidates = std::move(state.candidates);
  return run;
}

StepResult Engine::step(const Frame& frame) {
  const schedule::OneCallAtATime hold(mImpl->busy, "step");
  validate_frame(frame);
  StepResult out;
  const auto start = util::Clock::now();
  std::vector<QueryResult> results;
  mImpl->timeline.begin(mOptions.timeline);
  // The work is cut for the threads this step really has (the host's arena and limit decide).
  EngineOptions options = mOptions;
  options.threads = mImpl->executor.threads();
  // The runners always keep their record (the engine's own bookkeeping, in storage reused from step
  // to step); it is handed out only when asked for.
  const bool profile = mOptions.profile || mOptions.timeline;
  std::shared_ptr<ScheduleRecord> handed = profile ? std::make_shared<ScheduleRecord>() : nullptr;
  if (!profile) reset_keeping_storage(mImpl->record);
  ScheduleRecord& record = profile ? *handed : mImpl->record;
  record.kind = frame.request.kind;
  const auto make = [&frame](std::size_t i, void* where) {
    const ObjectPair& t = frame.pairs[i];
    new (where) narrow::PairContext(*frame.models[t.a], frame.poses[t.a], *frame.models[t.b], frame.poses[t.b], frame.request,
                                    narrow::PairContext::Validated{});  // validate_frame checked them
  };
  const schedule::PairsRun run =
      mImpl->run_pairs(options, mOptions.method, frame.pairs, frame.request, mImpl->history, make, results, record);
  remember(mOptions, frame.pairs, results, run.plan, run.stage_root_tests, mImpl->history);
  out.narrow_ms = util::ms_since(start);
  // After the clock: gathering and sorting the spans is the instrument's cost, not the step's (the
  // timed prediction would count it serial).
  if (mOptions.timeline) record.timeline = mImpl->timeline.collect();

  const auto reduce = util::Clock::now();
  // (On the engine's threads only when there are pairs enough to share out.)
  if (frame.pairs.size() < kParallelSums) {
    schedule::gather_step(frame.pairs, results, run.candidates, out);
  } else {
    mImpl->executor.execute([&] { schedule::gather_step(frame.pairs, results, run.candidates, out); });
  }
  CALIBER_ASSERT(std::is_sorted(out.contacts.begin(), out.contacts.end(),
                                [](const Contact& x, const Contact& y) {
                                  return std::tie(x.object_a, x.object_b, x.tri_a, x.tri_b) <
                                         std::tie(y.object_a, y.object_b, y.tri_a, y.tri_b);
                                }),
                 "a step's contacts are sorted by objects, then triangles");
  CALIBER_ASSERT(std::accumulate(record.task_node_tests.begin(), record.task_node_tests.end(), std::uint64_t{0}) +
                         record.stage_node_tests + record.split_node_tests ==
                     out.stats.node_tests,
                 "node tests are conserved: the units the schedule ran add up to the pairs' totals");
  out.reduce_ms = util::ms_since(reduce);
  out.schedule = std::move(handed);
  return out;
}

}  // namespace caliber
