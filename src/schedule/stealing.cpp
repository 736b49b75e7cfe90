// The stealing runner: recursive splitting of the heavy pairs' CD trees on oneTBB's work stealing.

#include <algorithm>
#include <functional>

#include "narrow/finalize.h"
#include "schedule/runner.h"
#include "plans/weights.h"

namespace caliber::schedule {
namespace {

/// One depth-first traversal of pair `pair` from n, on this thread (which tests n unless `tested`),
/// recorded as one piece. `split`: the lanes of a split pair's pieces, which carry their waiting
/// leaf pairs from one to the next (narrow::PieceCarry: finished once every piece is done), or
/// null for a pair traversed whole.
void traverse_piece(StepState& state, WorkerSlots& w, std::size_t pair, narrow::NodePair n, bool tested,
                    const narrow::detail::WideLanes* split = nullptr) {
  const std::uint64_t before = w.stats[pair].node_tests;
  narrow::traverse(state.contexts[pair], n, w.scratch, w.candidates[pair], w.stats[pair],
                   tested ? narrow::RootTest::done : narrow::RootTest::as_root, {}, state.shared_of(pair), split);
  w.pieces.push_back(w.stats[pair].node_tests - before);
}

/// In the wide CD tree a visit passes about three of its up to eight children (2.6 to 3.1 on the
/// bunny, turbine and elephant pairs), and enough pieces for stealing to balance are about this
/// many per thread: a pair that holds all the work is split to the depth at which 3^depth reaches
/// that (4 on 2 threads, 6 on 16). Deeper, the jobs cost more than they balance: on those pairs on
/// 2 threads, depth 3 or 4 was fastest, 7 a third slower than sequential's half, 10 slower than
/// sequential.
constexpr long kWidePiecesPerThread = 32;

/// The depth at which a pair holding `share` of the step's work gives its share of those pieces
/// (share 1: 4 on 2 threads, 6 on 16; 1/24, as each of funnel's pairs: 1 on 2 threads).
int wide_depth(int threads, double share) {
  int depth = 0;
  for (double pieces = 1.0; pieces < share * static_cast<double>(kWidePiecesPerThread * threads); pieces *= 3.0) ++depth;
  return depth;
}

/// A distance query's pieces each search best first with the pair's nearest distance so far, and
/// until a piece finds a pair nothing bounds the others: cut deep, the pieces test far more than
/// one traversal (two_small's knobs 0.001 to 0.26 apart on 2 threads: depth 10 took 2.4 to 3.3
/// times depth 2's time, more than the pair run whole). So a distance pair is cut to the depth
/// whose 2^depth reaches 2 x threads (a visit has two to four children: at least that many
/// pieces where none is pruned): 2 on 2 threads (1.2 to 1.5 times faster than whole there), 5 on
/// 16.
int nearest_depth(int threads) {
  int depth = 0;
  while ((1L << depth) < 2L * threads) ++depth;
  return depth;
}

/// Each pair's share of the step's work, as stealing cuts by it: the larger of its share of the a
/// priori weight and its share of the weights that count node tests, last step's where the pair
/// has some (else its a priori weight times the ratio of node tests to a priori weight over the
/// pairs that have them). Either alone misleads: an a priori weight can be far from the work
/// (front_car's two heaviest pairs take 55 % and 37 % of its node tests and weigh 4.1 % and 1.9 %
/// a priori), and last step's node tests miss a pair that has just come into deep contact.
/// `measured[i]`: whether pair i has node tests last step (an entry in `history`).
std::vector<double> work_shares(const std::vector<ObjectPair>& pairs, const plans::History& history,
                                narrow::PairContexts contexts, std::vector<char>& measured) {
  const std::size_t n = pairs.size();
  const std::vector<double> prior = plans::root_weights(contexts);
  const std::vector<const std::uint64_t*> known = history.node_tests.find_sorted(pairs);
  measured.assign(n, 0);
  double prior_total = 0.0, tests = 0.0, tests_prior = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    prior_total += prior[i];
    if (known[i] != nullptr) {
      measured[i] = 1;
      tests += static_cast<double>(*known[i]);
      tests_prior += prior[i];
    }
  }
  const double ratio = tests > 0.0 && tests_prior > 0.0 ? tests / tests_prior : 1.0;
  std::vector<double> weight(n);
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    weight[i] = known[i] != nullptr ? static_cast<double>(*known[i]) : ratio * prior[i];
    total += weight[i];
  }
  std::vector<double> share(n);
  for (std::size_t i = 0; i < n; ++i) {
    share[i] = std::max(total > 0.0 ? weight[i] / total : 0.0, prior_total > 0.0 ? prior[i] / prior_total : 0.0);
  }
  return share;
}

