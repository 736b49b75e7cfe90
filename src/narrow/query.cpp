// The query front-end: one object pair, one traversal, and the brute-force oracle beside it.

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <tuple>

#include "caliber/error.h"
#include "caliber/engine.h"
#include "caliber/query.h"
#include "narrow/pair_context.h"
#include "narrow/finalize.h"
#include "narrow/traversal.h"
#include "util/assert.h"

namespace caliber {

std::string_view to_string(QueryKind kind) {
  switch (kind) {
    case QueryKind::interference:
      return "interference";
    case QueryKind::proximity:
      return "proximity";
    case QueryKind::contact:
      return "contact";
    case QueryKind::distance:
      return "distance";
  }
  return "unknown";
}

QueryKind parse_query_kind(std::string_view name) {
  if (name == "interference") return QueryKind::interference;
  if (name == "proximity") return QueryKind::proximity;
  if (name == "contact") return QueryKind::contact;
  if (name == "distance") return QueryKind::distance;
  throw Error(ErrorCode::bad_value, "kind",
              "unknown query kind '" + std::string(name) + "' (expected interference, proximity, contact or distance)");
}

void validate_request(const QueryRequest& request) {
  const bool unbounded = request.kind == QueryKind::distance && request.tolerance == kUnbounded;
  if (!unbounded && (!std::isfinite(request.tolerance) || request.tolerance < 0.0)) {
    throw Error(ErrorCode::bad_value, "tolerance",
                request.kind == QueryKind::distance ? "must be a number >= 0, or unbounded" : "must be a finite number >= 0");
  }
  if (request.tolerance > kMaxCoordinate && !unbounded) {
    throw Error(ErrorCode::bad_value, "tolerance", "must be at most 1e15 (caliber's limit on coordinates)");
  }
  if (request.tolerance > 0.0 && request.tolerance < kMinCoordinate) {
    throw Error(ErrorCode::bad_value, "tolerance",
                "must be 0 or at least 2^-120 (about 7.5e-37; caliber's exact predicates need no smaller)");
  }
  if (!std::isfinite(request.angle_deg) || request.angle_deg < 0.0 || request.angle_deg > 180.0) {
    throw Error(ErrorCode::bad_value, "angle", "must be a number of degrees in [0, 180]");
  }
}

namespace narrow {

namespace {

/// The most traversal scratch a thread keeps between whole queries.
constexpr std::size_t kKeptScratchBytes = std::size_t{2} << 20;

/// Kept from call to call on each thread: the distance queue's tables cost more to make than a
/// small query takes, and a batch's entries reuse the candidates' storage.
thread_local TraversalScratch t_scratch;
thread_local std::vector<Candidate> t_candidates;

/// A large query's scratch is let go: the thread would hold it, and every later query would clear
/// its tables. (Such a query takes far longer than making them again.)
void let_go_if_large() {
  if (t_scratch.footprint() > kKeptScratchBytes) t_scratch = TraversalScratch{};
}

}  // namespace

void query_whole(const PairContext& ctx, QueryResult& result) {
  std::vector<Candidate>& candidates = t_candidates;
  candidates.clear();
  QueryStats stats;
  PairShared limit;
  limit.max = ctx.request().max_pairs;
  traverse(ctx, NodePair{0, 0}, t_scratch, candidates, stats, RootTest::as_root, {}, limit.max != 0 ? &limit : nullptr);
  let_go_if_large();
  finalize(ctx, candidates, stats, ObjectPair{0, 1}, ContactPair::as_found, false, result);
  if (candidates.capacity() * sizeof(Candidate) > kKeptScratchBytes) std::vector<Candidate>().swap(candidates);
}

QueryResult query_whole(const PairContext& ctx) {
  QueryResult result;
  query_whole(ctx, result);
  return result;
}

Candidate first_contact(const PairContext& ctx) {
  CALIBER_ASSERT(ctx.request().kind == QueryKind::distance && !ctx.request().lowest_ids,
                 "the first contact is that of a distance traversal from the root that stops at contact");
  Nearest nearest;
  QueryStats stats;
  traverse_nearest(ctx, NodePair{0, 0}, t_scratch, nearest, stats);
  let_go_if_large();
  CALIBER_ASSERT(nearest.found && nearest.best.distance == 0.0, "the traversal from the root finds a pair at distance 0");
  return nearest.best;
}

bool takes_first_hit(const PairContext& ctx) {
  const QueryRequest& r = ctx.request();
  return r.kind == QueryKind::distance && !r.lowest_ids && r.first_hit && !few_pairs(ctx);
}

bool answered_by_first_hit(const PairContext& ctx, Candidate& hit, QueryStats& stats) {
  if (!takes_first_hit(ctx)) return false;
  Nearest nearest;
  const bool found = first_hit(ctx, t_scratch, nearest, stats);
  let_go_if_large();
  if (found) hit = nearest.best;
  return found;
}

}  // namespace narrow

QueryResult query(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request) {
  return narrow::query_whole(narrow::PairContext(a, pose_a, b, pose_b, request));
}

QueryResult query_brute_force(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b,
                              const QueryRequest& request) {
  const narrow::PairContext ctx(a, pose_a, b, pose_b, request);
  std::vector<narrow::Candidate> candidates;
  QueryStats stats;
  const auto na = static_cast<std::uint32_t>(a.triangle_count());
  const auto nb = static_cast<std::uint32_t>(b.triangle_count());
  // Distance: every pair against the tolerance (no bound from the pairs before it); the closest
  // kept, ties to the lowest ids, by a comparison of its own (the oracle shares no rule with the
  // traversal's Nearest).
  std::optional<narrow::Candidate> best;
  for (std::uint32_t ta = 0; ta < na; ++ta) {
    for (std::uint32_t tb = 0; tb < nb; ++tb) {
      ++stats.leaf_tests;
      if (request.kind != QueryKind::distance) {
        ctx.leaf_test(ta, tb, candidates);
      } else if (narrow::Candidate c; ctx.leaf_distance(ta, tb, request.tolerance, c)) {
        if (!best || std::tie(c.distance, c.tri_a, c.tri_b) < std::tie(best->distance, best->tri_a, best->tri_b)) best = c;
      }
    }
  }
  if (best) candidates.push_back(*best);
  return narrow::finalize(ctx, candidates, stats, ObjectPair{0, 1}, narrow::ContactPair::as_found);
}

}  // namespace caliber
