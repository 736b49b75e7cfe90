// The contact reduction: each candidate against the candidates next to it in the list, then
// against its neighbours' pairs through a table of the candidates' keys and distances.

#include "narrow/local_minima.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>

#include "narrow/nearby_look.h"
#include "parallel/executor.h"

namespace caliber::narrow {

const detail::NearbyLook kNearbyLook =
    detail::nearby_look_form(16) != nullptr ? detail::nearby_look_form(16) : detail::nearby_look_form(8);

namespace {

/// A candidate as the reduction reads it, 16 of its 64 bytes: its triangle pair as one key (A's id
/// in the high half, so that keys order as `closer` orders the ids) and its distance.
struct Entry {
  std::uint64_t key;
  double distance;
};

std::uint64_t key_of(std::uint32_t ta, std::uint32_t tb) { return (std::uint64_t{ta} << 32) | tb; }
std::uint32_t tri_a(std::uint64_t key) { return static_cast<std::uint32_t>(key >> 32); }
std::uint32_t tri_b(std::uint64_t key) { return static_cast<std::uint32_t>(key); }

/// `closer` on entries: the same order.
bool closer(const Entry& x, const Entry& y) { return x.distance != y.distance ? x.distance < y.distance : x.key < y.key; }

/// Below this many candidates the reduction's entries are made on the calling thread: a parallel
/// pass over a few thousand costs more in waking threads than it saves.
constexpr std::size_t kParallelFill = std::size_t{1} << 15;

/// From this many threads, the table of kParallelFill entries or more is filled by all of them
/// before the look (each slot claimed by compare-and-swap), not by one beside it. On two threads
/// (two_large, 71,000 entries) the shared fill took 0.54 ms, the fill in order 0.27 on one: four
/// times the cost an entry, so that one thread's fill holds up a look shared by about six or more
/// (a model of those figures; not measured beyond two threads).
constexpr int kSharedFillThreads = 6;

/// Where each entry sits, by its key: open addressing with linear probing, at most half full, four
/// bytes a slot (the table of a pair's 70,000 candidates fits in 1 MiB, so that filling it stays
/// in cache). Filled in order on this thread (the reduction runs the list's look meanwhile), or,
/// given a grain, in chunks of it on the executor's threads (a slot claimed by compare-and-swap;
/// which slot an entry gets may vary, what a lookup finds does not); then only read.
class EntryTable {
 public:
  /// `shared_grain`: 0 to fill in order here, else the chunks of the shared fill.
  explicit EntryTable(const std::vector<Entry>& entries, std::size_t shared_grain = 0) : mEntries(entries) {
    std::size_t capacity = 16;
    mShift = 60;
    while (capacity < 2 * entries.size()) {
      capacity *= 2;
      --mShift;
    }
    mMask = capacity - 1;
    mSlots.assign(capacity, kEmpty);
    if (shared_grain != 0) {
      parallel::parallel_for(0, entries.size(), shared_grain, [&](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i != hi; ++i) {
          for (std::size_t h = slot(entries[i].key);; h = (h + 1) & mMask) {
            std::uint32_t expected = kEmpty;
            if (std::atomic_ref<std::uint32_t>(mSlots[h]).compare_exchange_strong(expected, static_cast<std::uint32_t>(i),
                                                                                  std::memory_order_relaxed)) {
              break;
            }
          }
        }
      });
      return;
    }
    constexpr std::size_t kAhead = 16;  // the slot of the entry this many places on, prefetched
    for (std::size_t i = 0; i < entries.size(); ++i) {
      if (i + kAhead < entries.size()) __builtin_prefetch(&mSlots[slot(entries[i + kAhead].key)], 1);
      std::size_t h = slot(entries[i].key);
      while (mSlots[h] != kEmpty) h = (h + 1) & mMask;
      mSlots[h] = static_cast<std::uint32_t>(i);
    }
  }

  void prefetch(std::uint64_t key) const { __builtin_prefetch(&mSlots[slot(key)]); }

  /// The entry of `key`, or nullptr.
  [[nodiscard]] const Entry* find(std::uint64_t key) const {
    for (std::size_t h = slot(key);; h = (h + 1) & mMask) {
      const std::uint32_t i = mSlots[h];
      if (i == kEmpty) return nullptr;
      if (mEntries[i].key == key) return &mEntries[i];
    }
  }

 private:
  /// Entry positions; kEmpty marks a free slot (2^32 - 1 candidates of 64 bytes cannot be in memory).
  static constexpr std::uint32_t kEmpty = 0xffffffffu;
  /// Fibonacci hashing: the top log2(capacity) bits of the key times 2^64 / phi, which every bit
  /// of both ids moves (the low bits would not see A's id beyond its residue modulo the capacity).
  [[nodiscard]] std::size_t slot(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ull) >> mShift);
  }

  const std::vector<Entry>& mEntries;
  std::vector<std::uint32_t> mSlots;
  std::size_t mMask = 0;
  int mShift = 60;  ///< 64 - log2(capacity)
};

