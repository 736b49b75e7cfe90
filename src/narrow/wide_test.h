#pragma once
/// \file
/// The node test of the pair-collecting queries (interference, proximity, contact): a CD-tree node
/// descends on one side, and its children, the pairs of the staying node with each slot of the
/// descending side's wide node (WideNode), are tested at once, eight lanes of float.
///
/// 1. The boxes, exactly: the staying node's box moved into the other model's frame in double
///    (center M c + t, half-extents |M| h + reach: PairContext's box test's quantities), grown by a
///    share of its magnitude that covers the conversion, and rounded to float; each slot's box
///    (its grid bounds, floats computed exactly: WideNode) overlaps it or the pair is refused, as
///    are the empty slots. No slack: every float lies outside the double box it stands for.
/// 2. Then, in float, against each threshold plus a slack far above float's rounding (as the float
///    four-pair test: 2^-15 of the scale): each slot's box along the staying node's own axes; each
///    slot's slab against the staying box, or where the staying node is a leaf against its
///    triangle's corners, less and plus their error (staying_corners); the staying node's slab
///    against each slot, projected
///    along it as lambda (the slot's slab) + the rest (the slot's box), lambda the axes' cosine
///    where the slabs are near parallel (|cos| >= 1/2; else 0: the slot's box alone), so that
///    parallel patches a hair apart are refused high in the tree. Refused only where surely
///    beyond.
/// Every form (AVX2, scalar) makes each lane's operations in the same order: the same decisions.
/// What they compute of the staying node is kept for the visits after, when given a cache
/// (StayingCache).

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "bvh/leaf_shape.h"
#include "bvh/model_data.h"
#include "narrow/node_test_avx2.h"

