// The contact reduction's look at each candidate's neighbours in the list (narrow/nearby_look.h):
// every vector form against the portable one on random lists whose ids and distances repeat (ties,
// shared triangles, shared corners, both at once), and the whole reduction against an independent
// one on meshes without hubs.

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/local_minima.h"
#include "narrow/nearby_look.h"
#include "narrow/traversal.h"
#include "parallel/executor.h"
#include "support/local_minima_oracle.h"
#include "support/pool_host.h"
#include "support/random_poses.h"

namespace caliber::narrow {
namespace {

/// Random candidates: triangles from `tris` ids, each triangle's welded corners from `corners` ids
/// (fixed per triangle, as a mesh's are), distances from a few values (ties).
struct RandomList {
  std::vector<std::uint32_t> welded_a, welded_b;
  std::vector<detail::NearbyCandidate> list;

  RandomList(std::mt19937_64& rng, std::size_t n, std::uint32_t tris, std::uint32_t corners)
      : welded_a(3 * tris), welded_b(3 * tris) {
    std::uniform_int_distribution<std::uint32_t> tri(0, tris - 1), corner(0, corners - 1);
    for (auto* w : {&welded_a, &welded_b}) {
      for (std::uint32_t& v : *w) v = corner(rng);
    }
    const double distances[] = {0.0, 0.25, 0.25, 0.5, 1.0, 1e-300};
    std::uniform_int_distribution<int> pick(0, 5);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t ta = tri(rng), tb = tri(rng);
      list.push_back({ta, tb, distances[pick(rng)], &welded_a[3 * ta], &welded_b[3 * tb]});
    }
  }
  /// The whole list as one run.
  [[nodiscard]] detail::NearbyColumns columns() const {
    detail::NearbyColumns c(list.size());
    for (std::size_t i = 0; i < list.size(); ++i) c.set(static_cast<std::ptrdiff_t>(i), list[i]);
    return c;
  }
};

TEST(NearbyLook, EveryFormGivesThePortableVerdicts) {
  std::mt19937_64 rng(20261207);
  int forms = 0, settled = 0;
  for (const int lanes : {8, 16}) {
    const detail::NearbyLook form = detail::nearby_look_form(lanes);
    if (form == nullptr) continue;
    ++forms;
    for (const std::size_t n : {0, 1, 2, 9, 17, 400}) {
      for (const std::uint32_t tris : {2u, 5u, 40u}) {
        const RandomList r(rng, n, tris, tris + 3);
        const detail::NearbyColumns c = r.columns();
        std::vector<char> want(n + 1, 7), got(n + 1, 7);
        detail::nearby_look_portable(c, 0, n, want.data());
        // In two calls, as chunks: each place written once, nothing past hi.
        form(c, 0, n / 2, got.data());
        form(c, n / 2, n, got.data());
        EXPECT_EQ(got, want) << lanes << " lanes, " << n << " candidates of " << tris << " triangles";
        settled += static_cast<int>(std::count(want.begin(), want.end() - 1, 1));
      }
    }
  }
  EXPECT_GT(settled, 100) << "the lists have candidates the look settles";
  if (forms == 0) GTEST_SKIP() << "this CPU has no vector form of the look";
}

TEST(NearbyLook, RunsOfAListGiveTheWholeListsVerdicts) {
  // A run loaded from a longer list reads the list's candidates around it, pads past its ends.
  std::mt19937_64 rng(7);
  const RandomList r(rng, 300, 6, 9);
  const detail::NearbyColumns whole = r.columns();
  std::vector<char> want(300);
  detail::nearby_look_portable(whole, 0, 300, want.data());
  EXPECT_GT(std::count(want.begin(), want.end(), 1), 30);
  for (const std::size_t run : {1, 7, 64, 300}) {
    for (const detail::NearbyLook form :
         {detail::nearby_look_portable, detail::nearby_look_form(8), detail::nearby_look_form(16)}) {
      if (form == nullptr) continue;
      detail::NearbyColumns c(run);
      std::vector<char> got(300, 7);
      for (std::size_t at = 0; at < 300; at += run) {
        const std::size_t count = std::min<std::size_t>(run, 300 - at);
        c.load(at, count, 300, [&](std::size_t g) { return r.list[g]; });
        form(c, 0, count, got.data() + at);
      }
      EXPECT_EQ(got, want) << "runs of " << run;
    }
  }
}

TEST(NearbyLook, PortableVerdictsFollowTheirDefinition) {
  // Candidate 1 dominates 0 (the same B triangle, A's triangles share corner 7, closer); 2 shares
  // no corner with 0; 3 shares A's triangle with 0 but its B triangle shares no corner.
  detail::NearbyColumns c(4);  // (its candidates set below)
  const std::uint32_t a0[] = {1, 2, 7}, a1[] = {7, 8, 9}, a2[] = {3, 4, 5}, b0[] = {1, 2, 3}, b3[] = {4, 5, 6};
  c.set(0, {10, 20, 0.5, a0, b0});
  c.set(1, {11, 20, 0.25, a1, b0});
  c.set(2, {12, 20, 0.0, a2, b0});
  c.set(3, {10, 21, 0.0, a0, b3});
  char got[4];
  detail::nearby_look_portable(c, 0, 4, got);
  EXPECT_EQ(got[0], 1);
  EXPECT_EQ(got[1], 0);  // 0 is farther; 2 shares nothing with 1
  EXPECT_EQ(got[2], 0);
  EXPECT_EQ(got[3], 0);
  // A tie is settled by the ids: at equal distances the lower key dominates.
  detail::NearbyColumns tie(2);
  tie.set(0, {11, 20, 0.5, a1, b0});
  tie.set(1, {10, 20, 0.5, a0, b0});
  detail::nearby_look_portable(tie, 0, 2, got);
  EXPECT_EQ(got[0], 1);
  EXPECT_EQ(got[1], 0);
}

/// The contact query's local minima on meshes without hubs (every vertex with a few triangles)
/// equal an independent reduction of every pair within the tolerance: kept unless a closer pair
/// (ties: lower ids) shares one of its triangles and has the other sharing a vertex with its own.
TEST(NearbyLook, ContactsAreTheLocalMinimaOfTheProximityPairs) {
  const Mesh ma = make_torus(1.0, 0.35, 48, 24), mb = make_sphere(0.6, 16, 24);
  const auto a = build_model(ma);
  const auto b = build_model(mb);
  const Pose pa, pb = Pose::from_values(1.05, 0.1, 0.2, 1, 0.1, 0.05, 0.02);
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = 0.15;
  const QueryResult within = query(*a, pa, *b, pb, request);
  ASSERT_GT(within.contacts.size(), 500u);
  const auto want = test::local_minima_oracle(within.contacts, ma, mb);
  request.kind = QueryKind::contact;
  request.angle_deg = 180.0;
  const QueryResult got = query(*a, pa, *b, pb, request);
  EXPECT_EQ(test::pair_ids(got.contacts), want);
  EXPECT_GE(want.size(), 2u);
  EXPECT_LT(want.size(), within.contacts.size() / 10) << "the reduction dropped most pairs";
  test::expect_identical(got, query_brute_force(*a, pa, *b, pb, request), "torus and sphere");
}

/// A contact query's candidates between a torus and a sphere (their segments given), as a
/// traversal of the pair from its root gathers them.
struct TorusAndSphere {
  TorusAndSphere(int torus_u, int torus_v, int sphere_u, int sphere_v)
      : a(build_model(make_torus(1.0, 0.35, torus_u, torus_v))),
        b(build_model(make_sphere(0.6, sphere_u, sphere_v))),
        pb(Pose::from_values(1.05, 0.1, 0.2, 1, 0.1, 0.05, 0.02)),
        request(contact_request()),
        ctx(*a, pa, *b, pb, request) {
    TraversalScratch scratch;
    QueryStats stats;
    traverse(ctx, NodePair{0, 0}, scratch, all, stats);
  }
  static QueryRequest contact_request() {
    QueryRequest r;
    r.kind = QueryKind::contact;
    r.tolerance = 0.15;
    r.angle_deg = 180.0;
    return r;
  }

