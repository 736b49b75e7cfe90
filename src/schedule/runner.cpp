// The plan runner, the one finalization of a step's pairs, and the step's reduction.

#include "schedule/runner.h"

#include <algorithm>
#include <numeric>

#include "narrow/finalize.h"
#include "util/assert.h"

namespace caliber::schedule {

namespace {

/// `contact_pair`: as_found where the pair was traversed whole (from its CD tree's root, one
/// traversal on no taboo list: its contact at distance 0 is the pair's), else from_root.
void finalize_into(StepState& state, std::size_t i, std::vector<narrow::Candidate>& all, const QueryStats& stats,
                   narrow::ContactPair contact_pair) {
  state.candidates[i] = all.size();
  state.results[i] = narrow::finalize(state.contexts[i], all, stats, state.pairs[i], contact_pair, state.parallel_finalize);
}

/// A pair that is one root of one task, from its CD tree's root and neither split nor on a taboo
/// list, is finalized by that task as soon as it is traversed (its candidates are all in that
/// thread's slots): no second pass over it. Returns per pair 1 for those; `rest` gets the others,
/// finalized once every task is done.
std::vector<std::uint8_t> whole_pairs(const plans::Plan& plan, const std::vector<std::size_t>& split_of,
                                      std::vector<std::uint32_t>& rest) {
  const std::size_t n = split_of.size();
  std::vector<std::uint8_t> roots_of(n, 0);  // 0: none seen, 1: one from the top, 2: otherwise
  for (const plans::RunTask& task : plan.run) {
    for (const plans::Root& root : task.roots) {
      const bool from_top = root.node == narrow::NodePair{0, 0} && root.taboo < 0 && root.owner < 0;
      roots_of[root.pair] = from_top && roots_of[root.pair] == 0 && split_of[root.pair] == SIZE_MAX ? 1 : 2;
    }
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (roots_of[i] != 1) {
      rest.push_back(i);
      roots_of[i] = 0;
    }
  }
  return roots_of;
}

/// The wide lanes of the pairs cut into pieces (`rest`), made once and shared by their pieces
/// (narrow::PieceCarry); none for the others, nor for a distance query's binary CD tree.
class PieceLanes {
 public:
  PieceLanes(const StepState& state, const std::vector<std::uint32_t>& rest) : mAt(state.contexts.size(), -1) {
    for (const std::uint32_t i : rest) {
      if (!narrow::wide_cd_tree(state.contexts[i])) continue;
      mAt[i] = static_cast<std::int32_t>(mLanes.size());
      mLanes.push_back(narrow::wide_lanes(state.contexts[i]));
    }
  }
  /// Pair i's lanes, or null (its pieces carry nothing).
  [[nodiscard]] const narrow::detail::WideLanes* of(std::size_t i) const { return mAt[i] >= 0 ? &mLanes[mAt[i]] : nullptr; }

 private:
  std::vector<std::int32_t> mAt;
  std::vector<narrow::detail::WideLanes> mLanes;
};

/// The record's fields the plan sets before it runs.
void record_plan(const plans::Plan& plan, ScheduleRecord& record) {
  record.omega = plan.omega;
  record.kept = plan.kept;
  record.split = plan.split;
  record.carted = plan.carted;
  record.taboo = plan.taboo_nodes;
  record.generated = plan.run.size();
  record.task_node_tests.assign(plan.run.size(), 0);
  if (plan.weighted) record.task_weights.resize(plan.run.size());
}

/// Pair i, cut into pieces, finalized from what `start` seeds and every current worker's slots
/// (`count`: the workers' candidates): a contact query without a limit reads them where they are
/// (narrow::finalize_contacts: its reduction keeps few), any other gathers them into one list.
void finalize_split(StepState& state, const std::vector<WorkerSlots*>& slots, std::size_t i,
                    const std::function<void(std::size_t, std::vector<narrow::Candidate>&, QueryStats&)>& start,
                    std::size_t count) {
  std::vector<narrow::Candidate> all;
  QueryStats stats;
  if (start) start(i, all, stats);
  for (const WorkerSlots* w : slots) {
    if (!state.current(*w)) continue;
    stats.node_tests += w->stats[i].node_tests;
    stats.leaf_tests += w->stats[i].leaf_tests;
  }
  const narrow::PairContext& ctx = state.contexts[i];
  if (ctx.request().kind == QueryKind::contact && ctx.request().max_pairs == 0) {
    narrow::CandidateLists lists;
    lists.add(all);
    for (const WorkerSlots* w : slots) {
      if (state.current(*w)) lists.add(w->candidates[i]);
    }
    state.candidates[i] = lists.size();
    state.results[i] = narrow::finalize_contacts(ctx, lists, stats, state.pairs[i], state.parallel_finalize);
    return;
  }
  all.reserve(all.size() + count);
  for (const WorkerSlots* w : slots) {
    if (state.current(*w)) all.insert(all.end(), w->candidates[i].begin(), w->candidates[i].end());
  }
  finalize_into(state, i, all, stats, narrow::ContactPair::from_root);
}

}  // namespace

void flush_pieces(StepState& state) {
  std::vector<WorkerSlots*> carrying;  // (none where no pair was cut, or none carries: a limit, distance)
  state.workers.for_each([&](WorkerSlots& w) {
    if (state.current(w) && w.scratch.carry.ctx != nullptr) carrying.push_back(&w);
  });
  if (carrying.size() == 1) carrying.front()->scratch.flush_pieces();
  if (carrying.size() < 2) return;
  parallel::parallel_for(0, carrying.size(), 1, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t k = lo; k != hi; ++k) carrying[k]->scratch.flush_pieces();
  });
}