namespace caliber::narrow::detail {

/// The pose as a visit moves its staying node into the descending side's frame, x_D = M x_S + t:
/// M = R, t = T where A descends (B stays); M = R^T, t = -R^T T where B descends.
struct alignas(32) WideSide {
  double col[3][4];      ///< column j of M (lanes x, y, z, 0)
  double abs_col[3][4];  ///< column j of |M| grown by the hair (PairContext's abs_rot)
  double t[4];           ///< t
  double mt_t[4];        ///< M^T t
  float m[3][3][8];      ///< m[j][i][*] = M(j, i) in float, in every lane
  float abs_m[3][3][8];  ///< its magnitude
};

/// What the test reads besides the nodes: both directions, the reach, and the float stage's
/// thresholds. The float stage computes in units of `unit`, 2^-k for the scale's exponent k (the
/// scale is 1 to 2 units), so that its values are near 1 and scale with the models exactly: a pose
/// and models scaled by a power of two get the same decisions, down to scales of about 2^-117,
/// where floats' smallest steps (and the stage-1 floor, 2^-149) stop scaling. Made once per traversal
/// (make_wide_lanes; 1,728 bytes: not kept in the pair context, which the engine holds for every
/// pair).
struct alignas(32) WideLanes {
  WideSide side[2];    ///< [0]: A descends; [1]: B descends
  double reach;        ///< the boxes' reach
  double round_floor;  ///< stage 1's least growth before rounding to float
  double unit;         ///< the float stage's unit
  float unit_f;        ///< the same, in float
  float half_unit;     ///< half of it
  float reach_f;       ///< the reach plus the slack, in units
  float slab_f;        ///< the slab reach plus the slack, in units
  bool floats;         ///< the float stage runs
  /// The wide nodes of the side that stays: [0] B's (A descends), [1] A's (StayingSlab).
  const WideNode* staying_wide[2];
};

/// l.side[0] where A descends, else l.side[1], its address hidden from the optimizer: the test then
/// reads each field from one base register, where the compiler would keep each field's offset for
/// either side apart (spilled to the stack at every visit).
inline const WideSide& side_of(const WideLanes& l, bool a_descends) {
  const WideSide* s = &l.side[a_descends ? 0 : 1];
#if defined(__GNUC__)
  asm("" : "+r"(s));
#endif
  return *s;
}

/// The staying node as the float stage reads it, in the descending frame and in units (the same
/// operations in every form): its own center plus M^T t, its half-extents plus the reach, its slab
/// axis moved (nf) and the slab's offset, its center moved (cf), its half-extents (sh), its slab
/// bounds less and plus the slab reach; and where it is a leaf (`triangle`), its triangle's
/// corners moved (corner[j][i]: coordinate i of corner j) and how far they may lie from the true
/// ones along any unit axis (corner_error), which the slots' slabs are tested against in place of
/// its box (staying_corners).
struct StayingFloats {
  float co[3], ho[3], nf[3], off, cf[3], sh[3], slab_lo, slab_hi;
  float corner[3][4];      ///< (the fourth lane 0; all 0 where the node is no leaf)
  float corner_error;      ///< (0 where the node is no leaf)
  std::uint32_t triangle;  ///< 1 for a leaf, else 0 (a whole word: the struct has no padding)
};
static_assert(sizeof(StayingFloats) == 32 * 4, "every byte of StayingFloats is a value (the forms compare them)");

/// The staying nodes of a traversal's visits as the test moved them, kept for the visits after
/// them: a staying node stays for the visits below it while the other side descends, and those
/// visits read it here rather than move it again (the same values: the same operations on the
/// same node). A table of kEntries, each node at one place (by its index and side), a newer node
/// taking an older one's place. The test claims and fills it. One thread's traversals use it one
/// after the other (TraversalScratch::staying), each from renew on: one pair context and its lanes.
struct StayingCache {
  static constexpr int kEntries = 64;
  /// One staying node moved.
  struct Entry {
    alignas(16) float lo[4];      ///< stage 1's box, its low corner (lanes x, y, z; the fourth unused)
    alignas(16) float hi[4];      ///< its high corner
    alignas(32) double moved[4];  ///< its box center in the descending frame (lanes x, y, z; the fourth 0)
    bool has_floats;              ///< `floats` made (stage 2 ran on it)
    StayingFloats floats;         ///< what stage 2 reads of it
  };
  /// When the generation reaches this, the keys are cleared and it starts again at 1.
  static constexpr std::uint64_t kGenerations = std::uint64_t{1} << 29;
  std::uint64_t key[kEntries] = {};  ///< generation << 34 | (2 stay + (A descends)); 0: empty
  Entry entry[kEntries];
  std::uint64_t generation = 1;  ///< the traversal's (renew): the keys of earlier ones do not match

  /// Starts a traversal (of any pair, pose and lanes): nothing kept before is found again.
  void renew() {
    if (++generation == kGenerations) {
      for (std::uint64_t& k : key) k = 0;
      generation = 1;
    }
  }
  /// The place of node `stay` moved for the side `a_descends` says; `held`: whether it holds that
  /// node.
  Entry& find(std::uint32_t stay, bool a_descends, bool& held) {
    const std::uint64_t k = key_of(stay, a_descends);
    held = key[place(k)] == k;
    return entry[place(k)];
  }
  /// find, and where the place does not hold the node, the place named its own: the caller fills it
  /// (fill) before anything reads it.
  Entry& claim(std::uint32_t stay, bool a_descends, bool& held) {
    const std::uint64_t k = key_of(stay, a_descends);
    const std::size_t at = place(k);
    held = key[at] == k;
    key[at] = k;
    return entry[at];
  }
  /// Never 0 (generation >= 1); 2 stay + 1 < 2^33, below the generation's bits.
  [[nodiscard]] std::uint64_t key_of(std::uint32_t stay, bool a_descends) const {
    return generation << 34 | (2u * std::uint64_t{stay} + (a_descends ? 1u : 0u));
  }
  static std::size_t place(std::uint64_t k) { return static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> 58); }
  /// Fills entry e with a node moved: its center `c`, its box lo, hi (its floats not yet made).
  static void fill(Entry& e, const double c[3], const float lo[3], const float hi[3]) {
    e.has_floats = false;
    for (int i = 0; i < 3; ++i) {
      e.moved[i] = c[i];
      e.lo[i] = lo[i];
      e.hi[i] = hi[i];
    }
    e.lo[3] = e.hi[3] = 0.0f;
    e.moved[3] = 0.0;
  }
};

