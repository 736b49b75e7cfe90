#pragma once
/// \file
/// The wide tree of a built BVH (WideNode): collapsed from its binary nodes, so that both describe
/// the same volumes and a slot is a BVH node.

#include <cstdint>

#include "bvh/model_data.h"

namespace caliber::bvh {

/// Builds model.wide from model.nodes and model.filters (the BVH already built), and sets each
/// node's slot and link.
void build_wide_tree(ModelData& model);

/// The slab a wide node keeps of its slot n (filter f): f's axis with each component cut toward
/// zero to a half float (so no longer than f's: the queries' slab reach holds along it), and
/// bounds along that axis from f's, moved over n's box (which holds every vertex below n) and
/// rounded outward. An axis of 0 keeps bounds of 0 (it prunes nothing).
struct SlotSlab {
  std::uint16_t axis[3];  ///< (half floats)
  float lo, hi;
};
[[nodiscard]] SlotSlab slot_slab(const BvhNode& n, const BvhNodeFilter& f);

/// A wide node whose one slot is BVH node `node` as the wide node that holds it as a slot has it
/// (its grid, its bounds; the others empty): what a node's own test reads where no visit of its
/// parent tested it (narrow::RootTest). `node` is a slot of some wide node (a node of the wide CD
/// tree, not the root).
[[nodiscard]] WideNode single_slot(const ModelData& model, std::uint32_t node);

}  // namespace caliber::bvh
