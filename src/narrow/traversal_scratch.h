#pragma once
/// \file
/// What a thread's traversals keep from one call to the next (narrow/traversal.h): their stacks
/// and stores, and what the pieces of a split pair carry from one piece to the next.

#include <cstddef>
#include <memory>
#include <vector>

#include "narrow/candidate.h"
#include "narrow/leaf_buffer.h"
#include "narrow/pair_context.h"
#include "narrow/prepared.h"
#include "narrow/wide_test.h"
#include "util/gap_buckets.h"

namespace caliber::narrow {

/// What the depth-first pieces of one split pair (a schedule's cut: each piece a traversal from
/// one of its CD-tree nodes, given the pair's lanes) leave on a thread for its next piece of the
/// same pair: the leaf pairs still waiting for the batch kernels, which go to one pair context's
/// candidate list, and the lanes whose moves the staying cache holds. So that a pair cut in many
/// pieces runs its batch kernels on full batches and finds its staying nodes moved, as one
/// traversal would: the same candidates, appended later.
struct PieceCarry {
  LeafBuffer leaves;
  const PairContext* ctx = nullptr;          ///< the pair the waiting leaf pairs are of, or null
  std::vector<Candidate>* out = nullptr;     ///< the list their candidates go to
  const detail::WideLanes* lanes = nullptr;  ///< the lanes of the staying cache's moves, or null
};

/// Per-thread scratch for traversals, reused across calls to avoid allocation.
struct TraversalScratch {
  std::vector<NodePair> stack;  ///< explicit depth-first stack
  using NearA = PreparedTree<PairContext::NearA>::Node;
  using NearB = PreparedTree<PairContext::NearB>::Node;
  /// A CD-tree node waiting in the distance traversal: its prepared nodes of A and of B.
  struct Reached {
    NearA* a;
    NearB* b;
  };
  util::GapBuckets<Reached> waiting;        ///< distance traversal: the nodes waiting, by gap
  PreparedTree<PairContext::NearA> near_a;  ///< distance traversal: A's nodes prepared so far
  PreparedTree<PairContext::NearB> near_b;  ///< distance traversal: B's nodes prepared so far
  /// Wide traversals: the staying nodes moved, renewed by each but a piece that follows a piece of
  /// its pair (made by the first; 10.5 KB, kept off the thread's own storage).
  std::unique_ptr<detail::StayingCache> staying;
  /// Distance traversal of a pair with few triangle pairs: the pairs within the tolerance; of
  /// others, what a batch of leaf pairs kept.
  std::vector<Candidate> within;
  /// Distance traversal: the leaf pairs waiting for the batch kernels.
  LeafBuffer leaves;
  /// What the last pieces of a split pair left (PieceCarry).
  PieceCarry carry;

  /// Bytes held that grow with the largest traversal so far (not the buckets' fixed tables).
  [[nodiscard]] std::size_t footprint() const {
    return stack.capacity() * sizeof(NodePair) + waiting.footprint() + near_a.footprint() + near_b.footprint() +
           within.capacity() * sizeof(Candidate);
  }

  /// The staying cache, renewed unless it holds the moves of `lanes` (null: always renewed, and
  /// no piece finds it as its own).
  detail::StayingCache& staying_for(const detail::WideLanes* lanes) {
    if (staying == nullptr) staying = std::make_unique<detail::StayingCache>();
    if (lanes == nullptr || carry.lanes != lanes) staying->renew();
    carry.lanes = lanes;
    return *staying;
  }
  /// A piece of ctx's pair starts, its candidates going to `out`: the leaf pairs of another pair's
  /// pieces are finished first (flush_pieces); its own are kept waiting.
  LeafBuffer& piece_leaves(const PairContext& ctx, std::vector<Candidate>& out) {
    if (carry.ctx != &ctx || carry.out != &out) {
      flush_pieces();
      carry.ctx = &ctx;
      carry.out = &out;
    }
    return carry.leaves;
  }
  /// Finishes the leaf pairs the pieces left waiting (their candidates appended to their list):
  /// what a schedule calls once every piece of its pairs is done, before reading their candidates.
  /// Nothing is carried after it.
  void flush_pieces() {
    if (carry.ctx != nullptr) carry.ctx->flush_leaves(carry.leaves, *carry.out);
    drop_pieces();
  }
  /// Forgets what was carried, unfinished (a new run: the pair contexts it named may be gone, so
  /// that a scratch left by a run that stopped is never flushed). A traversal given `piece`
  /// appends its last leaf pairs' candidates only once flushed: every caller that gives pieces
  /// flushes them before it reads their candidates.
  void drop_pieces() {
    carry.leaves.refusal.batch.size = carry.leaves.closest.batch.size = 0;
    carry.ctx = nullptr;
    carry.out = nullptr;
    carry.lanes = nullptr;
  }
};

}  // namespace caliber::narrow