  decltype(build_model(Mesh{})) a, b;
  Pose pa, pb;
  QueryRequest request;
  PairContext ctx;
  std::vector<Candidate> all;
};

/// The triangle pairs of `c`, in order.
std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_of(const std::vector<Candidate>& c) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  for (const Candidate& x : c) out.emplace_back(x.tri_a, x.tri_b);
  return out;
}

/// The reduction of a pair's candidates read where they are, in lists (CandidateLists: the
/// workers' of a cut pair), keeps what it keeps of them gathered into one list, in that order.
TEST(NearbyLook, ListsKeepWhatTheirConcatenationKeeps) {
  const TorusAndSphere pair(48, 24, 16, 24);
  const PairContext& ctx = pair.ctx;
  const std::vector<Candidate>& all = pair.all;
  ASSERT_GT(all.size(), 2000u) << "runs of the look across lists and chunks";
  const std::vector<Candidate> want = local_minima(ctx, all, 128);
  ASSERT_GT(want.size(), 2u);
  const auto ids = pairs_of;
  std::mt19937_64 rng(11);
  for (int split = 0; split < 6; ++split) {
    // Up to seven lists cut at random places (empty ones where two cuts meet), and an empty last one.
    std::vector<std::size_t> cuts = {0, all.size()};
    std::uniform_int_distribution<std::size_t> at(0, all.size());
    for (int k = 0; k < split; ++k) cuts.push_back(at(rng));
    cuts.push_back(cuts[1]);  // an empty list
    std::sort(cuts.begin(), cuts.end());
    std::vector<std::vector<Candidate>> parts;
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) parts.emplace_back(all.begin() + cuts[k], all.begin() + cuts[k + 1]);
    CandidateLists lists;
    for (const std::vector<Candidate>& p : parts) lists.add(p);
    ASSERT_EQ(lists.size(), all.size());
    for (const std::size_t grain : {std::size_t{128}, all.size()}) {
      EXPECT_EQ(ids(local_minima(ctx, lists, grain)), ids(want)) << split << " cuts, grain " << grain;
    }
    // On threads: the table filled by one job while the look's chunks run.
    parallel::Executor executor(2);
    executor.execute([&] {
      for (const std::size_t grain : {std::size_t{16}, std::size_t{128}}) {
        EXPECT_EQ(ids(local_minima(ctx, lists, grain)), ids(want)) << split << " cuts, grain " << grain << ", 2 threads";
      }
    });
  }
}

