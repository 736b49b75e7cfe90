// The pieces of a split pair carrying their waiting leaf pairs and staying nodes from one to the
// next on a thread (narrow::PieceCarry): two pairs cut into pieces at the root's children, their
// pieces interleaved on one scratch with whole traversals of a third pair between two pieces of
// one pair, give each pair the candidates of its whole traversal, bit for bit, once the pieces
// are flushed.

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/model.h"
#include "caliber/procedural.h"
#include "narrow/traversal.h"

namespace caliber::narrow {
namespace {

bool by_ids(const Candidate& x, const Candidate& y) { return x.tri_a != y.tri_a ? x.tri_a < y.tri_a : x.tri_b < y.tri_b; }

/// The candidates sorted, as bytes: equal only where every field is.
std::vector<unsigned char> bytes_of(std::vector<Candidate> c) {
  std::sort(c.begin(), c.end(), by_ids);
  std::vector<unsigned char> out(c.size() * sizeof(Candidate));
  for (std::size_t i = 0; i < c.size(); ++i) {
    // Field by field (the struct's padding, if any, is not a value).
    unsigned char* at = out.data() + i * sizeof(Candidate);
    std::memcpy(at, &c[i].tri_a, 4);
    std::memcpy(at + 4, &c[i].tri_b, 4);
    std::memcpy(at + 8, &c[i].distance, 8);
    std::memcpy(at + 16, c[i].point_a.data(), 24);
    std::memcpy(at + 40, c[i].point_b.data(), 24);
  }
  return out;
}

std::vector<Candidate> whole(const PairContext& ctx) {
  TraversalScratch scratch;
  std::vector<Candidate> out;
  QueryStats stats;
  traverse(ctx, NodePair{0, 0}, scratch, out, stats);
  return out;
}

TEST(PieceCarry, InterleavedPiecesGiveEachPairItsWholeCandidates) {
  const auto torus = build_model(make_torus(1.0, 0.35, 40, 20));
  const auto sphere = build_model(make_sphere(0.6, 16, 24));
  const auto box = build_model(make_box(0.5, 0.4, 0.3, 8));
  for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity, QueryKind::contact}) {
    QueryRequest request;
    request.kind = kind;
    request.tolerance = kind == QueryKind::interference ? 0.0 : 0.08;
    request.angle_deg = 180.0;  // (contact: every pair's normals face)
    const PairContext p(*torus, Pose{}, *sphere, Pose::from_values(1.05, 0.1, 0.2, 1, 0.1, 0.05, 0.02), request);
    const PairContext q(*box, Pose{}, *torus, Pose::from_values(0.3, 0.9, 0.1, 1, -0.2, 0.1, 0.3), request);
    const PairContext r(*sphere, Pose{}, *box, Pose::from_values(0.5, 0.2, 0.0, 1, 0.3, 0.0, 0.1), request);
    const std::vector<Candidate> want_p = whole(p), want_q = whole(q), want_r = whole(r);
    ASSERT_GT(want_p.size(), 20u);
    ASSERT_GT(want_q.size(), 20u);
    ASSERT_GT(want_r.size(), 0u);
    // Each pair cut at its root's children (each a piece that tests its own root).
    NodePair kids_p[kMaxChildren], kids_q[kMaxChildren];
    const int np = cd_children(p, NodePair{0, 0}, kids_p), nq = cd_children(q, NodePair{0, 0}, kids_q);
    const detail::WideLanes lanes_p = wide_lanes(p), lanes_q = wide_lanes(q);
    TraversalScratch scratch;
    std::vector<Candidate> got_p, got_q, got_r;
    QueryStats stats;
    const auto whole_r = [&] {
      got_r.clear();
      traverse(r, NodePair{0, 0}, scratch, got_r, stats);
      EXPECT_EQ(bytes_of(got_r), bytes_of(want_r)) << "a whole traversal between pieces";
    };
    for (int k = 0; 2 * k < np || k < nq; ++k) {
      // A piece of p, the third pair whole, p's next piece, then one of q.
      if (2 * k < np) traverse(p, kids_p[2 * k], scratch, got_p, stats, RootTest::as_root, {}, nullptr, &lanes_p);
      whole_r();
      if (2 * k + 1 < np) traverse(p, kids_p[2 * k + 1], scratch, got_p, stats, RootTest::as_root, {}, nullptr, &lanes_p);
      if (k < nq) traverse(q, kids_q[k], scratch, got_q, stats, RootTest::as_root, {}, nullptr, &lanes_q);
    }
    scratch.flush_pieces();
    const std::string what = "kind " + std::to_string(static_cast<int>(kind));
    EXPECT_EQ(bytes_of(got_p), bytes_of(want_p)) << what;
    EXPECT_EQ(bytes_of(got_q), bytes_of(want_q)) << what;
    EXPECT_EQ(scratch.carry.ctx, nullptr) << "nothing carried after the flush";
  }
}

}  // namespace
}  // namespace caliber::narrow
