#pragma once
/// \file
/// The order in which a traversal that stops early takes a visit's children, so that it meets a
/// touching pair after fewer tests: the depth-first traversal with a limit
/// (QueryRequest::max_pairs) enters first the child pairs whose boxes' centers lie nearest
/// relative to their sizes (detail::SlotOrderKeys), the distance traversal at contact those whose
/// spheres overlap the most relative to their size (PairContext::sphere_apart). Which pair they
/// meet first is theirs to choose (documented so); a traversal that visits every node keeps
/// cd_children order.

#include <bit>
#include <cstdint>

#include "narrow/cd_tree.h"
#include "narrow/pair_context.h"
#include "util/assert.h"

namespace caliber::narrow {

/// Pushes the `count` children of a visit (passed, 0..8 of them, in cd_children order) onto a
/// depth-first stack at `top` so that the one whose box is nearest the staying node's box relative
/// to their sizes (their order keys, `keys`, as the visit wrote them: VisitLanes::order,
/// detail::SlotOrderKeys) is popped first, ties in cd_children order; returns the new top. The order
/// of a traversal that stops at a limit: it meets a touching pair after fewer tests (the first hit
/// on bench_batch's colliding poses: bench/results/amd-epyc-2c/batch/README.md), which pair it
/// meets first being the traversal's choice (QueryRequest::max_pairs). A traversal that visits
/// every node keeps cd_children order.
inline NodePair* push_nearest_first(const NodePair passed[], const float keys[], int count, NodePair* top) {
  if (count < 2) {  // nothing to order
    if (count == 1) *top++ = passed[0];
    return top;
  }
  // Each child's key (finite and at least 0 for validated input: its bits order as it does) above
  // its place, so that one integer orders both. `passed` in cd_children order: equals keep it.
  std::uint64_t order[kMaxChildren];
  for (int k = 0; k < count; ++k)
    order[k] = std::uint64_t{std::bit_cast<std::uint32_t>(keys[k])} << 32 | static_cast<std::uint32_t>(k);
  // Farthest first on the stack, equals in reverse cd_children order (popped in that order): an
  // insertion sort of at most eight, descending.
  for (int i = 1; i < count; ++i) {
    const std::uint64_t x = order[i];
    int j = i;
    for (; j > 0 && order[j - 1] < x; --j) order[j] = order[j - 1];
    order[j] = x;
  }
  for (int k = 0; k < count; ++k) *top++ = passed[order[k] & 0xFu];
  return top;
}

/// The order in which the distance traversal takes a visit's `count` children (kids) when several
/// are at gap 0 and it stops at contact: `nearest` becomes the one at gap 0 whose spheres overlap
/// the most relative to their size (PairContext::sphere_apart; ties to the first in cd_children
/// order), and `order` lists the children to push: those at a positive gap in cd_children order,
/// then those at gap 0 from the least overlapping to the most (popped in reverse).
template <class Waiting>
void touching_first(const PairContext& ctx, const Waiting kids[4], int count, int order[4], int& nearest) {
  double apart[4];
  int n = 0;
  for (int k = 0; k < count; ++k) {
    if (kids[k].key != 0.0) order[n++] = k;
  }
  const int first_touching = n;
  for (int k = 0; k < count; ++k) {
    if (kids[k].key != 0.0) continue;
    apart[k] = ctx.sphere_apart(kids[k].value.a->index, kids[k].value.b->index);
    // Insertion from the back: the most overlapping last, equals in reverse cd_children order.
    int j = n++;
    for (; j > first_touching && apart[order[j - 1]] <= apart[k]; --j) order[j] = order[j - 1];
    order[j] = k;
  }
  nearest = order[count - 1];
}

}  // namespace caliber::narrow
