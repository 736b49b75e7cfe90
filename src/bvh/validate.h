#pragma once
/// \file
/// The invariants of a built BVH, checked in one pass (after Box2D's b2Validate functions): the
/// debug and sanitizer builds check them at the end of every build (CALIBER_ASSERT), and tests call
/// the check on built models and on models broken on purpose.

#include <string>

#include "bvh/model_data.h"

namespace caliber::bvh {

/// The first broken invariant of `model`'s BVH, in words (empty when none): the node arrays of one
/// size (2n - 1 for n triangles); every node reached once from the root, children after their
/// parent; counts that add up; every subtree a run of the leaf order (leaf_position);
/// every triangle in one leaf; each leaf's sphere, box and slab around its triangle's vertices
/// (relative to ModelData::origin); group masks the union of their children's; and where the wide
/// tree is built, each wide node named by one inner node (BvhNode::link), its 2 to 8 slots counted
/// (WideNode::count), each a node, an inner one with a wide node, their runs of leaves following
/// one another over the naming node's (so each lies below it), and each node's slot
/// (BvhNode::slot) holding it with the slab bvh::slot_slab makes of its filter's.
[[nodiscard]] std::string bvh_problem(const ModelData& model);

}  // namespace caliber::bvh
