#pragma once
/// \file
/// The two runners of the engine. The plan runner executes any method's plan (plans/plan.h): the
/// run-time tasks handed out in order, each traversed depth first by one thread, which also
/// finalizes the pairs it holds whole; the pairs cut into pieces are finalized once every task is
/// done (the same finalization per pair either way). Stealing has its own runner (recursive
/// splitting on work stealing). Both fill the same ScheduleRecord.

#include <cstdint>
#include <vector>

#include "caliber/engine.h"
#include "caliber/profile.h"
#include "schedule/workers.h"
#include "plans/plan.h"

namespace caliber::schedule {

/// The split pairs' last leaf pairs, which each worker's pieces carried (narrow::PieceCarry),
/// finished into its slots, a worker a job: what a runner calls once every piece is done, before
/// the pairs are finalized.
void flush_pieces(StepState& state);

/// Runs `plan` on the current executor; fills state.results and, in `record`, the plan's counts,
/// the node tests and weight of every run-time task, the stage's counts, traverse_ms and
/// finalize_ms. Returns, per split of the plan, the depth-first node tests of each stage record's
/// root (plans::subtree_counts reads them).
std::vector<std::vector<std::uint64_t>> run_plan(const plans::Plan& plan, StepState& state, ScheduleRecord& record);

/// Stealing: the CD tree of every heavy pair (its share of the work at least 1 / (64 x threads):
/// the larger of its share of the a priori weight and of the weights that count node tests, last
/// step's from `history`, keyed by `pairs`, else the a priori weight scaled to node tests) split
/// recursively into jobs down to `depth` (no deeper than wide_depth in the wide CD tree, where a
/// pair with node tests last step goes only as deep as its share asks, and nearest_depth in a
/// distance query's), the other pairs whole, then each subtree traversed depth
/// first; oneTBB's scheduler steals the pieces. Fills state.results and, in `record`, the pieces'
/// node tests (largest first), the splitting's node tests, traverse_ms and finalize_ms. The node
/// tests are exactly those of one depth-first traversal per pair. A heavy pair of a distance query
/// that takes the first hit asks for it first (narrow::answered_by_first_hit, one piece): where
/// the meshes intersect it is the pair's answer, finalized at once, and the pair is not cut.
/// `threads`: the threads the work is cut for (EngineOptions::plan_threads, else the step's); on
/// one, nothing is split (every pair runs whole: there is nothing to balance).
void run_stealing(int depth, int threads, const std::vector<ObjectPair>& pairs, const plans::History& history, StepState& state,
                  ScheduleRecord& record);

}  // namespace caliber::schedule
