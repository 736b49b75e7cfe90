// Engine::sweep and Engine::sweep_many: continuous collision detection for many objects (the
// pairs whose swept boxes overlap) and for one pair along many motions, the sweeps in parallel and
// a heavy sweep's queries split by the engine's method (caliber/engine.h).

#include <algorithm>
#include <limits>
#include <new>
#include <numeric>
#include <string>
#include <unordered_map>

#include "broad/box_tree.h"
#include "broad/broad_phase.h"
#include "caliber/error.h"
#include "mesh/pose_check.h"
#include "narrow/finalize.h"
#include "narrow/sweep_bounds.h"
#include "parallel/executor.h"
#include "schedule/engine_impl.h"

namespace caliber {
namespace {

/// A query of at least this many node tests is split across threads when few sweeps are left: the
/// last query of a sweep predicts its next (the models come closer, step by step). Measured
/// (Engine::query_many of one distance entry, stealing, 2 threads against 1): two plates face to
/// face, whose many equal distances the search must all visit, gained little from the split on
/// queries well below this size and nearly a second thread's worth near it; the bunny and blade of
/// bench_sweep_many, whose search finds its nearest pair early, lost by it at every size tried, all
/// below this one (a split search prunes less at first). Below, one thread (what the split gives a
/// sweep: bench/results/amd-epyc-2c/sweep/README.md).
constexpr std::uint64_t kSplitNodeTests = 16384;

/// Sweeps run in one parallel loop between two calls of EngineOptions::between_chunks.
constexpr std::size_t kSweepChunk = 8192;

}  // namespace

void Engine::Impl::run_sweeps(const EngineOptions& options, Method method, std::vector<schedule::ActiveSweep>& sweeps,
                              const GroupCompatibility* groups) {
  const QueryRequest distance = narrow::sweep_distance_request(groups);
  const int threads = executor.threads();
  timeline.begin(false);  // (a split query's spans are not recorded)
  // Exploitation runs a pair whole, as the loop over sweeps does: only the other methods cut one.
  const bool can_split = threads > 1 && method != Method::sequential && method != Method::exploitation;
  std::vector<std::size_t> active(sweeps.size()), whole, split;
  std::iota(active.begin(), active.end(), std::size_t{0});
  const plans::History no_history;
  std::vector<QueryResult> results;
  bool started = false;  // whether work was done (the hook is called between chunks of it)
  while (!active.empty()) {
    whole.clear();
    split.clear();
    const bool few = can_split && active.size() < schedule::kEntriesPerThread * static_cast<std::size_t>(threads);
    for (const std::size_t i : active) {
      (few && sweeps[i].advance.last_node_tests() >= kSplitNodeTests ? split : whole).push_back(i);
    }
    // Whole queries, a sweep to a thread: until it is over, or (when queries can be split) until
    // one of them was heavy, to be looked at again with the sweeps left.
    // In chunks of kSweepChunk sweeps, options.between_chunks called between them.
    for (std::size_t first = 0; first < whole.size(); first += kSweepChunk) {
      if (started && options.between_chunks) options.between_chunks();
      started = true;
      executor.execute([&] {
        parallel::parallel_for_each(first, std::min(whole.size(), first + kSweepChunk), [&](std::size_t k) {
          schedule::ActiveSweep& sweep = sweeps[whole[k]];
          do {
            const narrow::PairContext ctx(*sweep.a, sweep.advance.pose_a(), *sweep.b, sweep.advance.pose_b(), distance);
            sweep.done = sweep.advance.take(narrow::query_whole(ctx), ctx);
          } while (!sweep.done && !(can_split && sweep.advance.last_node_tests() >= kSplitNodeTests));
        });
      });
    }
    // Heavy queries of the few sweeps left: one each, as the pairs of one run of the method.
    if (!split.empty()) {
      if (started && options.between_chunks) options.between_chunks();
      started = true;
      EngineOptions run = options;
      run.threads = threads;
      run.stealing_depth = schedule::stealing_cutoff(split.size(), threads, options.stealing_depth);
      const std::vector<ObjectPair> ids(split.size(), ObjectPair{0, 1});  // the object ids caliber::sweep's contact carries
      ScheduleRecord record;
      // The last closest pair, at the new poses: a distance the pieces prune by from the start.
      std::vector<double> nearest(split.size(), std::numeric_limits<double>::infinity());
      for (std::size_t k = 0; k < split.size(); ++k) {
        const schedule::ActiveSweep& sweep = sweeps[split[k]];
        std::uint32_t ta, tb;
        narrow::Candidate c;
        if (sweep.advance.last_pair(ta, tb) &&
            narrow::PairContext(*sweep.a, sweep.advance.pose_a(), *sweep.b, sweep.advance.pose_b(), distance)
                .leaf_distance(ta, tb, kUnbounded, c)) {
          nearest[k] = c.distance;
        }
      }
      const auto make = [&](std::size_t k, void* where) {
        const schedule::ActiveSweep& sweep = sweeps[split[k]];
        new (where) narrow::PairContext(*sweep.a, sweep.advance.pose_a(), *sweep.b, sweep.advance.pose_b(), distance);
      };
      run_pairs(run, method, ids, distance, no_history, make, results, record, nearest);
      for (std::size_t k = 0; k < split.size(); ++k) {
        schedule::ActiveSweep& sweep = sweeps[split[k]];
        sweep.done = sweep.advance.take(
            results[k], narrow::PairContext(*sweep.a, sweep.advance.pose_a(), *sweep.b, sweep.advance.pose_b(), distance));
      }
      schedule::g_split_sweep_queries.fetch_add(split.size(), std::memory_order_relaxed);
    }
    std::erase_if(active, [&](std::size_t i) { return sweeps[i].done; });
  }
}

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
  const double margin = narrow::kSweepMargin * (2.0 * largest + reach) + narrow::kSweepFlush;
  const double tolerance = narrow::sweep_tolerance(request, largest, margin);
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
  mImpl->executor.execute([&] {
    broad::BoxTree tree;
    tree.pairs(boxes, filter, pairs);
  });
  std::vector<schedule::ActiveSweep> sweeps;
  sweeps.reserve(pairs.size());
  for (const ObjectPair& p : pairs) {
    sweeps.push_back({models[p.a].get(), models[p.b].get(),
                      narrow::SweepAdvance(radius[p.a], {from[p.a], to[p.a]}, radius[p.b], {from[p.b], to[p.b]}, request)});
  }
  mImpl->run_sweeps(mOptions, mOptions.method, sweeps, request.groups);
  std::vector<PairSweep> out;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (sweeps[k].advance.result().status != SweepStatus::free) out.push_back(PairSweep{pairs[k], sweeps[k].advance.result()});
  }
  return out;
}