void finalize_whole(StepState& state, std::size_t i, WorkerSlots& w) {
  state.timeline.record(TaskSpan::Phase::finalize, i,
                        [&] { finalize_into(state, i, w.candidates[i], w.stats[i], narrow::ContactPair::as_found); });
}

void finalize_pairs(StepState& state, const std::vector<std::uint32_t>& rest,
                    const std::function<void(std::size_t, std::vector<narrow::Candidate>&, QueryStats&)>& start) {
  const std::vector<WorkerSlots*> slots = state.workers.all();
  // A pair's finalization costs about its candidate count: most candidates first, to the next free
  // thread (ties by pair index; the order changes who runs what, never the results).
  std::vector<std::size_t> candidates(rest.size(), 0), order(rest.size());
  for (const WorkerSlots* w : slots) {
    if (!state.current(*w)) continue;
    for (std::size_t k = 0; k < rest.size(); ++k) candidates[k] += w->candidates[rest[k]].size();
  }
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return candidates[x] > candidates[y]; });
  parallel::for_each_in_order(rest.size(), [&](std::size_t k) {
    const std::size_t i = rest[order[k]];
    state.timeline.record(TaskSpan::Phase::finalize, i, [&] { finalize_split(state, slots, i, start, candidates[order[k]]); });
  });
}

