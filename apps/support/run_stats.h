#pragma once
// The summary of a run that `caliber run` and `caliber bench` print: the paper's Table 1 and timings.

#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "caliber/engine.h"

namespace caliber::cli {

/// The paper's Table 1 for a run, and its timing summary, accumulated step by step (no step is kept).
class RunStats {
 public:
  /// Adds one step.
  void add(const StepResult& step);

  /// Steps added.
  [[nodiscard]] std::size_t steps() const { return mStepMs.size(); }
  /// Median wall time of a step (broad + narrow + reduction), ms.
  [[nodiscard]] double median_step_ms() const;
  /// Mean wall time of a step, ms.
  [[nodiscard]] double mean_step_ms() const;
  /// Mean node tests per step.
  [[nodiscard]] double mean_node_tests() const;
  /// Mean contacts (reported triangle pairs) per step.
  [[nodiscard]] double mean_contacts() const;
  /// Mean pairs (the broad phase's object pairs) per step.
  [[nodiscard]] double mean_pairs() const;
  /// Steps with at least one contact.
  [[nodiscard]] std::size_t steps_with_contacts() const { return mStepsWithContacts; }
  /// Distinct object pairs the broad phase kept over the run.
  [[nodiscard]] std::size_t distinct_pairs() const { return mPairWork.size(); }
  /// The object pair with the most node tests over the run, and its share of all node tests (0..1).
  [[nodiscard]] std::pair<ObjectPair, double> heaviest_pair() const;
  /// The pair with the second most node tests over the run, and its share.
  [[nodiscard]] std::pair<ObjectPair, double> second_heaviest_pair() const;

 private:
  [[nodiscard]] std::vector<std::pair<std::uint64_t, ObjectPair>> ranked() const;

  std::vector<double> mStepMs;
  std::uint64_t mNodeTests = 0;
  std::uint64_t mContacts = 0;
  std::uint64_t mPairs = 0;
  std::size_t mStepsWithContacts = 0;
  std::map<ObjectPair, std::uint64_t> mPairWork;
};

}  // namespace caliber::cli
