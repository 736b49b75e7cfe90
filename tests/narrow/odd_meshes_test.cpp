// Meshes that are legal but unusual, from the bad-input catalog (docs/bad_input.md): duplicate
// vertices, non-manifold edges, only degenerate triangles. Documented behaviour: all are accepted,
// and queries on them are exact (identical to the brute-force oracle).

#include <algorithm>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "narrow/local_minima.h"
#include "narrow/traversal.h"
#include "parallel/executor.h"
#include "support/local_minima_oracle.h"
#include "support/pool_host.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

/// Every triangle with its own three vertices (as STL stores meshes): same triangles, same ids.
Mesh as_soup(const Mesh& mesh) {
  Mesh soup;
  soup.source = mesh.source + " (soup)";
  for (const auto& t : mesh.triangles) {
    const auto base = static_cast<std::uint32_t>(soup.vertices.size());
    for (const std::uint32_t v : t) soup.vertices.push_back(mesh.vertices[v]);
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  return soup;
}

/// `pages` triangles sharing one edge (the z axis from 0 to 1): a non-manifold edge.
Mesh book(int pages) {
  Mesh m;
  m.source = "book";
  m.vertices = {{0, 0, 0}, {0, 0, 1}};
  for (int p = 0; p < pages; ++p) {
    const double a = 2.0 * std::numbers::pi * p / pages;
    m.vertices.emplace_back(0.8 * std::cos(a), 0.8 * std::sin(a), 0.5);
    m.triangles.push_back({0, 1, static_cast<std::uint32_t>(m.vertices.size() - 1)});
  }
  return m;
}

int compare_with_oracle(const Model& a, const Model& b, int poses, double spread, std::uint64_t seed, const std::string& name) {
  std::mt19937_64 rng(seed);
  int non_empty = 0;
  for (int i = 0; i < poses; ++i) {
    QueryRequest request;
    request.kind = static_cast<QueryKind>(i % 3);
    request.tolerance = 0.05;
    request.angle_deg = 40.0;
    const Pose pa = test::random_pose(rng, spread), pb = test::random_pose(rng, spread);
    const QueryResult fast = query(a, pa, b, pb, request);
    test::expect_identical(fast, query_brute_force(a, pa, b, pb, request), name + " pose " + std::to_string(i));
    if (::testing::Test::HasFatalFailure()) return non_empty;
    non_empty += fast.contacts.empty() ? 0 : 1;
  }
  return non_empty;
}

TEST(OddMeshes, DuplicateVerticesGiveTheSameAnswerAsSharedOnes) {
  const Mesh torus = make_torus(0.8, 0.3, 14, 9);
  const auto indexed = build_model(torus);
  const auto soup = build_model(as_soup(torus));
  const auto sphere = build_model(make_sphere(0.5, 8, 10));
  std::mt19937_64 rng(7);
  int non_empty = 0;
  for (int i = 0; i < 150; ++i) {
    QueryRequest request;
    request.kind = static_cast<QueryKind>(i % 3);
    request.tolerance = 0.05;
    const Pose p = test::random_pose(rng, 0.7);
    const QueryResult want = query(*indexed, Pose{}, *sphere, p, request);
    // Vertices are welded by exact position for adjacency, so even the contact reduction agrees.
    test::expect_identical(query(*soup, Pose{}, *sphere, p, request), want, "soup pose " + std::to_string(i));
    if (HasFatalFailure()) return;
    non_empty += want.contacts.empty() ? 0 : 1;
  }
  EXPECT_GT(non_empty, 30);
  EXPECT_GT(compare_with_oracle(*soup, *sphere, 60, 0.7, 8, "soup-sphere"), 10);
}

TEST(OddMeshes, NonManifoldEdgesAreExact) {
  const auto pages = build_model(book(9));
  const auto sphere = build_model(make_sphere(0.4, 8, 10));
  EXPECT_GT(compare_with_oracle(*pages, *sphere, 150, 0.5, 9, "book-sphere"), 30);
  EXPECT_GT(compare_with_oracle(*pages, *pages, 150, 0.3, 10, "book-book"), 30);
}

TEST(OddMeshes, OnlyDegenerateTrianglesAreExact) {
  Mesh m = load_mesh(std::filesystem::path(CALIBER_TEST_DATA) / "degenerate_only.off");
  const auto degenerate = build_model(m);
  const auto box = build_model(make_box(0.4, 0.4, 0.4, 2));
  EXPECT_GT(compare_with_oracle(*degenerate, *box, 300, 0.4, 11, "degenerate-box"), 0);
}

/// A degenerate triangle has no normal, so a contact query never reports it, whatever its angle
/// (up to 90 degrees the normal test refuses it through the dot product alone, above by a test of
/// its own). A box with a degenerate triangle of its own vertices on its top face, against a box
/// just above, as A and as B: the proximity query reports the degenerate triangle; the contact
/// query at every angle, and its brute force, do not, still report the faces, and agree.
TEST(OddMeshes, DegenerateTrianglesMakeNoContactAtAnyAngle) {
  Mesh top = make_box(0.5, 0.5, 0.5, 2);
  const auto first = static_cast<std::uint32_t>(top.vertices.size());
  top.vertices.emplace_back(-0.2, 0.1, 0.5);
  top.vertices.emplace_back(0.0, 0.1, 0.5);
  top.vertices.emplace_back(0.2, 0.1, 0.5);
  top.triangles.push_back({first, first + 1, first + 2});
  const auto degenerate = static_cast<std::uint32_t>(top.triangles.size() - 1);
  const auto a = build_model(top);
  const auto b = build_model(make_box(0.5, 0.5, 0.5, 2));
  const Pose low, high = Pose::from_values(0.05, 0.02, 1.01, 1, 0, 0, 0);
  for (const bool degenerate_is_a : {true, false}) {
    const Model& first_model = degenerate_is_a ? *a : *b;
    const Model& second_model = degenerate_is_a ? *b : *a;
    const Pose& first_pose = degenerate_is_a ? low : high;
    const Pose& second_pose = degenerate_is_a ? high : low;
    const auto has_degenerate = [&](const QueryResult& r) {
      return std::any_of(r.contacts.begin(), r.contacts.end(),
                         [&](const Contact& c) { return (degenerate_is_a ? c.tri_a : c.tri_b) == degenerate; });
    };
    QueryRequest request;
    request.tolerance = 0.02;
    request.kind = QueryKind::proximity;
    ASSERT_TRUE(has_degenerate(query(first_model, first_pose, second_model, second_pose, request)));
    request.kind = QueryKind::contact;
    for (const double angle : {0.0, 30.0, 89.0, 90.0, 91.0, 120.0, 180.0}) {
      request.angle_deg = angle;
      const std::string name = std::string(degenerate_is_a ? "A" : "B") + " degenerate, " + std::to_string(angle) + " degrees";
      const QueryResult r = query(first_model, first_pose, second_model, second_pose, request);
      const QueryResult brute = query_brute_force(first_model, first_pose, second_model, second_pose, request);
      EXPECT_FALSE(has_degenerate(r)) << name;
      EXPECT_FALSE(has_degenerate(brute)) << name;
      EXPECT_FALSE(r.contacts.empty()) << name;
      test::expect_identical(r, brute, name);
    }
  }
}

/// A flat fan of n triangles around one centre vertex (a hub of degree n), its rim a circle of radius
/// 1, bent down by `sag` at the rim: the triangles around the centre are the closest to a plane below.
Mesh fan(int n, double sag) {
  Mesh m;
  m.source = "fan";
  m.vertices.emplace_back(0, 0, 0);
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * std::numbers::pi * k / n;
    m.vertices.emplace_back(std::cos(a), std::sin(a), -sag * (1.0 + 0.5 * std::sin(3.0 * a)));
  }
  for (int k = 0; k < n; ++k) {
    m.triangles.push_back({0, static_cast<std::uint32_t>(1 + k), static_cast<std::uint32_t>(1 + (k + 1) % n)});
  }
  return m;
}

