// The storage per pair and per object that docs/architecture.md ("Memory") states: if one of these
// structures grows, this test fails and the stated bound must be measured and written again.

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "broad/box_tree.h"
#include "caliber/engine.h"
#include "caliber/scene.h"
#include "narrow/pair_context.h"
#include "plans/calibration.h"

namespace caliber {
namespace {

TEST(Memory, PerPairStorageWithinTheStatedBound) {
  // The context's storage is kept at up to 1.25 times the largest step's pairs (ContextStore).
  const double context = 1.25 * sizeof(narrow::PairContext);
  EXPECT_LE(sizeof(narrow::PairContext), 592u);
  const std::size_t result = sizeof(QueryResult) + sizeof(PairRecord) + sizeof(std::size_t);
  EXPECT_LE(result, 56u + 48u + 8u);
  const std::size_t broad = 2 * sizeof(ObjectPair);  // found, then sorted into the frame
  // The largest plan entry per pair: a task of its own (sequential, exploitation); a cart root, its
  // two sort keys and its history entry (calibrated methods); stealing's 65 bytes are less.
  const std::size_t plan = std::max(sizeof(plans::RunTask), sizeof(plans::Root) + 48 + 16);
  EXPECT_LE(plan, 184u);
  EXPECT_LE(context + static_cast<double>(result + broad + plan), 1100.0) << "bytes a pair, beside the threads' slots";
  // Per worker thread: the pair's candidate list and counts.
  EXPECT_LE(sizeof(std::vector<narrow::Candidate>) + sizeof(QueryStats), 40u);
  EXPECT_LE(sizeof(Contact), 104u);
}

TEST(Memory, PerObjectStorageWithinTheStatedBound) {
  // The broad phase: the box, the box in the tree's order, order + code + scratch, the counting
  // sort's start; the tree's nodes (64 bytes, one per two objects on the grid scenes) come beside.
  const std::size_t broad = sizeof(broad::WorldBox) + sizeof(broad::FlatBox) + 3 * sizeof(std::uint32_t) + sizeof(std::uint32_t);
  EXPECT_LE(broad + 32u, 150u);
  EXPECT_LE(sizeof(Pose) + sizeof(std::shared_ptr<const Model>), 80u) << "the frame's pose and model pointer";
  EXPECT_LE(sizeof(SceneObject), 272u) << "a World's scene entry (its name and groups on the heap)";
}

}  // namespace
}  // namespace caliber
