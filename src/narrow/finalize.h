#pragma once
/// \file
/// The one finalization of an object pair's candidates, shared by caliber::query and every method
/// of the engine, so that the contacts do not depend on how the traversal was cut.

#include <cstddef>
#include <string_view>
#include <vector>

#include "caliber/engine.h"
#include "caliber/query.h"
#include "narrow/local_minima.h"
#include "narrow/pair_context.h"

namespace caliber::narrow {

/// Below this many candidates a pair is finalized serially; above, its local-minimum test, sort
/// and world transform run in chunks of this many on several threads (one heavy pair's
/// finalization would otherwise be serial work). But an interference result's keys are sorted
/// serially below kParallelSortKeys, and a contact reduction's hash index is filled by one thread
/// while the others run the list's look, on fewer than six threads (local_minima).
inline constexpr std::size_t kFinalizeGrain = 128;
/// From this many, an interference result's keys are sorted on the engine's threads. Below, the
/// serial radix sort: on 2 threads it was the faster on a few thousand keys (TBB's parallel sort
/// cost more than it shared out); between that and this bound it was not measured.
inline constexpr std::size_t kParallelSortKeys = std::size_t{1} << 20;

/// How many pieces of work the finalization of a pair of `candidates` runs in, on the engine's
/// threads (what the load-balance simulation replays): chunks of kFinalizeGrain, but one for an
/// interference result below kParallelSortKeys (it is serial).
inline std::size_t finalize_chunks(QueryKind kind, std::size_t candidates) {
  if (candidates < kFinalizeGrain || (kind == QueryKind::interference && candidates < kParallelSortKeys)) return 1;
  return (candidates + kFinalizeGrain - 1) / kFinalizeGrain;
}

/// Where a distance answer of 0 comes from. as_found: the candidates came from one traversal from
/// the root (caliber::query's, or a method's pair traversed whole, whose first hit is the answer;
/// on models with at most 16 triangle pairs, all tested, the lowest ids) or from the brute force
/// (the lowest ids).
/// from_root: they came from pieces of the traversal (a method's tasks), each stopped at its own
/// first intersecting pair; the answer is that of the traversal from the root (its first hit),
/// found again here, so that it does not depend on the cut.
enum class ContactPair { as_found, from_root };

/// Applies the contact reduction (local minima) for contact queries, sorts the candidates of one
/// object pair canonically (by triangle ids) and converts them to world coordinates, as contacts
/// between `objects` (their ids in the frame; 0 and 1 for caliber::query). With
/// `parallel`, a large candidate list is processed by several jobs of the current executor (same
/// result). A distance query's closest pair is the candidates' closest, ties to the lowest ids, but
/// at distance 0 as `contact_pair` says (unless the request asks for the lowest ids).
QueryResult finalize(const PairContext& ctx, std::vector<Candidate>& candidates, const QueryStats& stats, ObjectPair objects,
                     ContactPair contact_pair, bool parallel = false);
/// finalize into `result`, every field of it written, its contacts' storage reused (what a batch
/// keeps from entry to entry: no allocation once it has grown).
void finalize(const PairContext& ctx, std::vector<Candidate>& candidates, const QueryStats& stats, ObjectPair objects,
              ContactPair contact_pair, bool parallel, QueryResult& result);

/// finalize for a contact query without a limit (QueryRequest::max_pairs 0) whose candidates are
/// the concatenation of `lists`: the local minima read where the candidates are (not copied into
/// one list first), then sorted and in world coordinates, as finalize makes them.
QueryResult finalize_contacts(const PairContext& ctx, const CandidateLists& lists, const QueryStats& stats, ObjectPair objects,
                              bool parallel);

/// The intersecting pair the distance traversal from the root reports (its first hit: the pair
/// caliber::query reports on meshes that intersect; the lowest ids on models with at most 16
/// triangle pairs), on the calling thread with its kept scratch. Its node and leaf tests are counted nowhere. The
/// meshes must have a pair at distance 0.
Candidate first_contact(const PairContext& ctx);

/// Whether ctx's query is a distance query that asks for the first hit before its own traversal
/// (not the lowest ids, QueryRequest::first_hit; more than kFewPairs triangle pairs).
bool takes_first_hit(const PairContext& ctx);
/// For such a query (takes_first_hit) on meshes that intersect: the first hit from the root, the
/// pair's answer as caliber::query finds it, written to `hit` (its tests counted in `stats`), on
/// the calling thread with its kept scratch: true. Else false. What a schedule asks before it cuts
/// such a pair (its pieces would each look for a contact of their own).
bool answered_by_first_hit(const PairContext& ctx, Candidate& hit, QueryStats& stats);

/// One pair's whole query on the calling thread: the depth-first or distance traversal from the
/// root (stopping at the request's max_pairs) and the finalization, with the thread's kept
/// scratch and candidate storage (let go past 2 MiB). What caliber::query runs, and the batch for
/// every entry it does not split.
QueryResult query_whole(const PairContext& ctx);
/// query_whole into `result` (finalize's form that reuses the result's storage).
void query_whole(const PairContext& ctx, QueryResult& result);

/// Throws caliber::Error (bad_argument, "contact query") where `request` is a contact query and a
/// model lacks adjacency (BuildOptions::adjacency), which the contacts' reduction needs, naming it
/// as `name_a` or `name_b`. Made before any work by every caller of a contact query.
void check_contact_models(const QueryRequest& request, const Model& a, const Model& b, std::string_view name_a,
                          std::string_view name_b);

}  // namespace caliber::narrow
