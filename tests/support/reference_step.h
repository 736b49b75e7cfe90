#pragma once
// The reference a world's steps are checked against: caliber::query (the pairwise API, one
// traversal and one finalization per pair, no engine) on every pair of the world's frame, one after
// another, gathered as the engine gathers.

#include <vector>

#include "caliber/query.h"
#include "caliber/world.h"
#include "support/results.h"
#include "schedule/workers.h"

namespace caliber::test {

inline StepResult reference_step(const World& world, int k) {
  const Frame frame = world.frame(k);
  std::vector<QueryResult> results;
  results.reserve(frame.pairs.size());
  for (const ObjectPair& t : frame.pairs) {
    results.push_back(query(*frame.models[t.a], frame.poses[t.a], *frame.models[t.b], frame.poses[t.b], frame.request));
    results.back().contacts = between(results.back(), t.a, t.b);  // the frame's object ids, as the engine writes them
  }
  StepResult out;
  out.step = k;
  out.time = k * world.scene().dt;
  schedule::gather_step(frame.pairs, results, {}, out);
  return out;
}

}  // namespace caliber::test
