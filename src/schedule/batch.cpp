// Batch queries: one pair of models at many poses, in chunks. Each entry is caliber::query's own
// path (narrow::query_whole) in a parallel loop, or, for a few heavy entries, a pair of a run of
// the engine's method (the same traversal and finalization, split as a heavy pair is).

#include <algorithm>
#include <new>
#include <string>

#include "caliber/batch.h"
#include "caliber/engine.h"
#include "caliber/error.h"
#include "narrow/finalize.h"
#include "parallel/executor.h"
#include "schedule/engine_impl.h"

namespace caliber {
namespace {

/// Entries per run of the method: bounds the per-entry bookkeeping of a run (results, the workers'
/// slots) whatever the batch's size, and is large enough that the end of a run, where threads
/// wait for its last entries, is a small part of it.
constexpr std::size_t kChunk = 8192;

/// Entries traversed whole: at most this many to a job (few enough to balance heavy entries,
/// enough that a light entry's job costs little beside it).
constexpr std::size_t kWholeGrain = 4;

/// The contacts' storage a kept batch result may hold between chunks and calls (Engine::Impl::
/// batch_results): beyond it, let go after the chunk.
constexpr std::size_t kKeptContacts = 16;

void validate_poses(std::span<const Pose> poses, const char* side) {
  for (std::size_t i = 0; i < poses.size(); ++i) {
    try {
      validate_pose(poses[i]);
    } catch (const Error&) {
      validate_pose(poses[i], std::string("poses of ") + side + "[" + std::to_string(i) + "]");  // throws, naming it
    }
  }
}

/// Lets go of a kept result's contacts' storage past kKeptContacts (`= {}` would only clear it).
void let_go_if_large(QueryResult& r) {
  if (r.contacts.capacity() > kKeptContacts) std::vector<Contact>().swap(r.contacts);
}

/// Lets go of the large storage of an engine's kept results when a batch ends, however it ends: a
/// between_chunks that throws stops the call, and what its entries held goes with their answers.
struct LetGoOnExit {
  std::vector<QueryResult>& results;
  explicit LetGoOnExit(std::vector<QueryResult>& kept) : results(kept) {}
  LetGoOnExit(const LetGoOnExit&) = delete;
  LetGoOnExit& operator=(const LetGoOnExit&) = delete;
  ~LetGoOnExit() {
    for (QueryResult& r : results) let_go_if_large(r);
  }
};

/// Makes room in the batch's contacts for `adding` more, `done` of its `n` entries answered, `last`
/// their growth before (updated): schedule::batch_capacity where they do not fit; where that much
/// is refused, twice what is needed, else exactly that (which throws where refused too).
void make_room(std::vector<Contact>& contacts, std::size_t adding, std::size_t done, std::size_t n, schedule::BatchGrowth& last) {
  const std::size_t need = contacts.size() + adding;
  if (need <= contacts.capacity()) return;
  try {
    contacts.reserve(schedule::batch_capacity(need, done, n, contacts.max_size(), last));
  } catch (const std::bad_alloc&) {
    try {
      contacts.reserve(need <= contacts.max_size() / 2 ? 2 * need : need);
    } catch (const std::bad_alloc&) {
      contacts.reserve(need);
    }
  }
  last = schedule::BatchGrowth{need, done};
}

/// Appends an entry's answer to the batch's (its room made: make_room).
void append(BatchResult& out, const QueryResult& r) {
  out.contacts.insert(out.contacts.end(), r.contacts.begin(), r.contacts.end());
  out.offsets.push_back(out.contacts.size());
  out.limit_reached.push_back(r.limit_reached ? 1 : 0);
  out.stats.node_tests += r.stats.node_tests;
  out.stats.leaf_tests += r.stats.leaf_tests;
}

}  // namespace

BatchResult Engine::query_many(const Model& a, std::span<const Pose> poses_a, const Model& b, std::span<const Pose> poses_b,
                               const QueryRequest& request) {
  const schedule::OneCallAtATime hold(mImpl->busy, "query_many");
  const std::size_t n =
      schedule::entry_count(poses_a.size(), poses_b.size(), "poses", "or one pose to a side that does not move");
  validate_poses(poses_a, "A");
  validate_poses(poses_b, "B");
  validate_request(request);
  // (A contact query needs both models built with adjacency: refused before any work.)
  narrow::check_contact_models(request, a, b, "model A", "model B");
  BatchResult out;
  out.kind = request.kind;
  out.offsets.reserve(n + 1);
  out.limit_reached.reserve(n);
  EngineOptions options = mOptions;
  options.threads = mImpl->executor.threads();
  // Entries are not objects that persist from call to call: the calibrated methods plan with no
  // history, and the engine's is left as it is.
  const plans::History no_history;
  std::vector<QueryResult>& results = mImpl->batch_results;
  const LetGoOnExit let_go{results};
  mImpl->timeline.begin(false);
  schedule::BatchGrowth growth;
  for (std::size_t first = 0; first < n; first += kChunk) {
    if (first > 0 && mOptions.between_chunks) mOptions.between_chunks();
    const std::size_t count = std::min(kChunk, n - first);
    const auto context = [&](std::size_t i) {  // entry first + i's
      const std::size_t e = first + i;
      return narrow::PairContext(a, poses_a[poses_a.size() == 1 ? 0 : e], b, poses_b[poses_b.size() == 1 ? 0 : e], request,
                                 narrow::PairContext::Validated{});
    };
    // With max_pairs, which pairs an entry keeps depends on the order its traversal met them: one
    // thread traverses each entry whole, in caliber::query's order. So does a run of many entries.
    if (request.max_pairs != 0 || count >= schedule::kEntriesPerThread * static_cast<std::size_t>(options.threads) ||
        mOptions.method == Method::sequential) {
      // Each entry's result rewritten whole, its storage reused. On one thread the entries come in
      // order: each answer goes straight into the batch's, through one result (none held an entry).
      const bool in_order = options.threads == 1;
      results.resize(in_order ? 1 : count);
      mImpl->executor.execute([&] {
        if (in_order) {
          for (std::size_t i = 0; i != count; ++i) {
            narrow::query_whole(context(i), results[0]);
            make_room(out.contacts, results[0].contacts.size(), first + i + 1, n, growth);
            append(out, results[0]);
          }
          return;
        }
        parallel::parallel_for(0, count, kWholeGrain, [&](std::size_t lo, std::size_t hi) {
          for (std::size_t i = lo; i != hi; ++i) narrow::query_whole(context(i), results[i]);
        });
      });
      if (in_order) continue;
    } else {
      options.stealing_depth = schedule::stealing_cutoff(count, options.threads, mOptions.stealing_depth);
      const std::vector<ObjectPair> chunk_pairs(count, ObjectPair{0, 1});  // the object ids every contact carries
      ScheduleRecord record;
      const auto make = [&](std::size_t i, void* where) { new (where) narrow::PairContext(context(i)); };
      mImpl->run_pairs(options, mOptions.method, chunk_pairs, request, no_history, make, results, record);
    }
    std::size_t adding = 0;
    for (const QueryResult& r : results) adding += r.contacts.size();
    make_room(out.contacts, adding, first + count, n, growth);
    for (QueryResult& r : results) {
      append(out, r);
      let_go_if_large(r);
    }
  }
  return out;
}

}  // namespace caliber
