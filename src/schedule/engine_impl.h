#pragma once
/// \file
/// The engine's state between calls (Engine::Impl) and the pieces its entry points share:
/// Engine::step (schedule/engine.cpp) runs a frame's pairs, Engine::query_many
/// (schedule/batch.cpp) a batch's poses, both through run_pairs; Engine::sweep and
/// Engine::sweep_many (schedule/engine_sweep.cpp) run sweeps through run_sweeps, which splits a
/// heavy sweep's distance queries through run_pairs.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "broad/broad_phase.h"
#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/profile.h"
#include "narrow/pair_context.h"
#include "narrow/sweep_bounds.h"
#include "parallel/executor.h"
#include "schedule/workers.h"
#include "plans/plan.h"

namespace caliber::schedule {

/// A call's pair contexts, built into storage kept from call to call (no allocation once it has
/// grown to the largest call), in parallel for many pairs. The input is validated first, so no
/// context throws.
class ContextStore {
 public:
  /// Makes n contexts, context i by make(i, where) (a placement new at `where`).
  template <class Make>
  [[nodiscard]] narrow::PairContexts build(std::size_t n, Make&& make) {
    static_assert(std::is_trivially_destructible_v<narrow::PairContext>, "contexts are overwritten without destruction");
    if (mCapacity < n) {
      // A quarter more than asked: the pairs of a moving scene grow by a few from step to step,
      // and each regrowth is a fresh allocation whose pages are touched again. Left uninitialized
      // (no zeroing: 592 bytes a context, 35 MB at 60,000 pairs), the pages are first touched by
      // the parallel loop below.
      mCapacity = n + n / 4;
      mSlots.reset(new Slot[mCapacity]);
    }
    auto* const base = reinterpret_cast<narrow::PairContext*>(mSlots.get());
    // A context is quick to make (front_car's 209 take a negligible part of its step): chunks of 64
    // keep a small call on this thread and spread a large one.
    parallel::parallel_for(0, n, 64, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i != hi; ++i) make(i, static_cast<void*>(&base[i]));
    });
    return {std::launder(base), n};
  }

 private:
  struct alignas(narrow::PairContext) Slot {
    std::byte bytes[sizeof(narrow::PairContext)];
  };
  std::unique_ptr<Slot[]> mSlots;
  std::size_t mCapacity = 0;
};

/// Holds an engine for one call; a call made while another holds it is an Error (an engine keeps
/// state between steps: two steps at once would corrupt it).
class OneCallAtATime {
 public:
  OneCallAtATime(std::atomic<bool>& busy, const char* what) : mBusy(busy) {
    if (mBusy.exchange(true, std::memory_order_acquire)) {
      throw Error(ErrorCode::bad_argument, "engine",
                  std::string(what) +
                      " called while another call on the same engine is running (an engine runs one step at a time: "
                      "use one engine per thread)");
    }
  }
  ~OneCallAtATime() { mBusy.store(false, std::memory_order_release); }
  OneCallAtATime(const OneCallAtATime&) = delete;
  OneCallAtATime& operator=(const OneCallAtATime&) = delete;

 private:
  std::atomic<bool>& mBusy;
};

/// What one run of the method over a set of pairs leaves besides their results: the plan, and per
/// split of the plan the weight-driven stage's root counts (plans::subtree_counts reads them).
struct PairsRun {
  plans::Plan plan;
  std::vector<std::vector<std::uint64_t>> stage_root_tests;
  std::vector<std::size_t> candidates;  ///< per pair: the candidates its finalization took in
};

/// Below this many entries (a batch's poses, a sweep's pairs) per thread, the engine's method cuts
/// the work (a heavy entry split as a heavy pair is); from it up, each entry runs whole on one
/// thread (there are enough entries to share out, and splitting adds work: a split traversal's
/// pieces each start from their own root, and a distance query's prune only by what some piece has
/// found so far).
inline constexpr std::size_t kEntriesPerThread = 8;

/// Stealing: how deep a run of `n` entries is split: as deep as it takes to give each thread
/// kEntriesPerThread pieces, never deeper than the engine's stealing depth.
inline int stealing_cutoff(std::size_t n, int threads, int stealing_depth) {
  int depth = 0;
  for (std::size_t pieces = n; depth < stealing_depth && pieces < kEntriesPerThread * static_cast<std::size_t>(threads);
       pieces *= 4)
    ++depth;
  return depth;
}

/// A batch's contacts and entries answered when its contacts last grew (zeros before they did).
struct BatchGrowth {
  std::size_t contacts = 0;
  std::size_t entries = 0;
};