/// A heavy pair of a distance query that narrow::answered_by_first_hit answers (meshes that
/// intersect), its root passed: the first hit as one piece on this worker, finalized here as
/// found: true. Cut in pieces, each would look for a contact of its own with the distance bounds
/// (two_small at 2 threads: 646 pieces and 8,125 node tests a step where the first hit takes 55).
/// Else false (the pair is cut).
bool answered_by_first_hit(StepState& state, std::size_t pair, WorkerSlots& w) {
  const narrow::PairContext& ctx = state.contexts[pair];
  if (!narrow::takes_first_hit(ctx)) return false;
  bool found = false;
  state.timeline.record(TaskSpan::Phase::traverse, pair, [&] {
    const std::uint64_t before = w.stats[pair].node_tests;
    narrow::Candidate hit;
    found = narrow::answered_by_first_hit(ctx, hit, w.stats[pair]);
    w.pieces.push_back(w.stats[pair].node_tests - before);
    if (!found) return;
    w.candidates[pair].push_back(hit);
    finalize_whole(state, pair, w);
  });
  return found;
}

/// The heavy pairs the first hit did not answer (answered[k] == 0 for heavy[k]).
std::vector<std::uint32_t> unanswered(const std::vector<std::uint32_t>& heavy, const std::vector<char>& answered) {
  std::vector<std::uint32_t> rest;
  for (std::size_t k = 0; k < heavy.size(); ++k) {
    if (answered[k] == 0) rest.push_back(heavy[k]);
  }
  return rest;
}

/// The lanes of a pair's node tests (narrow::VisitLanes), those of its CD tree's shape.
struct PairLanes {
  narrow::detail::WideLanes wide;
  narrow::detail::NodeLanes binary;

  narrow::VisitLanes of(const narrow::PairContext& ctx) {
    if (narrow::wide_cd_tree(ctx)) {
      narrow::wide_lanes(ctx, wide);
      return narrow::VisitLanes{nullptr, &wide};
    }
    binary = ctx.node_lanes();
    return narrow::VisitLanes{&binary, nullptr};
  }
};

/// Above the cut-off depth, visits CD-tree node n of pair `pair` (it passed its test, made by its
/// parent's visit or before the first call) and spawns one job per child that passes; from the
/// cut-off down, one depth-first traversal (which tests n unless `tested`). The node tests made are
/// exactly those of a single depth-first traversal of the tree (for a distance query, those of its
/// pieces, which depend on what the others have found by then).
void steal(StepState& state, std::size_t pair, narrow::NodePair n, int depth, int cutoff, bool tested,
           const narrow::VisitLanes& lanes) {
  const narrow::PairContext& ctx = state.contexts[pair];
  narrow::NodePair kids[narrow::kMaxChildren];
  int count = 0;
  {
    WorkerSlots& w = local_slots(state);
    // A distance query's node farther than a pair some piece has found holds nothing that can win
    // (traverse_nearest's rule: beyond the reach of the nearest distance): dropped here, before it
    // is split or traversed. The children above the cut-off pass a test against the query's own
    // tolerance only, which for an unbounded distance query lets every one through.
    if (narrow::PairShared* shared = state.shared_of(pair); shared != nullptr && ctx.request().kind == QueryKind::distance) {
      const double reach = ctx.reach_for(std::min(ctx.request().tolerance, shared->nearest.load(std::memory_order_relaxed)));
      if (reach < kUnbounded) {
        narrow::PairContext::NearA a;
        narrow::PairContext::NearB b;
        ctx.near(n.a, a);
        ctx.near(n.b, b);
        if (ctx.gap(a, b, reach) > reach) return;
      }
    }
    if (depth >= cutoff) {
      state.timeline.record(TaskSpan::Phase::traverse, pair, [&] { traverse_piece(state, w, pair, n, tested, lanes.wide); });
      return;
    }
    const std::uint64_t before = w.stats[pair].node_tests;
    count = narrow::visit(ctx, n, w.candidates[pair], w.stats[pair], kids, {}, nullptr, lanes);
    w.split_node_tests += w.stats[pair].node_tests - before;
  }
  parallel::JobGroup group;
  for (int i = 1; i < count; ++i) {
    const narrow::NodePair kid = kids[i];
    group.run([&state, pair, kid, depth, cutoff, &lanes] { steal(state, pair, kid, depth + 1, cutoff, true, lanes); });
  }
  if (count > 0) steal(state, pair, kids[0], depth + 1, cutoff, true, lanes);
  group.wait();
}

}  // namespace

