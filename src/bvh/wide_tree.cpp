// The wide tree: each wide node a BVH node whose subtree is collapsed to at most eight slots.

#include "bvh/wide_tree.h"

#include <cmath>
#include <limits>
#include <vector>

namespace caliber::bvh {
namespace {

/// The largest float at or below d, and the smallest at or above it.
float float_below(double d) {
  float f = static_cast<float>(d);
  if (static_cast<double>(f) > d) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float float_above(double d) {
  float f = static_cast<float>(d);
  if (static_cast<double>(f) < d) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

/// Half the surface of node n's box: which slot opens first.
double half_surface(const BvhNode& n) {
  const double x = n.box_half[0], y = n.box_half[1], z = n.box_half[2];
  return x * y + y * z + z * x;
}

void clear_slot(int k, WideNode& out) {
  for (int i = 0; i < 3; ++i) {
    out.lo[i][k] = std::numeric_limits<float>::infinity();
    out.hi[i][k] = -std::numeric_limits<float>::infinity();
    out.axis[i][k] = 0.0f;
  }
  out.slab_lo[k] = out.slab_hi[k] = 0.0f;
  out.node[k] = WideNode::kEmpty;
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

}  // namespace

void fill_wide_slot(const ModelData& model, std::uint32_t node, int k, WideNode& out) {
  const BvhNode& n = model.nodes[node];
  const BvhNodeFilter& f = model.filters[node];
  for (int i = 0; i < 3; ++i) {
    const double center = n.box_center[i], half = n.box_half[i];
    out.lo[i][k] = float_below(center - half);
    out.hi[i][k] = float_above(center + half);
    out.axis[i][k] = f.cone_axis[i];
  }
  out.slab_lo[k] = f.slab_lo;
  out.slab_hi[k] = f.slab_hi;
  out.node[k] = node;
}

WideNode single_slot(const ModelData& model, std::uint32_t node) {
  WideNode out;
  for (int k = 0; k < WideNode::kSlots; ++k) clear_slot(k, out);
  fill_wide_slot(model, node, 0, out);
  return out;
}

void build_wide_tree(ModelData& model) {
  model.wide.clear();
  model.wide_of.assign(model.nodes.size(), WideNode::kEmpty);
  if (model.nodes.empty() || model.nodes[0].is_leaf()) return;
  // Depth first, an explicit stack (a BVH may be deep): each wide node is made when its BVH node
  // is popped, so a node's slots come after it.
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t root = stack.back();
    stack.pop_back();
    std::uint32_t slots[WideNode::kSlots];
    const int n = collapse(model, root, slots);
    model.wide_of[root] = static_cast<std::uint32_t>(model.wide.size());
    WideNode& w = model.wide.emplace_back();
    for (int k = 0; k < WideNode::kSlots; ++k) {
      if (k < n) {
        fill_wide_slot(model, slots[k], k, w);
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
