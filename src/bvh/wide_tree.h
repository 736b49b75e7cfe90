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

/// A wide node whose one slot is BVH node `node` as the wide node that holds it as a slot has it
/// (its grid, its bounds; the others empty): what a node's own test reads where no visit of its
/// parent tested it (narrow::RootTest). `node` is a slot of some wide node (a node of the wide CD
/// tree, not the root).
[[nodiscard]] WideNode single_slot(const ModelData& model, std::uint32_t node);

}  // namespace caliber::bvh
