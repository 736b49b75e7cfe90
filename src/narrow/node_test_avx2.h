#pragma once
/// \file
/// The geometric part of the node test on four node pairs at once, in AVX2: of a visit where both
/// sides descend (PairContext::node_within's spheres, boxes and slabs, and disks_beyond_slabs), or
/// without the disks on the two pairs of one where one side descends (its two children against the
/// other node, that node given twice). The same decisions as the scalar test, bit for bit (each lane does the
/// scalar test's operations in its order).

#include <cstdint>

#include "bvh/model_data.h"

namespace caliber::narrow::detail {

/// What the test reads of a pair context: the two models' nodes, B's pose in A's frame (as
/// PairContext keeps it: rot[i][j] is mRot(i, j)) and the reaches.
struct NodeTestFrame {
  const BvhNode* nodes_a;
  const BvhNodeFilter* filters_a;
  const BvhNode* nodes_b;
  const BvhNodeFilter* filters_b;
  double rot[3][3], abs_rot[3][3], trans[3];
  double hair, reach, slab_reach;
};

/// B's pose for four lanes that hold nodes a0, a1 of A and b0, b1 of B, in that order, so that one
/// product moves A's nodes into B's frame and B's into A's: rot[k][j] is the frame's rot[j][k] in
/// A's lanes and rot[k][j] in B's (abs_rot likewise); a point x goes to rot (x - pre) + post, pre
/// being the frame's trans in A's lanes and 0 in B's, post 0 in A's and trans in B's (each lane
/// the scalar test's operations: x - 0 and y + 0 are x and y). Made by make_lanes, once per
/// traversal (768 bytes: not kept in the pair context, which the engine holds for every pair).
struct NodeLanes {
  double rot[3][3][4], abs_rot[3][3][4], pre[3][4], post[3][4];
};

/// The lanes of frame f's pose.
inline NodeLanes make_lanes(const NodeTestFrame& f) {
  NodeLanes l;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 4; ++i) {
        l.rot[k][j][i] = i < 2 ? f.rot[j][k] : f.rot[k][j];
        l.abs_rot[k][j][i] = i < 2 ? f.abs_rot[j][k] : f.abs_rot[k][j];
      }
    }
    for (int i = 0; i < 4; ++i) {
      l.pre[k][i] = i < 2 ? f.trans[k] : 0.0;
      l.post[k][i] = i < 2 ? 0.0 : f.trans[k];
    }
  }
  return l;
}

/// Bit 2i + j set where node ai of A and node bj of B pass spheres, boxes, slabs and (in the forms
/// with them) disks: PairContext::node_within's geometry (not its groups) and !disks_beyond_slabs
/// on prepare_a(ai) and prepare_b(bj) with their disks.
using NodeWithin2x2 = int (*)(const NodeTestFrame& frame, const NodeLanes& lanes, std::uint32_t a0, std::uint32_t a1,
                              std::uint32_t b0, std::uint32_t b1);

/// The four-lane form compiled for AVX2 (`wide_registers` false) or for AVX-512VL (true: the same
/// code and operations with 32 vector registers, so fewer spills), or nullptr where this build or
/// this CPU has none. With `disks` false, the test of a visit where one side descends (a0 = a1 or
/// b0 = b1), without the disks: bits 0 (a0 with b0) and 3 (a1 with b1) alone.
NodeWithin2x2 node_within_2x2_form(bool wide_registers, bool disks = true);

/// The form the node test runs: the AVX-512VL one where the CPU has it, else the AVX2 one, else
/// nullptr.
NodeWithin2x2 node_within_2x2_avx2_if_supported(bool disks = true);

}  // namespace caliber::narrow::detail
