// Methods as plans: what each method hands the runner. The cut of a calibrated method is decided
// here, before any depth-first traversal starts.

#include "plans/plan.h"

#include <algorithm>
#include <numeric>

#include "narrow/finalize.h"
#include "parallel/executor.h"
#include "plans/weights.h"

namespace caliber::plans {

Plan plan_pairs(std::size_t pairs) {
  Plan plan;
  plan.run.reserve(pairs);
  for (std::size_t i = 0; i < pairs; ++i) {
    plan.run.push_back(RunTask{{Root{static_cast<std::uint32_t>(i), narrow::NodePair{0, 0}, false, 0.0}}, 0.0});
  }
  plan.kept = pairs;
  return plan;
}

InitialWeights initial_weights(Method method, const std::vector<ObjectPair>& pairs, narrow::PairContexts contexts,
                               const History& history) {
  const std::size_t n = pairs.size();
  InitialWeights w;
  w.weight.resize(n);
  w.scale.assign(n, 1.0);
  if (method != Method::hybrid && method != Method::aposteriori) {
    w.weight = root_weights(contexts);
  } else {
    // A pair with history weighs its node tests of last step; its root is estimated only for the
    // fallback ratio, on an evenly spaced sample of at most kRatioSample of those pairs (all of
    // them when fewer have history), or when it is split (scale_of). A pair without history is
    // estimated and scaled by the ratio.
    const std::vector<const std::uint64_t*> known = history.node_tests.find_sorted(pairs);
    const auto last = [&](std::size_t i) -> std::uint64_t { return known[i] == nullptr ? 0 : *known[i]; };
    std::size_t with_history = 0;
    for (std::size_t i = 0; i < n; ++i) with_history += last(i) > 0 ? 1 : 0;
    const std::size_t stride = std::max<std::size_t>(1, (with_history + kRatioSample - 1) / kRatioSample);
    std::vector<std::uint32_t> estimate;  // the pairs whose root is estimated
    std::size_t seen = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (last(i) == 0 || seen++ % stride == 0) estimate.push_back(static_cast<std::uint32_t>(i));
    }
    std::vector<double> root(estimate.size());
    parallel::parallel_for_each(0, estimate.size(), [&](std::size_t k) {
      root[k] = apriori_weight(contexts[estimate[k]], {0, 0});
    });
    double measured = 0.0, estimated = 0.0;
    for (std::size_t k = 0; k < estimate.size(); ++k) {
      if (last(estimate[k]) > 0) {
        measured += static_cast<double>(last(estimate[k]));
        estimated += root[k];
      }
    }
    const double fallback = estimated > 0.0 ? measured / estimated : 1.0;
    for (std::size_t i = 0; i < n; ++i) {
      w.weight[i] = static_cast<double>(last(i));
      w.scale[i] = 0.0;  // not estimated: scale_of
    }
    for (std::size_t k = 0; k < estimate.size(); ++k) {
      const std::size_t i = estimate[k];
      w.scale[i] = last(i) > 0 ? static_cast<double>(last(i)) / root[k] : fallback;
      if (last(i) == 0) w.weight[i] = fallback * root[k];
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    w.weight[i] += kPairWeight;
    w.total += w.weight[i];
  }
  return w;
}

double scale_of(const InitialWeights& w, narrow::PairContexts contexts, std::size_t i) {
  // (Its weight is its node tests of last step, an integer, plus kPairWeight: the difference is exact.)
  return w.scale[i] > 0.0 ? w.scale[i] : (w.weight[i] - kPairWeight) / apriori_weight(contexts[i], {0, 0});
}

namespace {

/// A posteriori: the sub-task roots of each heavy pair from last step's summary tree; nothing is
/// tested here. A pair without reported pairs last step cannot be split (the metric's known blind
/// spot) and runs whole. Its original task keeps the rest of the tree, the roots on its taboo list.
void split_by_summary(const EngineOptions& options, const std::vector<ObjectPair>& pairs, narrow::PairContexts contexts,
                      const History& history, const std::vector<std::size_t>& to_split, const std::vector<double>& weight,
                      Plan& plan, std::vector<Root>& cart) {
  std::vector<PosterioriSplit> chosen(to_split.size());
  parallel::parallel_for_each(0, to_split.size(), [&](std::size_t s) {
    const std::size_t i = to_split[s];
    const std::vector<TrianglePair>* reported = history.reported.find(pairs[i]);
    if (reported == nullptr) return;
    const auto summary = build_summary(contexts[i], *reported);
    chosen[s] = split_aposteriori(summary, static_cast<std::uint32_t>(i), weight[i], plan.omega, options.epsilon * plan.omega,
                                  static_cast<std::size_t>(options.taboo_cap));
    chosen[s].rest = chosen[s].taboo.empty() ? weight[i] : chosen[s].rest;
  });
  for (std::size_t s = 0; s < to_split.size(); ++s) {
    PosterioriSplit& ps = chosen[s];
    Root original{static_cast<std::uint32_t>(to_split[s]), narrow::NodePair{0, 0}, false, ps.rest};
    if (!ps.taboo.empty()) {
      original.taboo = static_cast<std::int32_t>(plan.taboos.size());
      plan.taboos.push_back(narrow::Taboo{ps.taboo});
      for (std::vector<Root>* list : {&ps.roots, &ps.cart}) {
        for (Root& r : *list) {
          r.owner = original.taboo;
          r.slot = plan.taboos.back().find(r.node);
        }
      }
    }
    plan.run.push_back(RunTask{{original}, original.weight});
    for (const Root& r : ps.roots) plan.run.push_back(RunTask{{r}, r.weight});
    cart.insert(cart.end(), ps.cart.begin(), ps.cart.end());
    plan.taboo_nodes += ps.taboo.size();
  }
}

/// A priori and hybrid: the weight-driven stage of each heavy pair, the pairs in parallel (and each
/// pair's levels in parallel inside).
void split_by_stage(const EngineOptions& options, const std::vector<ObjectPair>& pairs, narrow::PairContexts contexts,
                    const History& history, const std::vector<std::size_t>& to_split, const InitialWeights& w,
                    const StageWrapper& around_stage, Plan& plan, std::vector<Root>& cart) {
  const bool node_history = options.method == Method::hybrid && options.node_history;
  plan.splits.resize(to_split.size());
  parallel::parallel_for_each(0, to_split.size(), [&](std::size_t s) {
    const std::size_t i = to_split[s];
    const NodeCounts* measured = node_history ? history.node_counts.find(pairs[i]) : nullptr;
    const auto stage = [&] {
      plan.splits[s] = split_pair(contexts[i], static_cast<std::uint32_t>(i), w.weight[i], scale_of(w, contexts, i), plan.omega,
                                  options.epsilon * plan.omega, measured);
    };
    if (around_stage) {
      around_stage(i, stage);
    } else {
      stage();
    }
  });
  for (std::size_t s = 0; s < to_split.size(); ++s) {
    plan.split_pairs.push_back(static_cast<std::uint32_t>(to_split[s]));
    for (const Root& r : plan.splits[s].roots) plan.run.push_back(RunTask{{r}, r.weight});
    cart.insert(cart.end(), plan.splits[s].cart.begin(), plan.splits[s].cart.end());
  }
}

}  // namespace

Plan plan_calibrated(const EngineOptions& options, const std::vector<ObjectPair>& pairs, narrow::PairContexts contexts,
                     const History& history, const StageWrapper& around_stage) {
  const InitialWeights w = initial_weights(options.method, pairs, contexts, history);
  Plan plan;
  plan.weighted = true;
  plan.omega = caliber_threshold(w.total, options.beta, options.plan_threads > 0 ? options.plan_threads : options.threads);
  const double eps = options.epsilon * plan.omega;
  std::vector<Root> cart;
  cart.reserve(pairs.size());
  std::vector<std::size_t> to_split;
  QueryStats unused;  // the first hits' tests: a kept pair's task counts its own
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Root whole{static_cast<std::uint32_t>(i), narrow::NodePair{0, 0}, false, w.weight[i]};
    switch (classify(w.weight[i], plan.omega, eps)) {
      case Verdict::keep:
        plan.run.push_back(RunTask{{whole}, w.weight[i]});
        ++plan.kept;
        break;
      case Verdict::cart:
        cart.push_back(whole);
        break;
      case Verdict::split:
        // A distance pair the first hit answers (the meshes intersect): one task from the root,
        // whose traversal finds that pair again (cut, its pieces would each look for a contact).
        if (narrow::Candidate hit; narrow::answered_by_first_hit(contexts[i], hit, unused)) {
          plan.run.push_back(RunTask{{whole}, w.weight[i]});
          ++plan.kept;
          break;
        }
        to_split.push_back(i);
        break;
    }
  }
  plan.split = to_split.size();
  if (options.method == Method::aposteriori) {
    split_by_summary(options, pairs, contexts, history, to_split, w.weight, plan, cart);
  } else {
    split_by_stage(options, pairs, contexts, history, to_split, w, around_stage, plan, cart);
  }
  plan.carted = cart.size();
  // A cart of thousands of light pairs is merged into finer tasks than Omega: the run-time tasks
  // are then near-equal, and a list schedule of a dozen of them ends on a tail of up to one whole
  // task (on grid_4096, one of two threads idle for part of the traversal:
  // bench/results/amd-epyc-2c/many_objects/README.md).
  const double cart_omega =
      plan.omega / static_cast<double>(std::clamp<std::size_t>(cart.size() / kCartItemsPerTask, 1, kCartFiner));
  for (RunTask& t : merge_cart(std::move(cart), cart_omega)) plan.run.push_back(std::move(t));
  // Heaviest first, so that the ordered hand-out does not end on a heavy straggler.
  // (An order of indices, then each task moved once: tasks are too large to be moved around a sort.)
  std::vector<std::uint32_t> order(plan.run.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t x, std::uint32_t y) { return plan.run[x].weight > plan.run[y].weight; });
  std::vector<RunTask> sorted;
  sorted.reserve(order.size());
  for (const std::uint32_t t : order) sorted.push_back(std::move(plan.run[t]));
  plan.run = std::move(sorted);
  return plan;
}

}  // namespace caliber::plans
