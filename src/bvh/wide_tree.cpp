// The wide tree: each wide node a BVH node whose subtree is collapsed to at most eight slots.

#include "bvh/wide_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "util/assert.h"
#include "util/float_round.h"

namespace caliber::bvh {
namespace {

/// Half the surface of node n's box: which slot opens first.
double half_surface(const BvhNode& n) {
  const double x = n.box_half[0], y = n.box_half[1], z = n.box_half[2];
  return x * y + y * z + z * x;
}

void clear_slot(int k, WideNode& out) {
  for (int i = 0; i < 3; ++i) {
    out.lo[i][k] = WideNode::kSteps;
    out.hi[i][k] = -WideNode::kSteps;
    out.axis[i][k] = 0;
  }
  out.slab_lo[k] = out.slab_hi[k] = 0.0f;
  out.node[k] = WideNode::kEmpty;
  out.set_count(std::min(out.count(), k));
  out.set_leaves(out.leaves() & ~(1u << k));
}

/// A node's float box: along each axis, the nearest floats outside its double bounds.
struct FloatBox {
  float lo[3], hi[3];
};
FloatBox float_box(const BvhNode& n) {
  FloatBox out;
  for (int i = 0; i < 3; ++i) {
    const double center = n.box_center[i], half = n.box_half[i];
    out.lo[i] = util::round_down(center - half);
    out.hi[i] = util::round_up(center + half);
  }
  return out;
}

/// The grid of a wide node whose slots' float boxes are boxes[0 .. n): the least power of two
/// step with the boxes within 32000 steps of the origin (the multiple of the step nearest their
/// center), at least 2^-23 of their largest magnitude, so that the origin and every bound within
/// kSteps of it are floats (below 2^24 steps from zero), and at least 2^-126, so that every bound
/// is 0 or a normal float (a process that flushes subnormals reads it as stored).
void set_grid(const FloatBox* boxes, int n, WideNode& out) {
  double lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::numeric_limits<double>::infinity();
    hi[i] = -lo[i];
    for (int k = 0; k < n; ++k) {
      lo[i] = std::min(lo[i], static_cast<double>(boxes[k].lo[i]));
      hi[i] = std::max(hi[i], static_cast<double>(boxes[k].hi[i]));
    }
  }
  double reach = 0.0, far = 0.0, center[3];
  for (int i = 0; i < 3; ++i) {
    center[i] = 0.5 * lo[i] + 0.5 * hi[i];
    reach = std::max(reach, 0.5 * hi[i] - 0.5 * lo[i]);
    far = std::max(far, std::max(std::abs(lo[i]), std::abs(hi[i])));
  }
  const double least = std::max({reach / 32000.0, far * 0x1p-23, 0x1p-126});
  double step = std::ldexp(1.0, std::ilogb(least));
  if (step < least) step *= 2.0;
  out.set_step(static_cast<float>(step));
  for (int i = 0; i < 3; ++i) out.origin[i] = static_cast<float>(std::nearbyint(center[i] / step) * step);
}

/// Writes BVH node `node`, whose float box is `box`, into slot k of `out` (its grid set).
void fill_slot(const ModelData& model, std::uint32_t node, const FloatBox& box, int k, WideNode& out) {
  const double step = out.step(), per_step = 1.0 / step;  // (powers of two: exact)
  for (int i = 0; i < 3; ++i) {
    // The grid's nearest bounds outside the float box: from the quotients (truncated; within a
    // step or two of them), then set exactly (origin + q step is exact in double).
    const double origin = out.origin[i], lo = box.lo[i], hi = box.hi[i];
    auto q_lo = static_cast<int>((lo - origin) * per_step);
    auto q_hi = static_cast<int>((hi - origin) * per_step);
    while (origin + q_lo * step > lo) --q_lo;
    while (origin + (q_lo + 1) * step <= lo) ++q_lo;
    while (origin + q_hi * step < hi) ++q_hi;
    while (origin + (q_hi - 1) * step >= hi) --q_hi;
    CALIBER_ASSERT(q_lo >= -WideNode::kSteps && q_hi <= WideNode::kSteps, "a slot's box lies within its node's grid");
    out.lo[i][k] = static_cast<std::int16_t>(q_lo);
    out.hi[i][k] = static_cast<std::int16_t>(q_hi);
  }
  const SlotSlab slab = slot_slab(model.nodes[node], model.filters[node]);
  for (int i = 0; i < 3; ++i) out.axis[i][k] = slab.axis[i];
  out.slab_lo[k] = slab.lo;
  out.slab_hi[k] = slab.hi;
  out.node[k] = node;
  out.set_count(std::max(out.count(), k + 1));
  const unsigned leaf = model.nodes[node].is_leaf() ? 1u << k : 0u;
  out.set_leaves((out.leaves() & ~(1u << k)) | leaf);
}

/// The slots of internal node `root`: its two children, then, while there is room, one slot
/// replaced by its two children (in place, so the slots stay in the leaf order): the smallest
/// subtree whose triangles all fit in the room left, so that it ends as leaves here rather than as
/// a wide node of a few slots below (fuller nodes: fewer visits); else the slot of largest box
/// surface. Returns how many.
int collapse(const ModelData& m, std::uint32_t root, std::uint32_t slots[WideNode::kSlots]) {
  slots[0] = m.nodes[root].index;
  slots[1] = slots[0] + 1;
  int n = 2;
  while (n < WideNode::kSlots) {
    int best = -1, fits = -1;
    double largest = -1.0;
    for (int k = 0; k < n; ++k) {
      const BvhNode& s = m.nodes[slots[k]];
      if (s.is_leaf()) continue;
      if (half_surface(s) > largest) {
        largest = half_surface(s);
        best = k;
      }
      const bool room = s.count <= static_cast<std::uint32_t>(WideNode::kSlots - n + 1);
      if (room && (fits < 0 || s.count < m.nodes[slots[fits]].count)) fits = k;
    }
    if (fits >= 0) best = fits;
    if (best < 0) break;
    const std::uint32_t first = m.nodes[slots[best]].index;
    for (int k = n; k > best + 1; --k) slots[k] = slots[k - 1];
    slots[best] = first;
    slots[best + 1] = first + 1;
    ++n;
  }
  return n;
}

/// Wide node w with slot k alone.
WideNode with_slot_alone(const WideNode& w, int k) {
  WideNode out = w;
  for (int j = 0; j < WideNode::kSlots; ++j) clear_slot(j, out);
  for (int i = 0; i < 3; ++i) {
    out.lo[i][0] = w.lo[i][k];
    out.hi[i][0] = w.hi[i][k];
    out.axis[i][0] = w.axis[i][k];
  }
  out.slab_lo[0] = w.slab_lo[k];
  out.slab_hi[0] = w.slab_hi[k];
  out.node[0] = w.node[k];
  out.set_count(1);
  out.set_leaves(w.leaves() >> k & 1u);
  return out;
}

}  // namespace

