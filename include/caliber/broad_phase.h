#pragma once
/// \file
/// The broad phase over a program's own objects: which object pairs a frame needs tested. The
/// one World uses for scene files, callable on models and poses held in memory.

#include <memory>
#include <vector>

#include "caliber/engine.h"
#include "caliber/export.h"
#include "caliber/model.h"
#include "caliber/pose.h"

namespace caliber {

/// The object pairs whose world boxes overlap, as Frame::pairs takes them (a < b, sorted, each
/// once): object i is models[i] at poses[i], its box the model's root box moved by the pose
/// (conservative) and grown by reach / 2 and a rounding margin, so that every pair of objects
/// within `reach` of each other is kept (pass the request's reach(request): 0 for interference,
/// the tolerance otherwise). `fixed` is empty or holds one flag per object: a pair of two fixed
/// objects is skipped (they never move against each other). `ignored` lists pairs never tested
/// (a < b, any order). The pairs are exactly those whose boxes overlap (closed intervals on the
/// three axes): a tree of boxes over the objects in Morton order prunes the search, each pair met
/// once. Runs on the calling thread; Engine::find_pairs runs the same search on the engine's threads
/// and keeps the tree from one frame to the next.
/// Throws caliber::Error (source "broad phase") on a null model, sizes that do not match, or an
/// ignored pair that names no two objects a < b; and (source "reach") on a reach that is negative,
/// not finite or above 1e15 (kMaxCoordinate, as a query's tolerance).
[[nodiscard]] CALIBER_EXPORT std::vector<ObjectPair> broad_phase(const std::vector<std::shared_ptr<const Model>>& models,
                                                                 const std::vector<Pose>& poses, double reach,
                                                                 const std::vector<bool>& fixed = {},
                                                                 const std::vector<ObjectPair>& ignored = {});

}  // namespace caliber
