// The load-balance simulation: what a step's recorded work units predict on P virtual cores, in
// node tests (a node test taken to cost the same everywhere) or in measured time per piece. It
// predicts; it does not measure.

#include <algorithm>
#include <functional>
#include <queue>
#include <string>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/profile.h"
#include "narrow/finalize.h"

namespace caliber {

namespace {

/// The step's schedule; an Error when the step was run without EngineOptions::profile.
const ScheduleRecord& schedule_of(const StepResult& step) {
  if (!step.schedule) {
    throw Error(ErrorCode::bad_argument, "load-balance simulation",
                "the step has no schedule (run it with EngineOptions::profile on)");
  }
  return *step.schedule;
}

/// The simulations take 1 to 65,536 virtual cores (each one an entry of the list schedule's
/// queue).
void check_cores(int cores) {
  if (cores < 1 || cores > 65536)
    throw Error(ErrorCode::bad_value, "cores", "must be in [1, 65536], not " + std::to_string(cores));
}

/// Greedy list scheduling of `costs` in order on `cores` cores: the makespan.
template <class Cost>
double list_schedule(const std::vector<Cost>& costs, int cores) {
  std::priority_queue<double, std::vector<double>, std::greater<>> loads;
  for (int c = 0; c < cores; ++c) loads.push(0.0);
  double makespan = 0.0;
  for (const Cost cost : costs) {
    const double load = loads.top() + static_cast<double>(cost);
    loads.pop();
    loads.push(load);
    makespan = std::max(makespan, load);
  }
  return makespan;
}

}  // namespace

double list_schedule_makespan(const std::vector<std::uint64_t>& costs, int cores) {
  check_cores(cores);
  return list_schedule(costs, cores);
}

namespace {

/// The weight-driven stage's makespan, each node test of split pair s costing `unit[s]`: each
/// split pair's levels one after another (a level's chunks list-scheduled on the cores, a barrier
/// after it, plus `serial[s]`, the pair's stage work outside its levels' visits), the split pairs
/// side by side; at least the stage's cost spread evenly (the cores are shared by the split pairs).
double stage_makespan(const ScheduleRecord& r, const std::vector<double>& unit, const std::vector<double>& serial, int cores) {
  const std::size_t splits = r.stage_pair_node_tests.size();
  double total = 0.0;
  std::vector<double> span(splits);
  for (std::size_t s = 0; s < splits; ++s) {
    total += unit[s] * static_cast<double>(r.stage_pair_node_tests[s]) + serial[s];
    span[s] = unit[s] + serial[s];  // the root's test, and the pair's serial part
  }
  if (total <= 0.0) return 0.0;
  for (std::size_t l = 0; l < r.stage_levels.size() && l < r.stage_level_pair.size(); ++l) {
    const std::uint32_t s = r.stage_level_pair[l];
    if (s < splits) span[s] += unit[s] * list_schedule(r.stage_levels[l], cores);
  }
  return std::max(total / cores, *std::max_element(span.begin(), span.end()));
}

}  // namespace

double simulated_speedup(const StepResult& step, Method method, int cores) {
  check_cores(cores);
  const ScheduleRecord& r = schedule_of(step);
  const double total = static_cast<double>(step.stats.node_tests);
  if (total <= 0.0 || method == Method::sequential) return 1.0;
  double makespan = 0.0;
  switch (method) {
    case Method::sequential:
      return 1.0;
    case Method::exploitation:
      makespan = list_schedule_makespan(r.task_node_tests, cores);
      break;
    case Method::stealing:
      makespan = list_schedule_makespan(r.task_node_tests, cores) + static_cast<double>(r.split_node_tests) / cores;
      break;
    case Method::aposteriori:
    case Method::apriori:
    case Method::hybrid:
      makespan = stage_makespan(r, std::vector<double>(r.stage_pair_node_tests.size(), 1.0),
                                std::vector<double>(r.stage_pair_node_tests.size(), 0.0), cores) +
                 list_schedule_makespan(r.task_node_tests, cores);
      break;
  }
  return makespan > 0.0 ? total / makespan : 1.0;
}

double predicted_step_ms(const StepResult& step, Method method, int cores) {
  check_cores(cores);
  const ScheduleRecord& r = schedule_of(step);
  if (r.timeline.empty()) {
    throw Error(ErrorCode::bad_argument, "predicted_step_ms", "the step has no timeline (EngineOptions::timeline)");
  }
  std::vector<const TaskSpan*> stage, traverse, finalize;
  // A pair traversed whole by one task is finalized inside that task's span: its finalize span lies
  // within the traverse span of the same thread, and its time is already the task's.
  std::vector<const TaskSpan*> by_thread;
  for (const TaskSpan& t : r.timeline) by_thread.push_back(&t);
  std::sort(by_thread.begin(), by_thread.end(), [](const TaskSpan* x, const TaskSpan* y) {
    return x->thread != y->thread       ? x->thread < y->thread
           : x->start_ms != y->start_ms ? x->start_ms < y->start_ms
                                        : x->end_ms > y->end_ms;
  });
  double spans = 0.0;
  const TaskSpan* open = nullptr;  // the thread's latest traverse span
  for (const TaskSpan* t : by_thread) {
    if (open != nullptr && open->thread != t->thread) open = nullptr;
    if (t->phase == TaskSpan::Phase::finalize && open != nullptr && t->start_ms >= open->start_ms && t->end_ms <= open->end_ms) {
      continue;
    }
    if (t->phase == TaskSpan::Phase::traverse) open = t;
    spans += t->end_ms - t->start_ms;
    (t->phase == TaskSpan::Phase::stage ? stage : t->phase == TaskSpan::Phase::traverse ? traverse : finalize).push_back(t);
  }
  const auto by_unit = [](const TaskSpan* x, const TaskSpan* y) {
    return x->unit != y->unit ? x->unit < y->unit : x->start_ms < y->start_ms;
  };
  const auto length = [](const TaskSpan* t) { return t->end_ms - t->start_ms; };
  // The stage: split pairs in pair order, as the stage spans' units (pairs) sort.
  std::sort(stage.begin(), stage.end(), by_unit);
  double stage_ms = 0.0;
  if (!stage.empty()) {
    std::vector<double> unit(r.stage_pair_node_tests.size(), 0.0);
    std::vector<double> serial(unit.size(), 0.0);
    if (stage.size() == unit.size()) {
      for (std::size_t s = 0; s < unit.size(); ++s) {
        if (r.stage_serial_ms.size() == unit.size()) serial[s] = std::min(r.stage_serial_ms[s], length(stage[s]));
        const double visits = length(stage[s]) - serial[s];
        unit[s] = r.stage_pair_node_tests[s] > 0 ? visits / static_cast<double>(r.stage_pair_node_tests[s]) : 0.0;
      }
      stage_ms = stage_makespan(r, unit, serial, cores);
    } else {  // not the stage's records (a step not from the engine): its spans one after another
      for (const TaskSpan* t : stage) stage_ms += length(t);
    }
  }
  // The traversal units: the run-time tasks in handout order; stealing's pieces largest first.
  // The traversal's time outside the units (handing each one out, and stealing's splitting above
  // the cut-off) is done by every thread for the units it takes: spread evenly.
  std::vector<double> units;
  if (method == Method::stealing) {
    for (const TaskSpan* t : traverse) units.push_back(length(t));
    std::sort(units.begin(), units.end(), std::greater<>());
  } else {
    std::sort(traverse.begin(), traverse.end(), by_unit);
    for (const TaskSpan* t : traverse) units.push_back(length(t));
  }
  double in_units = 0.0;
  for (const double u : units) in_units += u;
  const double split_ms = traverse.empty() ? 0.0 : std::max(0.0, r.traverse_ms - in_units);
  // Finalization: the pairs in the order they ran, a large one as its chunks.
  std::sort(finalize.begin(), finalize.end(), [](const TaskSpan* x, const TaskSpan* y) { return x->start_ms < y->start_ms; });
  std::vector<double> finals;
  for (const TaskSpan* t : finalize) {
    const std::size_t candidates = t->unit < step.pair_records.size() ? step.pair_records[t->unit].candidates : 0;
    const std::size_t chunks = narrow::finalize_chunks(r.kind, candidates);
    for (std::size_t c = 0; c < chunks; ++c) finals.push_back(length(t) / static_cast<double>(chunks));
  }
  const double serial = step.broad_ms + std::max(0.0, step.narrow_ms + step.reduce_ms - spans - split_ms);
  return serial + stage_ms + split_ms / cores + list_schedule(units, cores) + list_schedule(finals, cores);
}

void SimulatedRun::add(const StepResult& step) {
  if (step.schedule && !step.schedule->timeline.empty()) {
    mPredictedMs += predicted_step_ms(step, mMethod, mCores);
    ++mTimed;
  }
  if (step.stats.node_tests == 0) return;
  const double work = static_cast<double>(step.stats.node_tests);
  mWork += work;
  mSpan += work / simulated_speedup(step, mMethod, mCores);
}

}  // namespace caliber
