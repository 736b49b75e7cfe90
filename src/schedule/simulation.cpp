// The load-balance simulation: what a step's recorded work units predict on P virtual cores.
// It predicts; it does not measure (a node test is taken to cost the same everywhere).

#include <algorithm>
#include <functional>
#include <queue>

#include "caliber/engine.h"
#include "caliber/error.h"

namespace caliber {

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

void SimulatedRun::add(const StepResult& step) {
  if (step.stats.node_tests == 0) return;
  const double work = static_cast<double>(step.stats.node_tests);
  mWork += work;
  mSpan += work / simulated_speedup(step, mMethod, mCores);
}

}  // namespace caliber