/// A staying node's slab: its axis and bounds, as its slot (bvh::slot_slab) or its BvhNodeFilter
/// stores them.
struct StayingSlab {
  float axis[3], lo, hi;
};
/// The slab of node `stay` (sn), of B where A descends: read in the wide node that holds it
/// (BvhNode::slot; the visit that reached it read that node), its axis's half floats read by
/// `half` (util::half_value, or the CPU's conversion: the same floats), else in its filter.
template <class Half = float (*)(std::uint16_t)>
inline StayingSlab staying_slab(const NodeTestFrame& f, const WideLanes& l, bool a_descends, std::uint32_t stay,
                                const BvhNode& sn, Half half = util::half_value) {
  if (sn.slot != BvhNode::kNoSlot) {
    const WideNode& w = l.staying_wide[a_descends ? 0 : 1][sn.slot / WideNode::kSlots];
    const std::uint32_t k = sn.slot % WideNode::kSlots;
    return {{half(w.axis[0][k]), half(w.axis[1][k]), half(w.axis[2][k])}, w.slab_lo[k], w.slab_hi[k]};
  }
  const BvhNodeFilter& sf = a_descends ? f.filters_b[stay] : f.filters_a[stay];
  return {{sf.cone_axis[0], sf.cone_axis[1], sf.cone_axis[2]}, sf.slab_lo, sf.slab_hi};
}

/// Where the staying node sn is a leaf, its triangle's corners as leaf_corners decodes them, in the
/// descending frame and in units, moved as its box center is (M x + t, each step rounded once, then
/// times the unit, rounded to float once; the AVX2 form makes the same operations in lanes), with
/// their error along any unit axis (sqrt(3) times leaf_corners' along each, rounded up):
/// out.corner, out.corner_error and out.triangle. The moved corners lie within that error, plus a
/// few unit roundoffs of the scale (the box's rounding and the moves': the slack covers those, as
/// it does for the moved box center), of the points the leaf test reads.
inline void staying_corners(const WideLanes& l, const WideSide& s, const BvhNode& sn, StayingFloats& out) {
  out.triangle = sn.is_leaf() ? 1u : 0u;
  out.corner_error = 0.0f;
  for (float(&c)[4] : out.corner) c[0] = c[1] = c[2] = c[3] = 0.0f;
  if (out.triangle == 0) return;
  double p[3][3], error;
  bvh::leaf_corners(sn, p, error);
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      const double x = std::fma(s.col[2][i], p[j][2], std::fma(s.col[1][i], p[j][1], std::fma(s.col[0][i], p[j][0], s.t[i])));
      out.corner[j][i] = static_cast<float>(x * l.unit);
    }
  }
  out.corner_error = static_cast<float>(1.75 * error * l.unit);
}

/// The staying node sn (slab sf) of a visit in direction s, its box center already moved (c).
inline StayingFloats staying_floats(const WideLanes& l, const WideSide& s, const BvhNode& sn, const StayingSlab& sf,
                                    const double c[3]) {
  StayingFloats out;
  double nd[3];
  for (int i = 0; i < 3; ++i) {
    nd[i] = std::fma(s.col[2][i], sf.axis[2], std::fma(s.col[1][i], sf.axis[1], s.col[0][i] * sf.axis[0]));
    out.co[i] = static_cast<float>((static_cast<double>(sn.box_center[i]) + s.mt_t[i]) * l.unit);
    out.sh[i] = static_cast<float>(sn.box_half[i] * l.unit);
    out.ho[i] = out.sh[i] + l.reach_f;
    out.nf[i] = static_cast<float>(nd[i]);
    out.cf[i] = static_cast<float>(c[i] * l.unit);
  }
  out.off = static_cast<float>(-((nd[0] * s.t[0] + nd[1] * s.t[1]) + nd[2] * s.t[2]) * l.unit);
  out.slab_lo = static_cast<float>(sf.lo * l.unit) - l.slab_f;
  out.slab_hi = static_cast<float>(sf.hi * l.unit) + l.slab_f;
  staying_corners(l, s, sn, out);
  return out;
}

