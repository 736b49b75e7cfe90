#pragma once
/// \file
/// The contact query's reduction of a pair's candidates to their local minima.

#include <cstddef>
#include <vector>

#include "narrow/candidate.h"
#include "narrow/nearby_look.h"
#include "narrow/pair_context.h"

namespace caliber::narrow {

/// The reduction's look at each candidate's neighbours in the list (detail::NearbyLook): the
/// AVX-512 form where this CPU has it, else the AVX2 form, else null (the portable form), chosen
/// when the library loads.
extern const detail::NearbyLook kNearbyLook;

/// Quasi-LMD reduction: keeps a candidate unless a candidate that shares one of its triangles and
/// whose other triangle is vertex-adjacent to its own (ModelData::are_neighbours) is closer
/// (`closer`: ties to the lower ids). Each verdict depends only on the set of candidates, not on
/// their order, so they need no sorting first; the kept ones are returned in the input's order.
/// Linear in the candidates times the adjacency's degree, that degree taken at most 32 a vertex
/// (a vertex with more corners at it answers for its candidates by their closest); in
/// chunks of `grain` on the current executor (a grain as large as the input keeps it on this
/// thread). Both models need adjacency.
std::vector<Candidate> local_minima(const PairContext& ctx, const std::vector<Candidate>& candidates, std::size_t grain);

}  // namespace caliber::narrow