/// The capacity a batch's contacts grow to where `need` of them do not fit, `done` of its `n`
/// entries answered (those included), `last` their growth before: what the entries are on course
/// to give (need, and for each entry left what each gave since `last`: contacts come in runs, a
/// sweep's free poses before its colliding ones; a quarter more), at least twice and at most eight
/// times `need`, and at most `most` (never below need). Each reallocation of a large batch copies
/// its contacts and touches new pages, what it pays beside its queries (bench_batch's interference
/// on every pair); room reserved and never filled is address space no page backs (where the
/// system limits that, the batch keeps what it reserved while it lives).
inline std::size_t batch_capacity(std::size_t need, std::size_t done, std::size_t n, std::size_t most, BatchGrowth last = {}) {
  if (need >= most / 8) return std::max(need, most);  // (compared in integers: most may not be a double)
  const double at = static_cast<double>(need);
  const double since = static_cast<double>(done > last.entries ? done - last.entries : 1);
  const double rate = static_cast<double>(need - std::min(last.contacts, need)) / since;
  const double on_course = (at + rate * static_cast<double>(n > done ? n - done : 0)) * 1.25;
  // Below 8 need < most: the double converts back within size_t (rounded, at most a step off).
  const auto want = static_cast<std::size_t>(std::clamp(on_course, 2.0 * at, 8.0 * at));
  return std::clamp(want, need, most);
}

/// Distance queries of sweeps that went through the method (split across threads), counted over
/// the process: what the tests read to know that path ran (its answers are the same either way).
inline std::atomic<std::uint64_t> g_split_sweep_queries{0};

/// The number of entries of a call whose sides give `na` and `nb` items (a batch's poses, a sweep's
/// motions): both the same, or one side one item kept for every entry. Throws caliber::Error
/// (source `items`) naming the counts, `hint` saying what to give instead.
inline std::size_t entry_count(std::size_t na, std::size_t nb, const char* items, const char* hint) {
  if (na == nb || nb == 1) return na;
  if (na == 1) return nb;
  throw Error(ErrorCode::bad_argument, items,
              std::to_string(na) + " " + items + " of A but " + std::to_string(nb) + " of B (give both sides the same number, " +
                  hint + ")");
}

/// A sweep the engine runs: its two models and its advancement (done once it is over).
struct ActiveSweep {
  const Model* a;
  const Model* b;
  narrow::SweepAdvance advance;
  bool done = false;
};

}  // namespace caliber::schedule

namespace caliber {

struct Engine::Impl {
  Impl(int threads, HostExecutor* host) : executor(threads, host) {}
  /// Set while a step (or forget) runs: a second call meanwhile is refused, not a data race.
  std::atomic<bool> busy{false};
  parallel::Executor executor;
  schedule::Workers workers;
  /// run_pairs calls so far: the workers' slots hold the work of run `runs` (StepState::run).
  std::uint64_t runs = 0;
  /// What the temporal methods remember of each pair. Changes only how work is cut.
  plans::History history;
  /// Who ran what when, this step (EngineOptions::timeline).
  schedule::Timeline timeline;
  schedule::ContextStore contexts;
  /// The broad phase's tree and buffers (Engine::find_pairs).
  broad::State broad;
  /// This step's schedule record when nobody asked for it.
  ScheduleRecord record;
  /// A batch's results, entry by entry, kept from chunk to chunk and call to call: an entry
  /// traversed whole writes its contacts into storage already there (a batch of first hits or
  /// distances makes no allocation an entry). Storage grown past a few contacts is let go.
  std::vector<QueryResult> batch_results;

  /// Runs `method` over the pairs whose contexts `make` builds (schedule::ContextStore::build), on
  /// the engine's executor: fills results (one per pair; `pairs` are the object ids each pair's
  /// contacts carry), `record`, and with max_pairs the pairs' limits. A calibrated method plans with
  /// `history` (keyed by `pairs`). A distance query's pieces prune from the start by `nearest[i]`
  /// when given: a distance that some triangle pair of pair i has (PairContext::leaf_distance at
  /// these poses), which cannot change the answer. Leaves the workers' slots for the caller's
  /// bookkeeping. (Hidden: a member of the exported Engine's nested type would otherwise be
  /// exported.)
  [[gnu::visibility("hidden")]] schedule::PairsRun run_pairs(const EngineOptions& options, Method method,
                                                             const std::vector<ObjectPair>& pairs, const QueryRequest& request,
                                                             const plans::History& history,
                                                             const std::function<void(std::size_t, void*)>& make,
                                                             std::vector<QueryResult>& results, ScheduleRecord& record,
                                                             std::span<const double> nearest = {});
  /// Runs the sweeps to their ends on the engine's executor, in parallel over sweeps; when fewer
  /// than kEntriesPerThread a thread are left, a sweep whose last query was heavy makes its next
  /// one through run_pairs with `method` (split as a heavy pair is). Every query is
  /// caliber::query's answer, so every sweep is caliber::sweep's whatever the method and threads.
  /// `groups`: the sweeps' SweepRequest::groups.
  [[gnu::visibility("hidden")]] void run_sweeps(const EngineOptions& options, Method method,
                                                std::vector<schedule::ActiveSweep>& sweeps, const GroupCompatibility* groups);
};

}  // namespace caliber
