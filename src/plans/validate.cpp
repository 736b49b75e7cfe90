// The one-pass check of a plan's invariants (validate.h).

#include "plans/validate.h"

#include <cmath>
#include <vector>

namespace caliber::plans {
namespace {

constexpr std::uint32_t kNotSplit = 0xFFFFFFFFu;

/// Why a root does not agree with the plan's taboo lists and stages (empty when it does);
/// `split_of[pair]` is the pair's entry in plan.splits, or kNotSplit.
std::string root_problem(const Plan& plan, const Root& r, const std::vector<std::uint32_t>& split_of) {
  const auto lists = static_cast<std::int32_t>(plan.taboos.size());
  if (r.taboo < -1 || r.taboo >= lists) return "a root's taboo list does not exist";
  if (r.owner < -1 || r.owner >= lists) return "a root's owner list does not exist";
  if (r.owner >= 0) {
    const auto& nodes = plan.taboos[static_cast<std::size_t>(r.owner)].nodes;
    if (r.slot < 0 || static_cast<std::size_t>(r.slot) >= nodes.size() || !(nodes[static_cast<std::size_t>(r.slot)] == r.node)) {
      return "a sub-task root is not at its place on its taboo list";
    }
  }
  if (r.stage < -1) return "a root's stage record is negative";
  if (r.stage >= 0) {
    const std::uint32_t k = split_of[r.pair];
    if (k == kNotSplit) return "a root names a stage record of a pair that was not split";
    const auto& stage = plan.splits[k].stage;
    if (static_cast<std::size_t>(r.stage) >= stage.size() || !(stage[static_cast<std::size_t>(r.stage)].node == r.node)) {
      return "a root's stage record is not its node";
    }
  }
  return {};
}

/// Why a task is not well formed (empty when it is); counts the roots at each pair's CD root.
std::string task_problem(const Plan& plan, const RunTask& task, std::size_t pairs, const std::vector<std::uint32_t>& split_of,
                         std::vector<std::uint32_t>& at_root) {
  if (task.roots.empty()) return "a run-time task without a root";
  if (!std::isfinite(task.weight) || task.weight < 0.0) return "a run-time task's weight is negative or not finite";
  double sum = 0.0;
  for (const Root& r : task.roots) {
    if (r.pair >= pairs) return "a root names a pair out of range";
    if (std::string p = root_problem(plan, r, split_of); !p.empty()) return p;
    sum += r.weight;
    if (r.node == narrow::NodePair{0, 0}) ++at_root[r.pair];
  }
  if (plan.weighted && !(std::abs(sum - task.weight) <= 1e-9 * std::max(1.0, std::abs(task.weight)))) {
    return "a run-time task's weight is not the sum of its roots'";
  }
  return {};
}

}  // namespace

std::string plan_problem(const Plan& plan, std::size_t pairs) {
  if (plan.splits.size() != plan.split_pairs.size()) return "a split pair without its stage, or a stage without its pair";
  std::vector<std::uint32_t> split_of(pairs, kNotSplit);
  for (std::size_t k = 0; k < plan.split_pairs.size(); ++k) {
    const std::uint32_t pair = plan.split_pairs[k];
    if (pair >= pairs || split_of[pair] != kNotSplit) return "a split pair out of range or split twice";
    split_of[pair] = static_cast<std::uint32_t>(k);
  }
  std::vector<std::uint32_t> at_root(pairs, 0);
  for (const RunTask& task : plan.run) {
    if (std::string p = task_problem(plan, task, pairs, split_of, at_root); !p.empty()) return p;
  }
  for (std::size_t i = 0; i < pairs; ++i) {
    const bool split = split_of[i] != kNotSplit;
    if (split ? at_root[i] != 0 : at_root[i] != 1) {
      return "pair " + std::to_string(i) + (split ? ": split, but run from its root too" : ": not run from its root once");
    }
  }
  return {};
}

}  // namespace caliber::plans
