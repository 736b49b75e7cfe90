// Finalization of one object pair: the contact reduction, the canonical sort, world coordinates.

#include "narrow/finalize.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>

#include "caliber/error.h"
#include "narrow/local_minima.h"
#include "parallel/executor.h"
#include "util/assert.h"
#include "util/radix_sort.h"

namespace caliber {
namespace narrow {
namespace {

bool by_ids(const Candidate& x, const Candidate& y) { return x.tri_a != y.tri_a ? x.tri_a < y.tri_a : x.tri_b < y.tri_b; }

/// Whether `candidates` are strictly ascending in by_ids' order: sorted, each pair once (asserted).
[[maybe_unused]] bool sorted_once(const std::vector<Candidate>& candidates) {
  return std::adjacent_find(candidates.begin(), candidates.end(),
                            [](const Candidate& x, const Candidate& y) { return !by_ids(x, y); }) == candidates.end();
}

/// Contact::depth of an intersecting pair (A's frame): the largest depth of B's vertices behind
/// the plane through A's closest point with the contact normal.
double depth_estimate(const PairContext& ctx, const Candidate& c, const Eigen::Vector3d& normal) {
  const double plane = normal.dot(c.point_a);
  double depth = 0.0;
  for (int k = 0; k < 3; ++k) depth = std::max(depth, plane - normal.dot(ctx.b_vertex(c.tri_b, k)));
  return depth;
}

/// A kept candidate as a Contact in world coordinates (A's pose; `ra` its rotation matrix): the
/// normal from A to B (the direction between the points, else A's face normal, else B's), and the
/// depth of an intersecting pair.
Contact world_contact(const PairContext& ctx, const Candidate& c, ObjectPair objects, const Eigen::Matrix3d& ra) {
  const Pose& pose = ctx.pose_a();
  Contact contact;
  contact.object_a = objects.a;
  contact.object_b = objects.b;
  contact.tri_a = c.tri_a;
  contact.tri_b = c.tri_b;
  contact.distance = c.distance;
  contact.point_a = ra * c.point_a + pose.translation;
  contact.point_b = ra * c.point_b + pose.translation;
  const Eigen::Vector3d gap = c.point_b - c.point_a;
  const double gap_norm = gap.norm();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  if (c.distance > 0.0 && gap_norm > 0.0) {
    normal = gap / gap_norm;
  } else if (ctx.a().normals[c.tri_a].squaredNorm() > 0.0) {
    normal = ctx.a().normals[c.tri_a];
  } else if (ctx.b().normals[c.tri_b].squaredNorm() > 0.0) {
    normal = -(ctx.rotation_b_to_a() * ctx.b().normals[c.tri_b]).normalized();
  }
  contact.normal = ra * normal;
  if (c.distance == 0.0 && normal.squaredNorm() > 0.0) contact.depth = depth_estimate(ctx, c, normal);
  return contact;
}

/// A distance query's answer: each traversal (a whole pair, or one piece of it) brought its closest
/// pair; the closest of those, ties to the lowest ids, is the pair's answer whatever the cut. At 0,
/// pieces stopped at their own first intersecting pair: the traversal from the root finds its own
/// again. (Its tests are not the pair's counters, which stay the sum of what its pieces did.)
Candidate closest(const PairContext& ctx, const std::vector<Candidate>& candidates, ContactPair contact_pair) {
  const Candidate best = *std::min_element(candidates.begin(), candidates.end(), closer);
  const bool again = best.distance == 0.0 && !ctx.request().lowest_ids && contact_pair == ContactPair::from_root;
  return again ? first_contact(ctx) : best;
}

/// Up to this many candidates, an interference result sorts the candidates themselves.
constexpr std::size_t kFewCandidates = 8;

/// An interference result: the triangles meet, so a candidate is its ids alone (no points). They
/// are sorted as one integer each (A's id above B's, in as few bits as the largest ids need:
/// by_ids' order), which moves 8 bytes where sorting the candidates moves 64; serially by radix.
/// But a few (kFewCandidates), sorted in place. Appends to result.contacts.
void interference_result(std::vector<Candidate>& candidates, ObjectPair objects, bool parallel, QueryResult& result) {
  // Each contact copied from one made here (an empty Contact is cleared byte by byte, a slow
  // string store on 104 bytes, before its fields are written again).
  Contact made;
  made.object_a = objects.a;
  made.object_b = objects.b;
  made.point_a = made.point_b = made.normal = Eigen::Vector3d::Zero();
  const auto add = [&](std::uint32_t tri_a, std::uint32_t tri_b) {
    made.tri_a = tri_a;
    made.tri_b = tri_b;
    result.contacts.push_back(made);
  };
  // A few (a first hit's): sorted where they are, no keys made.
  if (candidates.size() <= kFewCandidates) {
    std::sort(candidates.begin(), candidates.end(), by_ids);
    CALIBER_ASSERT(sorted_once(candidates), "each triangle pair is a candidate once");
    result.contacts.reserve(candidates.size());
    for (const Candidate& c : candidates) add(c.tri_a, c.tri_b);
    return;
  }
  std::uint32_t most_a = 0, most_b = 0;
  for (const Candidate& c : candidates) {
    most_a = std::max(most_a, c.tri_a);
    most_b = std::max(most_b, c.tri_b);
  }
  const int shift = util::bits_of(most_b);
  const std::uint64_t low = (std::uint64_t{1} << shift) - 1;
  std::vector<std::uint64_t> keys(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) keys[i] = std::uint64_t{candidates[i].tri_a} << shift | candidates[i].tri_b;
  // Ids are unique, so every sort gives the same order: the parallel one is safe for determinism.
  // Serial radix below kParallelSortKeys (finalize.h).
  if (parallel && keys.size() >= kParallelSortKeys) {
    parallel::parallel_sort(keys.begin(), keys.end(), std::less<>());
  } else {
    std::vector<std::uint64_t> spare;
    util::radix_sort(keys, shift + util::bits_of(most_a), spare);
  }
  CALIBER_ASSERT(std::adjacent_find(keys.begin(), keys.end()) == keys.end(), "each triangle pair is a candidate once");
  // Each contact written once (a resize would clear them all in a pass of its own).
  result.contacts.reserve(keys.size());
  for (const std::uint64_t key : keys) add(static_cast<std::uint32_t>(key >> shift), static_cast<std::uint32_t>(key & low));
}

/// The reduction's models have adjacency (refused before any work by every caller:
/// check_contact_models).
void check_adjacency(const PairContext& ctx) {
  if (!ctx.a().has_adjacency() || !ctx.b().has_adjacency()) {
    throw Error(ErrorCode::bad_argument, "contact query", "a model was built without adjacency (BuildOptions::adjacency)");
  }
}

/// The kept candidates sorted by ids (each pair once) and written to result.contacts in world
/// coordinates, in chunks of `grain` where `parallel` (a grain of the whole list: this thread).
void sort_and_place(const PairContext& ctx, std::vector<Candidate>& candidates, ObjectPair objects, bool parallel,
                    std::size_t grain, QueryResult& result) {
  // Ids are unique, so every sort gives the same order: the parallel one is safe for determinism.
  if (parallel && candidates.size() >= kFinalizeGrain) {
    parallel::parallel_sort(candidates.begin(), candidates.end(), by_ids);
  } else {
    std::sort(candidates.begin(), candidates.end(), by_ids);
  }
  CALIBER_ASSERT(sorted_once(candidates), "a pair's candidates are sorted by triangle ids, each pair once");
  const Eigen::Matrix3d ra = ctx.pose_a().rotation_matrix();
  result.contacts.resize(candidates.size());
  const auto contacts = [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i != hi; ++i) result.contacts[i] = world_contact(ctx, candidates[i], objects, ra);
  };
  // Serial: called here, not through parallel_for's std::function (an allocation per query).
  if (candidates.size() <= grain) {
    contacts(0, candidates.size());
  } else {
    parallel::parallel_for(0, candidates.size(), grain, contacts);
  }
}

}  // namespace

void check_contact_models(const QueryRequest& request, const Model& a, const Model& b, std::string_view name_a,
                          std::string_view name_b) {
  if (request.kind != QueryKind::contact || (a.has_adjacency() && b.has_adjacency())) return;
  const std::string which = !a.has_adjacency() && !b.has_adjacency()
                                ? std::string(name_a) + " and " + std::string(name_b) + " were"
                                : std::string(a.has_adjacency() ? name_b : name_a) + " was";
  throw Error(ErrorCode::bad_argument, "contact query",
              which + " built without adjacency (BuildOptions::adjacency), which the contacts' reduction needs");
}

void finalize(const PairContext& ctx, std::vector<Candidate>& candidates, const QueryStats& stats, ObjectPair objects,
              ContactPair contact_pair, bool parallel, QueryResult& result) {
  // Serial unless asked: a grain as large as the input keeps parallel_for on this thread.
  const std::size_t grain = parallel ? kFinalizeGrain : std::max<std::size_t>(candidates.size(), 1);
  result.kind = ctx.request().kind;
  result.stats = stats;
  result.limit_reached = false;
  result.contacts.clear();
  // At the limit: flagged (the traversals stopped there, so there may be more); over it (split
  // traversals may keep a few more between them), the max_pairs lowest ids of what was found.
  const std::size_t max_pairs = ctx.request().max_pairs;
  if (max_pairs != 0 && result.kind != QueryKind::distance && candidates.size() >= max_pairs) {
    if (candidates.size() > max_pairs) {
      std::nth_element(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(max_pairs), candidates.end(), by_ids);
      candidates.resize(max_pairs);
    }
    result.limit_reached = true;
  }
  // Contacts: the local minima first (their verdicts do not depend on the order), so that only the
  // few kept candidates are sorted, not every pair within the tolerance.
  if (result.kind == QueryKind::contact) {
    check_adjacency(ctx);
    candidates = local_minima(ctx, candidates, grain);
  }
  if (result.kind == QueryKind::distance && !candidates.empty()) {
    const Candidate best = closest(ctx, candidates, contact_pair);
    candidates.assign(1, best);  // in the caller's storage (query_whole keeps it from call to call)
  }
  if (result.kind == QueryKind::interference) {
    interference_result(candidates, objects, parallel, result);
    return;
  }
  sort_and_place(ctx, candidates, objects, parallel, grain, result);
}

QueryResult finalize_contacts(const PairContext& ctx, const CandidateLists& lists, const QueryStats& stats, ObjectPair objects,
                              bool parallel) {
  CALIBER_ASSERT(ctx.request().kind == QueryKind::contact && ctx.request().max_pairs == 0,
                 "a contact query without a limit: its candidates all go to the reduction");
  check_adjacency(ctx);
  const std::size_t grain = parallel ? kFinalizeGrain : std::max<std::size_t>(lists.size(), 1);
  QueryResult result;
  result.kind = QueryKind::contact;
  result.stats = stats;
  result.limit_reached = false;
  std::vector<Candidate> kept = local_minima(ctx, lists, grain);
  sort_and_place(ctx, kept, objects, parallel, grain, result);
  return result;
}

QueryResult finalize(const PairContext& ctx, std::vector<Candidate>& candidates, const QueryStats& stats, ObjectPair objects,
                     ContactPair contact_pair, bool parallel) {
  QueryResult result;
  finalize(ctx, candidates, stats, objects, contact_pair, parallel, result);
  return result;
}

}  // namespace narrow

}  // namespace caliber