/// A contact query's local minima where a vertex is shared by hundreds of triangles (the fans'
/// centres, above the reduction's lookups one by one) equal an independent reduction: every pair
/// within the tolerance (the proximity query; at 180 degrees the contact query's normal test passes
/// every pair of these non-degenerate triangles) kept unless a closer pair (ties: lower ids) shares
/// one of its triangles and has the other sharing a vertex with its own.
TEST(OddMeshes, ContactsAroundAHubAreTheLocalMinima) {
  const auto a = build_model(fan(300, 0.02));
  const auto b = build_model(fan(200, -0.03));
  const Pose pa, pb = Pose::from_values(0.05, -0.03, -0.12, 1, 0.02, 0.01, 0);
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = 0.3;
  const QueryResult within = query(*a, pa, *b, pb, request);
  ASSERT_GT(within.contacts.size(), 1000u);
  const auto want = test::local_minima_oracle(within.contacts, a->mesh(), b->mesh());
  request.kind = QueryKind::contact;
  request.angle_deg = 180.0;
  const QueryResult got = query(*a, pa, *b, pb, request);
  EXPECT_EQ(test::pair_ids(got.contacts), want);
  EXPECT_GE(want.size(), 1u);
  test::expect_identical(got, query_brute_force(*a, pa, *b, pb, request), "fans");
  // On two threads, the hubs' groups made by the job that fills the table, the look's chunks beside
  // it; on eight, the table filled by all of them first.
  const narrow::PairContext ctx(*a, pa, *b, pb, request);
  narrow::TraversalScratch scratch;
  std::vector<narrow::Candidate> all;
  QueryStats stats;
  narrow::traverse(ctx, narrow::NodePair{0, 0}, scratch, all, stats);
  const auto ids = [](const std::vector<narrow::Candidate>& c) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    for (const narrow::Candidate& x : c) out.emplace_back(x.tri_a, x.tri_b);
    return out;
  };
  const auto serial = ids(narrow::local_minima(ctx, all, all.size()));
  ASSERT_EQ(serial.size(), want.size());
  ASSERT_GE(all.size(), std::size_t{1} << 15) << "a table that eight threads fill together";
  parallel::Executor two(2);
  two.execute([&] { EXPECT_EQ(ids(narrow::local_minima(ctx, all, 16)), serial) << "2 threads"; });
  test::PoolHost host(8);  // (eight whatever the cores: the engine's own pool has at most one a core)
  parallel::Executor eight(8, &host);
  eight.execute([&] {
    ASSERT_EQ(parallel::concurrency(), 8);
    EXPECT_EQ(ids(narrow::local_minima(ctx, all, 16)), serial) << "8 threads";
  });
}

}  // namespace
}  // namespace caliber
