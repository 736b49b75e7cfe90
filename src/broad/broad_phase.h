#pragma once
/// \file
/// The broad phase as the engine keeps it from frame to frame (Engine::find_pairs) and as
/// caliber::broad_phase runs it once.

#include <memory>
#include <vector>

#include "broad/box_tree.h"
#include "caliber/model.h"
#include "caliber/pose.h"

namespace caliber::broad {

/// What the broad phase keeps between frames: the tree and its buffers.
struct State {
  BoxTree tree;
  std::vector<WorldBox> boxes;
  std::vector<std::uint64_t> ignored;
};

/// Checks objects for a broad phase or a sweep: as many poses as models, no missing model, each pose
/// valid (named "<source>: <pose_name> of object i"), `fixed` empty or one per object, ignored pairs
/// a < b < objects. Throws caliber::Error whose source is `source`.
void validate_objects(const char* source, const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                      const char* pose_name, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored);

/// Sets `keys` to the pairs as PairFilter::ignored holds them: (a << 32 | b), sorted.
void pair_keys(const std::vector<ObjectPair>& pairs, std::vector<std::uint64_t>& keys);

/// Validates the input (caliber::broad_phase's errors), then sets `out` to the sorted pairs whose
/// world boxes, grown by reach / 2, overlap, less the pairs of two fixed objects and the ignored
/// ones. In parallel on the executor the caller runs in (serially outside any).
void find_pairs(State& state, const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                double reach, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored,
                std::vector<ObjectPair>& out);

}  // namespace caliber::broad
