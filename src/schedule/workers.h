#pragma once
/// \file
/// What every runner of the engine writes into during a step: each worker thread's candidates and
/// counts per pair (merged by the one finalization), and the optional timeline of who ran what when.

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "caliber/engine.h"
#include "caliber/profile.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"
#include "parallel/executor.h"
#include "util/timing.h"

namespace caliber::schedule {

/// One worker's output for a step: candidates and work per pair, and its traversal stack.
struct WorkerSlots {
  narrow::TraversalScratch scratch;
  std::vector<std::vector<narrow::Candidate>> candidates;  ///< per pair
  std::vector<QueryStats> stats;                           ///< per pair
  std::vector<std::uint64_t> pieces;                       ///< stealing: node tests of each depth-first piece
  std::uint64_t split_node_tests = 0;                      ///< stealing: node tests above the cut-off
  /// The run (StepState::run) whose work the slots hold: the slots of a thread that took no part
  /// in the current run are stale, and read as empty.
  std::uint64_t run = 0;

  void reset(std::size_t pairs) {
    scratch.drop_pieces();  // (what an earlier run stopped by an error left)
    candidates.resize(pairs);
    stats.assign(pairs, QueryStats{});
    for (auto& c : candidates) c.clear();
    pieces.clear();
    split_node_tests = 0;
  }
};

using Workers = parallel::PerThread<WorkerSlots>;

/// Optional record of who ran what when (EngineOptions::timeline), for Gantt charts.
struct Timeline {
  bool on = false;
  util::Clock::time_point origin;
  parallel::PerThread<std::vector<TaskSpan>> spans;

  /// Runs f(), recording its span on this thread when the timeline is on (`unit`: TaskSpan::unit).
  template <class F>
  void record(TaskSpan::Phase phase, std::size_t unit, F&& f) {
    if (!on) {
      f();
      return;
    }
    const auto start = util::Clock::now();
    f();
    const auto end = util::Clock::now();
    const int thread = std::max(parallel::current_thread_index(), 0);
    spans.local().push_back(TaskSpan{thread, util::ms_between(origin, start), util::ms_between(origin, end), phase,
                                     static_cast<std::uint32_t>(unit)});
  }

  /// Starts a step: clears the spans and sets the time origin.
  void begin(bool enabled) {
    on = enabled;
    spans.for_each([](std::vector<TaskSpan>& s) { s.clear(); });
    origin = util::Clock::now();
  }

  /// All spans, sorted by thread then start; threads numbered 0, 1, ... in the order of their
  /// executor indices (in a host's arena a thread's slot may lie beyond the step's thread count).
  std::vector<TaskSpan> collect() {
    std::vector<TaskSpan> all;
    spans.for_each([&](const std::vector<TaskSpan>& s) { all.insert(all.end(), s.begin(), s.end()); });
    std::vector<int> seen;
    for (const TaskSpan& s : all) seen.push_back(s.thread);
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    for (TaskSpan& s : all) s.thread = static_cast<int>(std::lower_bound(seen.begin(), seen.end(), s.thread) - seen.begin());
    std::sort(all.begin(), all.end(), [](const TaskSpan& a, const TaskSpan& b) {
      return a.thread != b.thread ? a.thread < b.thread : a.start_ms < b.start_ms;
    });
    return all;
  }
};

/// What a runner works on in one step: the pairs' contexts, the workers' slots, the timeline, and
/// where each pair's finalized result goes.
struct StepState {
  narrow::PairContexts contexts;
  Workers& workers;
  Timeline& timeline;
  std::vector<QueryResult>& results;
  bool parallel_finalize = true;  ///< let one heavy pair's finalization use several threads
  /// Per pair: what its traversals share (kept pairs against QueryRequest::max_pairs, a distance
  /// query's nearest distance so far); null when there is neither a limit nor a distance query.
  narrow::PairShared* shared = nullptr;
  /// Per pair: the candidates its finalization took in (sized by the runner, filled by the
  /// finalization).
  std::vector<std::size_t> candidates;
  /// The frame's object pairs (the ids each pair's contacts carry).
  const ObjectPair* pairs = nullptr;
  /// What the pair's traversals share, or null.
  [[nodiscard]] narrow::PairShared* shared_of(std::size_t pair) const { return shared != nullptr ? &shared[pair] : nullptr; }
  /// This run's number (Engine::Impl counts them): a worker's slots are reset by its own thread
  /// when it first works in a run (in parallel, not one thread for all of them), and slots of
  /// another run are stale.
  std::uint64_t run = 0;

  /// Whether w holds this run's work.
  [[nodiscard]] bool current(const WorkerSlots& w) const { return w.run == run; }
};

/// This thread's slots for the run, reset for it on the first call in the run.
inline WorkerSlots& local_slots(StepState& state) {
  WorkerSlots& w = state.workers.local();
  if (w.run != state.run) {
    w.reset(state.contexts.size());
    w.run = state.run;
  }
  return w;
}

/// Pair i, traversed whole by the worker `w` (every candidate and count of it in w's slots), through
/// the one finalization (narrow/finalize.h) into state.results, on the calling thread: what a
/// runner does at the end of the task that traversed it.
void finalize_whole(StepState& state, std::size_t i, WorkerSlots& w);

/// The pairs `rest` (those not finalized by finalize_whole), in parallel, most candidates first:
/// `start` seeds a pair's candidates and counts (work done outside the workers' slots), every
/// worker's slots are added, and the pair goes through the one finalization into state.results.
void finalize_pairs(StepState& state, const std::vector<std::uint32_t>& rest,
                    const std::function<void(std::size_t, std::vector<narrow::Candidate>&, QueryStats&)>& start);

/// The reduction of a step: per-pair records and the contacts of every pair, in pair order (pairs
/// are sorted and each result is sorted, so the concatenation is canonical). Fills out.pair_records,
/// out.contacts and out.stats (each record with its pair's entry of `candidates`, 0 past its
/// end), the pairs in parallel on the executor the caller runs in. Each
/// result's contacts carry its pair's object ids already. A lone pair's contacts are moved out of
/// its result (the step's contacts are its contacts), the others copied.
void gather_step(const std::vector<ObjectPair>& pairs, std::vector<QueryResult>& results,
                 const std::vector<std::size_t>& candidates, StepResult& out);

}  // namespace caliber::schedule