/// The candidates the list's look is given at a time (their columns, 48 bytes a candidate: 50 KB
/// kept by each thread that has made verdicts).
constexpr std::size_t kLookRun = 1024;

/// Above this many corners at a welded vertex (a hub: the centre of a fan, as load_mesh makes of a
/// large polygon, or the pole of a sphere of many segments; a triangle with two corners there
/// counts twice), a candidate's pairs through it are not looked up one by one: the closest
/// candidate of their group answers for them all (HubGroups), so that a fan of n triangles costs
/// the reduction n lookups, not n^2.
constexpr std::uint64_t kHubDegree = 32;

/// The triangles around welded vertex w of model m.
std::uint64_t degree(const ModelData& m, std::uint32_t w) { return m.vertex_offsets[w + 1] - m.vertex_offsets[w]; }

/// For each hub w of one side and triangle t of the other, the closest candidate (its entry's
/// index) of the group through them: those whose triangle on w's side has a corner at w and whose
/// other triangle is t. A candidate of the group is dominated through w (its neighbours there are
/// the group's other candidates) exactly where it is not the group's closest. Made on one thread
/// before the reduction's lookups (empty, nothing allocated, where no candidate meets a hub).
class HubGroups {
 public:
  /// Entry i is in the group of (w, t).
  void offer(std::uint32_t w, std::uint32_t t, std::uint32_t i, const std::vector<Entry>& entries) {
    const auto [at, fresh] = mClosest.try_emplace(key_of(w, t), i);
    if (!fresh && closer(entries[i], entries[at->second])) at->second = i;
  }
  /// The closest of the group of (w, t), which an entry offered.
  [[nodiscard]] std::uint32_t closest(std::uint32_t w, std::uint32_t t) const { return mClosest.at(key_of(w, t)); }

 private:
  std::unordered_map<std::uint64_t, std::uint32_t> mClosest;
};

/// The groups of both sides' hubs: (hub of A, triangle of B) and (hub of B, triangle of A).
struct Hubs {
  HubGroups of_a, of_b;

  Hubs(const ModelData& a, const ModelData& b, const std::vector<Entry>& entries) {
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const std::uint32_t ta = tri_a(entries[i].key), tb = tri_b(entries[i].key);
      const std::uint32_t* ca = a.welded_corners(ta);
      const std::uint32_t* cb = b.welded_corners(tb);
      for (int k = 0; k < 3; ++k) {
        if (degree(a, ca[k]) > kHubDegree) of_a.offer(ca[k], tb, static_cast<std::uint32_t>(i), entries);
        if (degree(b, cb[k]) > kHubDegree) of_b.offer(cb[k], ta, static_cast<std::uint32_t>(i), entries);
      }
    }
  }
};

/// The reduction's reading of a pair's candidates.
struct Reduction {
  const ModelData& a;
  const ModelData& b;
  const std::vector<Entry>& entries;
  const EntryTable& table;
  const Hubs* hubs;  ///< null where neither model has a hub

  /// Whether one of the pairs keys[0 .. count) is a candidate closer than c (their slots prefetched).
  [[nodiscard]] bool any_closer(const std::uint64_t* keys, int count, const Entry& c) const {
    return std::any_of(keys, keys + count, [&](std::uint64_t key) {
      const Entry* o = table.find(key);
      return o != nullptr && closer(*o, c);
    });
  }

  /// Whether a candidate dominates entry i: its pairs with a neighbour of either triangle looked
  /// up kLookups at a time, each batch's slots prefetched before the first lookup; the walk over
  /// the neighbours stops at the first batch that finds one. (What the list's look, done first,
  /// did not settle.)
  [[nodiscard]] bool dominated(std::size_t i) const {
    const Entry& c = entries[i];
    const std::uint32_t ta = tri_a(c.key), tb = tri_b(c.key);
    constexpr int kLookups = 4;
    std::uint64_t keys[kLookups];
    int count = 0;
    const auto add = [&](std::uint64_t key) {
      table.prefetch(key);
      keys[count++] = key;
      if (count < kLookups) return false;
      count = 0;
      return any_closer(keys, kLookups, c);
    };
    if (hubs == nullptr) {
      return a.any_neighbour(ta, [&](std::uint32_t u) { return add(key_of(u, tb)); }) ||
             b.any_neighbour(tb, [&](std::uint32_t u) { return add(key_of(ta, u)); }) || any_closer(keys, count, c);
    }
    // Corner by corner (ModelData::any_neighbour's walk), a hub answered by its group.
    const auto through = [&](const ModelData& m, std::uint32_t t, const HubGroups& groups, std::uint32_t other, auto&& key) {
      const std::uint32_t* corners = m.welded_corners(t);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t w = corners[k];
        if (degree(m, w) > kHubDegree) {
          if (groups.closest(w, other) != i) return true;
          continue;
        }
        for (std::uint64_t j = m.vertex_offsets[w]; j < m.vertex_offsets[w + 1]; ++j) {
          const std::uint32_t u = m.vertex_triangles[j];
          if (u != t && add(key(u))) return true;
        }
      }
      return false;
    };
    return through(a, ta, hubs->of_a, tb, [&](std::uint32_t u) { return key_of(u, tb); }) ||
           through(b, tb, hubs->of_b, ta, [&](std::uint32_t u) { return key_of(ta, u); }) || any_closer(keys, count, c);
  }
};