std::vector<SweepResult> Engine::sweep_many(const Model& a, std::span<const SweptPose> motions_a, const Model& b,
                                            std::span<const SweptPose> motions_b, const SweepRequest& request) {
  const schedule::OneCallAtATime hold(mImpl->busy, "sweep_many");
  const std::size_t na = motions_a.size(), nb = motions_b.size();
  const std::size_t n = schedule::entry_count(na, nb, "motions", "or one motion to a side that moves the same in every entry");
  const auto check = [](std::span<const SweptPose> motions, const char* side) {
    for (std::size_t i = 0; i < motions.size(); ++i) {
      const auto name = [&](const char* end) { return std::string("motions of ") + side + "[" + std::to_string(i) + "]." + end; };
      validate_pose_named(motions[i].start, [&] { return name("start"); });
      validate_pose_named(motions[i].end, [&] { return name("end"); });
    }
  };
  check(motions_a, "A");
  check(motions_b, "B");
  validate_sweep_request(request);
  const double ra = narrow::radius_about_origin(a), rb = narrow::radius_about_origin(b);
  std::vector<schedule::ActiveSweep> sweeps;
  sweeps.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    sweeps.push_back({&a, &b, narrow::SweepAdvance(ra, motions_a[na == 1 ? 0 : i], rb, motions_b[nb == 1 ? 0 : i], request)});
  }
  mImpl->run_sweeps(mOptions, mOptions.method, sweeps, request.groups);
  std::vector<SweepResult> out;
  out.reserve(n);
  for (const schedule::ActiveSweep& sweep : sweeps) out.push_back(sweep.advance.result());
  return out;
}

}  // namespace caliber
