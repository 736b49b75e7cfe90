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

/// Validates the input (caliber::broad_phase's errors), then sets `out` to the sorted pairs whose
/// world boxes, grown by reach / 2, overlap, less the pairs of two fixed objects and the ignored
/// ones. In parallel on the executor the caller runs in (serially outside any).
void find_pairs(State& state, const std::vector<std::shared_ptr<const Model>>& models, const std::vector<Pose>& poses,
                double reach, const std::vector<bool>& fixed, const std::vector<ObjectPair>& ignored,
                std::vector<ObjectPair>& out);

}  // namespace caliber::broad
