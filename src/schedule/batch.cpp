// Batch queries: one pair of models at many poses, run as the engine runs a frame's pairs (each
// entry one pair of the run, the same traversal and finalization), in chunks.

#include <algorithm>
#include <new>
#include <string>

#include "caliber/batch.h"
#include "caliber/engine.h"
#include "caliber/error.h"
#include "schedule/engine_impl.h"

namespace caliber {
namespace {

/// Entries per run of the method: bounds the per-entry bookkeeping of a run (results, the workers'
/// slots) whatever the batch's size, and is large enough that the end of a run, where threads
/// wait for its last entries, is a small part of it.
constexpr std::size_t kChunk = 8192;

/// The number of entries of a batch whose sides give `na` and `nb` poses; throws on counts that
/// do not match.
std::size_t entries(std::size_t na, std::size_t nb) {
  if (na == nb || nb == 1) return na;
  if (na == 1) return nb;
  throw Error(ErrorCode::bad_argument, "poses",
              std::to_string(na) + " poses of A but " + std::to_string(nb) +
                  " of B (give both sides the same number, or one pose to a side that does not move)");
}

/// Stealing: how deep a run of `n` entries is split. Every level above the cut-off is split work
/// (and a split distance traversal's pieces each look for their own nearest pair, more node tests
/// than one traversal), so only as deep as it takes to give each thread eight pieces: not at all
/// for a batch of many entries, a few levels for a few heavy ones; never deeper than the engine's
/// stealing depth.
int stealing_cutoff(std::size_t n, int threads, int stealing_depth) {
  int depth = 0;
  for (std::size_t pieces = n; depth < stealing_depth && pieces < 8 * static_cast<std::size_t>(threads); pieces *= 4) ++depth;
  return depth;
}

void validate_poses(std::span<const Pose> poses, const char* side) {
  for (std::size_t i = 0; i < poses.size(); ++i) {
    try {
      validate_pose(poses[i]);
    } catch (const Error&) {
      validate_pose(poses[i], std::string("poses of ") + side + "[" + std::to_string(i) + "]");  // throws, naming it
    }
  }
}

}  // namespace

BatchResult Engine::query_many(const Model& a, std::span<const Pose> poses_a, const Model& b, std::span<const Pose> poses_b,
                               const QueryRequest& request) {
  const schedule::OneCallAtATime hold(mImpl->busy, "query_many");
  const std::size_t n = entries(poses_a.size(), poses_b.size());
  validate_poses(poses_a, "A");
  validate_poses(poses_b, "B");
  validate_request(request);
  BatchResult out;
  out.kind = request.kind;
  out.offsets.reserve(n + 1);
  out.limit_reached.reserve(n);
  EngineOptions options = mOptions;
  options.threads = mImpl->executor.threads();
  // With max_pairs, which pairs an entry keeps depends on the order its traversal met them: one
  // thread traverses each entry whole, in caliber::query's order.
  const Method method = request.max_pairs != 0 && mOptions.method != Method::sequential ? Method::exploitation : mOptions.method;
  // Entries are not objects that persist from call to call: the calibrated methods plan with no
  // history, and the engine's is left as it is.
  const tasks::History no_history;
  std::vector<QueryResult> results;
  mImpl->timeline.begin(false);
  for (std::size_t first = 0; first < n; first += kChunk) {
    const std::size_t count = std::min(kChunk, n - first);
    const std::vector<ObjectPair> chunk_pairs(count, ObjectPair{0, 1});  // the object ids every contact carries
    const auto make = [&](std::size_t i, void* where) {
      const std::size_t e = first + i;
      new (where) narrow::PairContext(a, poses_a[poses_a.size() == 1 ? 0 : e], b, poses_b[poses_b.size() == 1 ? 0 : e], request);
    };
    options.stealing_depth = stealing_cutoff(count, options.threads, mOptions.stealing_depth);
    ScheduleRecord record;
    mImpl->run_pairs(options, method, chunk_pairs, request, no_history, make, results, record);
    for (const QueryResult& r : results) {
      out.contacts.insert(out.contacts.end(), r.contacts.begin(), r.contacts.end());
      out.offsets.push_back(out.contacts.size());
      out.limit_reached.push_back(r.limit_reached ? 1 : 0);
      out.stats.node_tests += r.stats.node_tests;
      out.stats.leaf_tests += r.stats.leaf_tests;
    }
  }
  return out;
}

}  // namespace caliber
