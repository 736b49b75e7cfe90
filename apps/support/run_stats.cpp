// The run summary: per-step sums and the pairs' shares of the work.

#include "run_stats.h"

#include <algorithm>

#include "timing.h"

namespace caliber::cli {

void RunStats::add(const StepResult& step) {
  mStepMs.push_back(step.broad_ms + step.narrow_ms + step.reduce_ms);
  mNodeTests += step.stats.node_tests;
  mContacts += step.contacts.size();
  mPairs += step.pair_records.size();
  if (!step.contacts.empty()) ++mStepsWithContacts;
  for (const PairRecord& t : step.pair_records) mPairWork[t.pair] += t.stats.node_tests;
}

double RunStats::median_step_ms() const { return median_of(mStepMs); }

double RunStats::mean_step_ms() const {
  double sum = 0.0;
  for (const double t : mStepMs) sum += t;
  return mStepMs.empty() ? 0.0 : sum / static_cast<double>(mStepMs.size());
}

double RunStats::mean_node_tests() const { return steps() ? double(mNodeTests) / double(steps()) : 0.0; }
double RunStats::mean_contacts() const { return steps() ? double(mContacts) / double(steps()) : 0.0; }
double RunStats::mean_pairs() const { return steps() ? double(mPairs) / double(steps()) : 0.0; }

std::vector<std::pair<std::uint64_t, ObjectPair>> RunStats::ranked() const {
  std::vector<std::pair<std::uint64_t, ObjectPair>> r;
  for (const auto& [pair, work] : mPairWork) r.emplace_back(work, pair);
  std::sort(r.begin(), r.end(),
            [](const auto& x, const auto& y) { return x.first != y.first ? x.first > y.first : x.second < y.second; });
  return r;
}

std::pair<ObjectPair, double> RunStats::heaviest_pair() const {
  const auto r = ranked();
  if (r.empty() || mNodeTests == 0) return {ObjectPair{0, 0}, 0.0};
  return {r[0].second, double(r[0].first) / double(mNodeTests)};
}

std::pair<ObjectPair, double> RunStats::second_heaviest_pair() const {
  const auto r = ranked();
  if (r.size() < 2 || mNodeTests == 0) return {ObjectPair{0, 0}, 0.0};
  return {r[1].second, double(r[1].first) / double(mNodeTests)};
}

}  // namespace caliber::cli
