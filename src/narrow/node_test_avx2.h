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
/// traversal (1,504 bytes: not kept in the pair context, which the engine holds for every pair).
struct NodeLanes {
  double rot[3][3][4], abs_rot[3][3][4], pre[3][4], post[3][4];
  /// The float pre-decision (node_test_float.cpp): eight lanes that move [sphere centers | box
  /// centers] (`move`: rot's lanes twice, then post8: -R^T T in A's lanes, T in B's, computed in
  /// double) and turn [half-extents | slab axes] (`turn`: abs_rot's lanes, then rot's), each value
  /// rounded to float once.
  alignas(32) float move[3][3][8];
  alignas(32) float turn[3][3][8];
  alignas(32) float post8[3][8];
  /// The thresholds of the float comparisons, each the double one less (lo) and plus (hi) a slack
  /// far above the float rounding (FloatSlack): the boxes' reach, the slabs' slab_reach, the
  /// spheres' reach (twice the slack); then slab_reach, the disks' slack on their gaps and on the
  /// squared sine between slab axes (cross), and hair. `floats` is false where the scale is too
  /// large or small for float's range: the double form alone.
  float reach_lo, reach_hi, slab_lo, slab_hi, sphere_lo, sphere_hi, slab, disk_slack, cross_slack, hair;
  bool floats;
};

/// The float pre-decision's slacks: 2^-15 of the scale on every linear quantity (512 times
/// float's unit roundoff of the scale; the rounding of the quantities compared adds up to about
/// 160 of it at most), twice that on the spheres' and the disks' distances, 2^-16 on the squared
/// sine (the rounding: about 100 unit roundoffs); the range of scales where floats are used.
struct FloatSlack {
  static constexpr double kShare = 0x1p-15, kCross = 0x1p-16, kLeast = 1e-12, kMost = 1e12;
};

/// The lanes of frame f's pose. `scale`: a bound on the magnitude of every coordinate, extent,
/// reach and slab bound the test computes with (the extents about the volume origins, the distance
/// between those, the slab reach), which sets the float pre-decision's slack.
inline NodeLanes make_lanes(const NodeTestFrame& f, double scale) {
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
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 8; ++i) {
        l.move[k][j][i] = static_cast<float>(l.rot[k][j][i % 4]);
        l.turn[k][j][i] = static_cast<float>(i < 4 ? l.abs_rot[k][j][i] : l.rot[k][j][i - 4]);
      }
    }
    for (int i = 0; i < 8; ++i) {
      const int n = i % 4;
      const double moved_trans = (l.rot[k][0][n] * l.pre[0][n] + l.rot[k][1][n] * l.pre[1][n]) + l.rot[k][2][n] * l.pre[2][n];
      l.post8[k][i] = static_cast<float>(l.post[k][n] - moved_trans);
    }
  }
  const double slack = FloatSlack::kShare * scale;
  l.floats = scale >= FloatSlack::kLeast && scale <= FloatSlack::kMost;
  l.reach_lo = static_cast<float>(f.reach - slack);
  l.reach_hi = static_cast<float>(f.reach + slack);
  l.slab_lo = static_cast<float>(f.slab_reach - slack);
  l.slab_hi = static_cast<float>(f.slab_reach + slack);
  l.sphere_lo = static_cast<float>(f.reach - 2.0 * slack);
  l.sphere_hi = static_cast<float>(f.reach + 2.0 * slack);
  l.slab = static_cast<float>(f.slab_reach);
  l.disk_slack = static_cast<float>(2.0 * slack);
  l.cross_slack = static_cast<float>(FloatSlack::kCross);
  l.hair = static_cast<float>(f.hair);
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

/// The form the node test runs: with the disks, the float pre-decision wherever the CPU has AVX2
/// (node_within_2x2_float_form); without them, the AVX-512VL form where the CPU has it, else the
/// AVX2 one; else nullptr.
NodeWithin2x2 node_within_2x2_avx2_if_supported(bool disks = true);

/// The contact angle as the cone test reads it (PairContext::cones_can_face): theta, its cosine
/// and sine, and the margin on the cosine.
struct ConeAngle {
  double theta, cos, sin, margin;
};

/// Bit 2i + j set where the normal cones of node ai of A and node bj of B can face within the
/// angle: PairContext::cones_can_face on the four pairs at once, the same operations lane by lane
/// (so the same decisions).
using ConesFace2x2 = int (*)(const NodeTestFrame& frame, const NodeLanes& lanes, std::uint32_t a0, std::uint32_t a1,
                             std::uint32_t b0, std::uint32_t b1, const ConeAngle& angle);

/// The AVX2 form of ConesFace2x2, or nullptr where the CPU has no AVX2.
ConesFace2x2 cones_face_2x2_avx2_if_supported();

/// The four-pair form with the disks in AVX2, double precision (node_within_2x2_form(false)'s).
int node_within_2x2_double(const NodeTestFrame& frame, const NodeLanes& lanes, std::uint32_t a0, std::uint32_t a1,
                           std::uint32_t b0, std::uint32_t b1);

/// The float pre-decision of the four-pair form with the disks (node_test_float.cpp): sets bit k
/// of `pass` where pair k surely passes, of `unsure` where the float rounding leaves the double
/// form's decision in doubt (neither bit: it surely fails). Needs AVX2 and lanes.floats.
void node_within_2x2_float_bits(const NodeTestFrame& frame, const NodeLanes& lanes, std::uint32_t a0, std::uint32_t a1,
                                std::uint32_t b0, std::uint32_t b1, int& pass, int& unsure);

/// The four-pair form the node test runs on an AVX2 CPU: the float pre-decision, and the AVX2
/// double form where some pair is in doubt (or lanes.floats is false). The double form's
/// decisions, bit for bit. nullptr where the CPU has no AVX2.
NodeWithin2x2 node_within_2x2_float_form();

}  // namespace caliber::narrow::detail