/// The box of the node that stays, sn, in double: center, half-extents.
struct StayingBox {
  double c[3], h[3];
};
inline StayingBox staying_box(const BvhNode& sn) {
  return StayingBox{{sn.box_center[0], sn.box_center[1], sn.box_center[2]}, {sn.box_half[0], sn.box_half[1], sn.box_half[2]}};
}

/// A test's entry for node `stay`: its place in `cache` (`held`: whether it holds the node, else
/// the place is claimed for it and the test fills it: StayingCache::claim), or `spare` without a
/// cache.
inline StayingCache::Entry& staying_entry(StayingCache* cache, StayingCache::Entry& spare, std::uint32_t stay, bool a_descends,
                                          bool& held) {
  held = false;
  return cache != nullptr ? cache->claim(stay, a_descends, held) : spare;
}

/// Makes entry `kept`'s float values (stage 2's) for node `stay` (sn), unless made already.
inline void make_staying_floats(const NodeTestFrame& f, const WideLanes& l, bool a_descends, std::uint32_t stay,
                                const BvhNode& sn, StayingCache::Entry& kept) {
  if (kept.has_floats) return;
  kept.floats = staying_floats(l, side_of(l, a_descends), sn, staying_slab(f, l, a_descends, stay, sn), kept.moved);
  kept.has_floats = true;
}

/// The lanes of frame f (its pose, reach and slab reach) between models a and b, written to `l`
/// (made in place: a traversal's lanes are 1,728 bytes, too many to copy for a query that stops
/// early). `scale`: a bound on every coordinate, extent, reach and slab bound the test computes
/// with, which sets the slack.
void make_wide_lanes(const NodeTestFrame& f, double scale, const ModelData& a, const ModelData& b, WideLanes& l);

/// The test of the children of a visit whose side `a_descends` says (true: A's node descends, B's
/// node `stay` stays; sn: its BvhNode) against the descending node's wide node w: bit k set where
/// slot k passes (slots past the last never do). The staying node is read from `cache` where it
/// holds it, else moved and kept there (null: moved for this test alone).
using WideTest = unsigned (*)(const NodeTestFrame& f, const WideLanes& l, bool a_descends, std::uint32_t stay, const BvhNode& sn,
                              const WideNode& w, StayingCache* cache);

/// The scalar form.
unsigned wide_test_scalar(const NodeTestFrame& f, const WideLanes& l, bool a_descends, std::uint32_t stay, const BvhNode& sn,
                          const WideNode& w, StayingCache* cache);

/// The AVX2 form, or (wide_registers) the same form built for AVX-512VL too (32 vector registers;
/// the same decisions); nullptr where the CPU (or this build) lacks what the form needs.
WideTest wide_test_form(bool wide_registers);

/// The order keys of the slots of wide node w against the staying node whose stage-1 box `kept`
/// holds (its box moved into w's frame, as floats): per slot, how far apart the two boxes' centers
/// lie relative to their sizes, the sum over the axes of |(low + high) - (kept.lo + kept.hi)| over
/// the sum of both boxes' extents (plus float's least normal: 0 for the same center, at most 1
/// where the boxes overlap). The centers are taken from w's grid origin (the slots' exactly, as
/// (q_lo + q_hi) step), so that a wide node far from its model's origin keeps the keys' precision.
/// Finite and at least 0 for the finite boxes of validated input (coordinates up to 1e15). Every
/// form makes each slot's operations in the same order, unfused: the same keys. Empty slots get
/// whatever their bounds give.
using SlotOrderKeys = void (*)(const StayingCache::Entry& kept, const WideNode& w, float keys[WideNode::kSlots]);
/// The portable form.
void slot_order_keys_portable(const StayingCache::Entry& kept, const WideNode& w, float keys[WideNode::kSlots]);
/// The AVX2 form, or nullptr where the CPU (or this build) has no AVX2.
SlotOrderKeys slot_order_keys_avx2_if_supported();

}  // namespace caliber::narrow::detail