/// A list of more than 32,768 candidates reduced on eight threads, where they fill the table
/// together before the look (compare-and-swap), keeps what the serial reduction keeps.
TEST(NearbyLook, ALargeListOnEightThreadsKeepsWhatOneKeeps) {
  const TorusAndSphere pair(192, 96, 64, 96);
  ASSERT_GE(pair.all.size(), std::size_t{1} << 15);
  const auto want = pairs_of(local_minima(pair.ctx, pair.all, pair.all.size()));
  ASSERT_GT(want.size(), 2u);
  test::PoolHost host(8);  // (eight whatever the cores: the engine's own pool has at most one a core)
  parallel::Executor eight(8, &host);
  eight.execute([&] {
    ASSERT_EQ(parallel::concurrency(), 8);
    EXPECT_EQ(pairs_of(local_minima(pair.ctx, pair.all, 128)), want);
  });
}

/// A reader of the lists gives the candidate operator[] gives, wherever it is sent next: on to the
/// next place, across a list's end, back, far ahead (lists added empty are not among them).
TEST(NearbyLook, ListReaderFindsEachCandidate) {
  std::vector<std::vector<Candidate>> parts(6);
  const std::size_t sizes[] = {3, 0, 1, 0, 5, 2};
  std::uint32_t id = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    for (std::size_t j = 0; j < sizes[k]; ++j) {
      Candidate c;
      c.tri_a = id++;
      parts[k].push_back(c);
    }
  }
  CandidateLists lists;
  for (const std::vector<Candidate>& p : parts) lists.add(p);
  ASSERT_EQ(lists.size(), 11u);
  CandidateLists::Reader read(lists);
  std::vector<std::size_t> order;
  for (std::size_t g = 0; g < lists.size(); ++g) order.push_back(g);  // in order
  for (std::size_t g = lists.size(); g-- > 0;) order.push_back(g);    // backwards
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::size_t> any(0, lists.size() - 1);
  for (int k = 0; k < 200; ++k) order.push_back(any(rng));
  for (const std::size_t g : order) {
    EXPECT_EQ(&read(g), &lists[g]) << g;
    EXPECT_EQ(read(g).tri_a, g);
  }
}

}  // namespace
}  // namespace caliber::narrow
