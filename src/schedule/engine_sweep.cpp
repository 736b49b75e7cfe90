// Engine::sweep: continuous collision detection for many objects, the pairs whose swept boxes
// overlap swept in parallel (caliber/engine.h).

#include <algorithm>
#include <string>
#include <unordered_map>

#include "broad/box_tree.h"
#include "broad/broad_phase.h"
#include "caliber/error.h"
#include "narrow/sweep_bounds.h"
#include "parallel/executor.h"
#include "schedule/engine_impl.h"

namespace caliber {

std::vector<PairSweep> Engine::sweep(const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& from,
                                     const std::vector<Pose>& to, const SweepRequest& request, const std::vector<bool>& fixed,
                                     const std::vector<ObjectPair>& ignored) {
  const schedule::OneCallAtATime hold(mImpl->busy, "sweep");
  broad::validate_objects("sweep", models, from, "start pose", fixed, ignored);
  broad::validate_objects("sweep", models, to, "end pose", fixed, ignored);
  validate_sweep_request(request);
  const std::size_t n = models.size();
  // Each object stays within its radius about its origin, and its origin on the segment between
  // its two positions: the box of that segment grown by the radius holds it all along. Grown
  // further by the largest tolerance a pair can get (caliber::sweep's own rule) and the rounding
  // margin, two boxes that do not overlap hold objects that never come within it.
  std::unordered_map<const Model*, double> radius_of;
  std::vector<double> radius(n);
  double largest = 0.0, reach = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    auto [it, fresh] = radius_of.try_emplace(models[i].get(), 0.0);
    if (fresh) it->second = narrow::radius_about_origin(*models[i]);
    radius[i] = it->second;
    largest = std::max(largest, radius[i]);
    reach = std::max({reach, from[i].translation.norm(), to[i].translation.norm()});
  }
  const double margin = narrow::kSweepMargin * (2.0 * largest + reach);
  const double tolerance =
      std::max(request.tolerance > 0.0 ? request.tolerance : narrow::kSweepDefaultTolerance * largest, 2.0 * margin);
  std::vector<broad::WorldBox> boxes(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double grow = radius[i] + 0.5 * tolerance + margin;
    boxes[i].lo = from[i].translation.cwiseMin(to[i].translation).array() - grow;
    boxes[i].hi = from[i].translation.cwiseMax(to[i].translation).array() + grow;
  }
  std::vector<std::uint64_t> skipped;
  broad::pair_keys(ignored, skipped);
  const broad::PairFilter filter{fixed.empty() ? nullptr : &fixed, skipped.empty() ? nullptr : &skipped};
  std::vector<ObjectPair> pairs;
  std::vector<SweepResult> results;
  mImpl->executor.execute([&] {
    broad::BoxTree tree;
    tree.pairs(boxes, filter, pairs);
    results.resize(pairs.size());
    // A pair's sweep is a run of distance queries, one after another: the pairs are the tasks (the
    // input checked above, each model's radius found once).
    parallel::parallel_for_each(0, pairs.size(), [&](std::size_t k) {
      const ObjectPair& p = pairs[k];
      results[k] = narrow::sweep_checked(*models[p.a], radius[p.a], {from[p.a], to[p.a]}, *models[p.b], radius[p.b],
                                         {from[p.b], to[p.b]}, request);
    });
  });
  std::vector<PairSweep> out;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (results[k].status != SweepStatus::free) out.push_back(PairSweep{pairs[k], results[k]});
  }
  return out;
}

}  // namespace caliber