/// Reads candidate g of a list (reader(list)(g)): a vector's by index; the lists' by a
/// CandidateLists::Reader, one per run read in order (no search a candidate).
struct VectorReader {
  const Candidate* data;
  const Candidate& operator()(std::size_t g) const { return data[g]; }
};
VectorReader reader(const std::vector<Candidate>& list) { return VectorReader{list.data()}; }
CandidateLists::Reader reader(const CandidateLists& lists) { return CandidateLists::Reader(lists); }

/// The list's look at candidates [lo, hi): keep[i] = 1 where a neighbour in the list dominates
/// candidate i (null also before the library's constants are made: a query from another
/// constant's constructor). Its columns are made here, a run at a time, in the thread's own (made
/// once: no allocation a call), not for the whole list first.
template <class List>
void look_at(const PairContext& ctx, const List& candidates, std::size_t lo, std::size_t hi, char* keep) {
  const detail::NearbyLook look = kNearbyLook != nullptr ? kNearbyLook : detail::nearby_look_portable;
  thread_local detail::NearbyColumns columns(kLookRun);
  auto read = reader(candidates);
  const auto nearby = [&](std::size_t g) {
    const Candidate& c = read(g);
    return detail::NearbyCandidate{c.tri_a, c.tri_b, c.distance, ctx.a().welded_corners(c.tri_a),
                                   ctx.b().welded_corners(c.tri_b)};
  };
  for (std::size_t at = lo; at < hi; at += kLookRun) {
    const std::size_t count = std::min(hi - at, kLookRun);
    columns.load(at, count, candidates.size(), nearby);
    look(columns, 0, count, keep + at);
  }
}

/// local_minima on the candidates `candidates` (a vector or CandidateLists: size and reader).
/// The list's look needs no table: it runs while one thread fills the table and makes the hubs'
/// groups (where a model has a hub: none on most meshes, a few on a sphere's poles), but where
/// many threads share a large table's fill first (kSharedFillThreads); then the lookups of what
/// the look left.
template <class List>
std::vector<Candidate> reduce(const PairContext& ctx, const List& candidates, std::size_t grain) {
  const std::size_t n = candidates.size();
  const bool serial = grain >= n;  // then here, not through parallel_for's std::function
  std::vector<Entry> entries(n);
  const auto fill = [&](std::size_t lo, std::size_t hi) {
    auto read = reader(candidates);
    for (std::size_t i = lo; i != hi; ++i) {
      const Candidate& c = read(i);
      entries[i] = {key_of(c.tri_a, c.tri_b), c.distance};
    }
  };
  if (n < kParallelFill) {
    fill(0, n);
  } else {
    parallel::parallel_for(0, n, grain, fill);
  }
  // Many threads: the table filled by all of them first (kSharedFillThreads).
  const bool shared_fill = !serial && n >= kParallelFill && parallel::concurrency() >= kSharedFillThreads;
  std::optional<EntryTable> table;
  std::unique_ptr<const Hubs> hubs;
  const auto index = [&] {
    table.emplace(entries, shared_fill ? std::max<std::size_t>(grain, 1) : 0);
    if (ctx.a().largest_degree > kHubDegree || ctx.b().largest_degree > kHubDegree) {
      hubs = std::make_unique<const Hubs>(ctx.a(), ctx.b(), entries);
    }
  };
  std::vector<char> keep(n, 0);
  const auto look = [&](std::size_t lo, std::size_t hi) { look_at(ctx, candidates, lo, hi, keep.data()); };
  if (serial) {
    index();
    look(0, n);
  } else if (shared_fill) {
    index();
    parallel::parallel_for(0, n, grain, look);
  } else {
    parallel::JobGroup group;
    group.run(index);
    parallel::parallel_for(0, n, grain, look);
    group.wait();
  }
  const Reduction reduction{ctx.a(), ctx.b(), entries, *table, hubs.get()};
  const auto verdicts = [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i != hi; ++i) keep[i] = keep[i] == 0 && !reduction.dominated(i) ? 1 : 0;
  };
  if (serial) {
    verdicts(0, n);
  } else {
    parallel::parallel_for(0, n, grain, verdicts);
  }
  std::vector<Candidate> kept;
  auto read = reader(candidates);
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) kept.push_back(read(i));
  }
  return kept;
}

}  // namespace

std::vector<Candidate> local_minima(const PairContext& ctx, const std::vector<Candidate>& candidates, std::size_t grain) {
  return reduce(ctx, candidates, grain);
}

std::vector<Candidate> local_minima(const PairContext& ctx, const CandidateLists& lists, std::size_t grain) {
  return reduce(ctx, lists, grain);
}

}  // namespace caliber::narrow