std::vector<std::vector<std::uint64_t>> run_plan(const plans::Plan& plan, StepState& state, ScheduleRecord& record) {
  const std::size_t n = state.contexts.size();
  const auto phase = util::Clock::now();
  record_plan(plan, record);
  if (state.timeline.on) {
    record.task_roots.resize(plan.run.size());
    for (std::size_t t = 0; t < plan.run.size(); ++t) {
      for (const plans::Root& root : plan.run[t].roots)
        record.task_roots[t].push_back(TaskRoot{root.pair, root.node.a, root.node.b});
    }
  }
  std::vector<std::size_t> split_of(n, SIZE_MAX);
  state.candidates.assign(n, 0);
  std::vector<std::vector<std::uint64_t>> stage_root_tests(plan.splits.size());
  for (std::size_t s = 0; s < plan.splits.size(); ++s) {
    split_of[plan.split_pairs[s]] = s;
    stage_root_tests[s].assign(plan.splits[s].stage.size(), 0);
    record.stage_node_tests += plan.splits[s].stats.node_tests;
    record.stage_pair_node_tests.push_back(plan.splits[s].stats.node_tests);
    record.stage_serial_ms.push_back(plan.splits[s].serial_ms);
    for (const std::vector<std::uint64_t>& level : plan.splits[s].levels) {
      record.stage_levels.push_back(level);
      record.stage_level_pair.push_back(static_cast<std::uint32_t>(s));
    }
    record.queue_peak = std::max(record.queue_peak, plan.splits[s].queue_peak);
  }
  std::vector<std::vector<std::uint64_t>> sub_tests(plan.taboos.size());
  std::vector<std::vector<char>> reached(plan.taboos.size());
  for (std::size_t t = 0; t < plan.taboos.size(); ++t) {
    sub_tests[t].assign(plan.taboos[t].nodes.size(), 0);
    reached[t].assign(plan.taboos[t].nodes.size(), 0);
  }
  std::vector<std::uint32_t> rest;
  const std::vector<std::uint8_t> whole = whole_pairs(plan, split_of, rest);
  const PieceLanes lanes(state, rest);
  // In plan order, each task to the next free thread: the list schedule the simulation replays.
  parallel::for_each_in_order(plan.run.size(), [&](std::size_t t) {
    state.timeline.record(TaskSpan::Phase::traverse, t, [&] {
      WorkerSlots& w = local_slots(state);
      std::uint64_t tests = 0;
      for (const plans::Root& root : plan.run[t].roots) {
        QueryStats& stats = w.stats[root.pair];
        const std::uint64_t before = stats.node_tests;
        const narrow::TabooView taboo =
            root.taboo >= 0 ? narrow::TabooView{&plan.taboos[root.taboo], reached[root.taboo].data()} : narrow::TabooView{};
        narrow::traverse(state.contexts[root.pair], root.node, w.scratch, w.candidates[root.pair], stats, root.root_test(), taboo,
                         state.shared_of(root.pair), lanes.of(root.pair));
        tests += stats.node_tests - before;
        if (root.owner >= 0) sub_tests[root.owner][root.slot] = stats.node_tests - before;
        if (root.stage >= 0) stage_root_tests[split_of[root.pair]][root.stage] = stats.node_tests - before;
        if (whole[root.pair] != 0) finalize_whole(state, root.pair, w);
      }
      record.task_node_tests[t] = tests;
      if (plan.weighted) record.task_weights[t] = plan.run[t].weight;
    });
  });
  flush_pieces(state);
  record.traverse_ms = util::ms_since(phase);
  const auto finalize_start = util::Clock::now();
  for (std::size_t t = 0; t < plan.taboos.size(); ++t) {
    for (std::size_t k = 0; k < plan.taboos[t].nodes.size(); ++k) {
      if (!reached[t][k]) record.taboo_unreached_node_tests += sub_tests[t][k];
    }
  }
  finalize_pairs(state, rest, [&](std::size_t i, std::vector<narrow::Candidate>& all, QueryStats& stats) {
    if (split_of[i] == SIZE_MAX) return;
    const plans::SplitResult& s = plan.splits[split_of[i]];
    all = s.candidates;
    stats = s.stats;
  });
  record.finalize_ms = util::ms_since(finalize_start);
  return stage_root_tests;
}

void gather_step(const std::vector<ObjectPair>& pairs, std::vector<QueryResult>& results,
                 const std::vector<std::size_t>& candidates, StepResult& out) {
  const std::size_t n = pairs.size();
  out.limit_reached = false;
  out.stats = QueryStats{};
  // Where each pair's contacts go (a prefix sum), then the records and contacts written in parallel
  // (a lone pair's moved).
  std::vector<std::size_t> at(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const QueryResult& r = results[i];
    at[i + 1] = at[i] + r.contacts.size();
    out.limit_reached = out.limit_reached || r.limit_reached;
    out.stats.node_tests += r.stats.node_tests;
    out.stats.leaf_tests += r.stats.leaf_tests;
  }
  out.pair_records.resize(n);
  const auto record = [&](std::size_t i) {
    const QueryResult& r = results[i];
    out.pair_records[i] =
        PairRecord{pairs[i], r.stats, r.contacts.size(), r.limit_reached, i < candidates.size() ? candidates[i] : 0};
    CALIBER_ASSERT(std::all_of(r.contacts.begin(), r.contacts.end(),
                               [&](const Contact& c) { return c.object_a == pairs[i].a && c.object_b == pairs[i].b; }),
                   "the finalization wrote the pair's object ids");
  };
  if (n == 1) {  // the pair's contacts are the step's: moved, not copied
    record(0);
    out.contacts = std::move(results[0].contacts);
    return;
  }
  out.contacts.resize(at[n]);
  parallel::parallel_for(0, n, 1024, [&](std::size_t first, std::size_t last) {
    for (std::size_t i = first; i != last; ++i) {
      record(i);
      std::copy(results[i].contacts.begin(), results[i].contacts.end(),
                out.contacts.begin() + static_cast<std::ptrdiff_t>(at[i]));
    }
  });
}

}  // namespace caliber::schedule