SlotSlab slot_slab(const BvhNode& n, const BvhNodeFilter& f) {
  SlotSlab out{};
  // For a vertex v of the box (center c, half-extents h): a' . v = a . v + d . v, where
  // d = a' - a (exact in double), and d . v lies within d . c +- |d| . h.
  double at = 0.0, reach = 0.0, magnitude = std::max(std::abs(double{f.slab_lo}), std::abs(double{f.slab_hi}));
  for (int i = 0; i < 3; ++i) {
    out.axis[i] = util::half_toward_zero(f.cone_axis[i]);
    const double d = double{util::half_value(out.axis[i])} - f.cone_axis[i], c = n.box_center[i], h = n.box_half[i];
    at += d * c;
    reach += std::abs(d) * h;
    magnitude += std::abs(d) * (std::abs(c) + h);
  }
  const double rounding = magnitude * 0x1p-48;  // (the few double roundings above: far below it)
  out.lo = util::round_down(f.slab_lo + at - reach - rounding);
  out.hi = util::round_up(f.slab_hi + at + reach + rounding);
  return out;
}

WideNode single_slot(const ModelData& model, std::uint32_t node) {
  if (const std::uint32_t slot = model.nodes[node].slot; slot != BvhNode::kNoSlot) {
    return with_slot_alone(model.wide[slot / WideNode::kSlots], static_cast<int>(slot % WideNode::kSlots));
  }
  // (A slot whose wide node is too far on for BvhNode::slot.) The wide node that holds `node` as
  // a slot, from the root down: at each, the slot whose run of leaves holds node's first leaf is
  // node, or holds node below it.
  const std::uint32_t place = model.first_leaf(node), count = model.nodes[node].count;
  std::uint32_t holder = 0, first = 0;  // the BVH node whose wide node is searched, its first leaf's place
  while (node != holder && model.nodes[holder].has_wide()) {
    const WideNode& w = model.wide[model.nodes[holder].link];
    int k = 0;
    while (place >= first + model.nodes[w.node[k]].count) first += model.nodes[w.node[k++]].count;
    if (w.node[k] == node) return with_slot_alone(w, k);
    if (model.nodes[w.node[k]].count <= count) break;  // node lies between w's root and its slots
    holder = w.node[k];
  }
  // Not a slot (the root, or a node inside a wide node's slots): on a grid of its own.
  CALIBER_ASSERT(false, "a node of the wide CD tree is a slot of a wide node");
  WideNode out{};
  const FloatBox box = float_box(model.nodes[node]);
  set_grid(&box, 1, out);
  for (int k = 0; k < WideNode::kSlots; ++k) clear_slot(k, out);
  fill_slot(model, node, box, 0, out);
  return out;
}

void build_wide_tree(ModelData& model) {
  model.wide.clear();
  for (BvhNode& n : model.nodes) {
    n.slot = BvhNode::kNoSlot;
    n.link = BvhNode::kNoWide;
  }
  if (model.nodes.empty() || model.nodes[0].is_leaf()) return;
  // Depth first, an explicit stack (a BVH may be deep): each wide node is made when its BVH node
  // is popped, so a node's slots come after it.
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t root = stack.back();
    stack.pop_back();
    std::uint32_t slots[WideNode::kSlots];
    const int n = collapse(model, root, slots);
    const auto index = static_cast<std::uint32_t>(model.wide.size());
    model.nodes[root].link = index;
    WideNode& w = model.wide.emplace_back();
    FloatBox boxes[WideNode::kSlots];
    for (int k = 0; k < n; ++k) boxes[k] = float_box(model.nodes[slots[k]]);
    set_grid(boxes, n, w);
    for (int k = 0; k < WideNode::kSlots; ++k) {
      if (k < n) {
        fill_slot(model, slots[k], boxes[k], k, w);
        if (index < BvhNode::kSlotWideNodes)
          model.nodes[slots[k]].slot = index * WideNode::kSlots + static_cast<std::uint32_t>(k);
      } else {
        clear_slot(k, w);
      }
    }
    for (int k = n; k-- > 0;) {
      if (!model.nodes[slots[k]].is_leaf()) stack.push_back(slots[k]);
    }
  }
}

}  // namespace caliber::bvh