void run_stealing(int depth, int threads, const std::vector<ObjectPair>& pairs, const plans::History& history, StepState& state,
                  ScheduleRecord& record) {
  const auto start = util::Clock::now();
  const std::size_t n = state.contexts.size();
  state.candidates.assign(n, 0);
  // Cut for one thread there is nothing to balance: every pair runs whole (no depth to split to).
  if (threads <= 1) depth = 0;
  const bool wide = n > 0 && narrow::wide_cd_tree(state.contexts[0]);
  if (n > 0) depth = std::min(depth, wide ? wide_depth(threads, 1.0) : nearest_depth(threads));
  // Only a pair that may hold a good part of the step's work is split: one whose share of it is
  // at least 1 / (64 x threads). The lighter ones run whole, in a parallel loop over them
  // (splitting thousands of light pairs costs more than it balances), each finalized by the thread
  // that traversed it, at once.
  std::vector<std::uint32_t> heavy, light;
  std::vector<int> cutoff;  // per heavy pair
  if (depth > 0 && n > 1) {
    std::vector<char> measured;
    const std::vector<double> share = work_shares(pairs, history, state.contexts, measured);
    for (std::uint32_t i = 0; i < n; ++i) {
      // In the wide CD tree a pair with node tests last step is split only as deep as its share
      // asks (depth 0: it runs whole, as a light one), so that a scene of many heavy pairs splits
      // each less; one without, to the full depth.
      const int cut = wide && measured[i] != 0 ? std::min(depth, wide_depth(threads, share[i])) : depth;
      if (share[i] < 1.0 / (64.0 * threads) || cut == 0) {
        light.push_back(i);
        continue;
      }
      heavy.push_back(i);
      cutoff.push_back(cut);
    }
  } else {
    for (std::uint32_t i = 0; i < n; ++i) (depth > 0 ? heavy : light).push_back(i);
    cutoff.assign(heavy.size(), depth);
  }
  // A split pair's node-test lanes, made once by the job that tests its root and read by every
  // visit above the cut-off (declared before the jobs' group, which waits for them on the way out).
  std::vector<PairLanes> lanes(heavy.size());
  std::vector<char> answered(heavy.size(), 0);  // heavy pairs the first hit answered, finalized at once
  parallel::JobGroup group;
  for (std::size_t k = 0; k < heavy.size(); ++k) {
    group.run([&state, &lanes, &answered, k, i = heavy[k], depth = cutoff[k]] {
      // The root is tested above the cut-off: splitting work.
      WorkerSlots& w = local_slots(state);
      ++w.split_node_tests;
      if (!narrow::test_root(state.contexts[i], narrow::NodePair{0, 0}, w.stats[i])) return;
      if (answered_by_first_hit(state, i, w)) {
        answered[k] = 1;
        return;
      }
      steal(state, i, narrow::NodePair{0, 0}, 0, depth, /*tested=*/true, lanes[k].of(state.contexts[i]));
    });
  }
  if (!light.empty()) {
    group.run([&state, &light] {
      parallel::parallel_for(0, light.size(), 16, [&](std::size_t lo, std::size_t hi) {
        for (std::size_t k = lo; k != hi; ++k) {
          // One piece, its finalization inside its span.
          state.timeline.record(TaskSpan::Phase::traverse, light[k], [&] {
            WorkerSlots& w = local_slots(state);
            traverse_piece(state, w, light[k], narrow::NodePair{0, 0}, /*tested=*/false);
            finalize_whole(state, light[k], w);
          });
        }
      });
    });
  }
  group.wait();
  flush_pieces(state);
  record.traverse_ms = util::ms_since(start);
  const auto finalize_start = util::Clock::now();
  finalize_pairs(state, unanswered(heavy, answered), {});
  record.finalize_ms = util::ms_since(finalize_start);
  state.workers.for_each([&](const WorkerSlots& w) {
    if (!state.current(w)) return;
    record.task_node_tests.insert(record.task_node_tests.end(), w.pieces.begin(), w.pieces.end());
    record.split_node_tests += w.split_node_tests;
  });
  // Pieces were collected per worker; sort them so the record does not depend on who ran what (in
  // parallel: a step of many pairs has a piece per light pair).
  parallel::parallel_sort(record.task_node_tests.begin(), record.task_node_tests.end(), std::greater<>());
}

}  // namespace caliber::schedule
