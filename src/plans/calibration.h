#pragma once
/// \file
/// Task calibration (docs/design.md section 3): from the step's pairs and their weights, a
/// run-time task list whose tasks all have about the same weight, the caliber Omega.
///   Omega = sum of weights / (beta * threads); a pair within [Omega - eps, Omega + eps] runs as is,
///   a heavier one is split by the weight-driven stage, a lighter one goes to the cart; the cart is
///   sorted and its heaviest item is merged with the lightest ones until the merge reaches Omega.

#include <array>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "caliber/query.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"

namespace caliber::plans {

/// A piece of work for one thread: a CD-tree node of one pair, and whether the weight-driven stage
/// already tested it (then the depth-first traversal starts below it, so no node is tested twice).
struct Root {
  std::uint32_t pair;       ///< index of the object pair (in the frame's pairs)
  narrow::NodePair node;    ///< CD-tree node
  bool tested;              ///< already tested (and passed) in the weight-driven stage
  double weight;            ///< its estimated weight
  std::int32_t taboo = -1;  ///< a posteriori: the taboo list this traversal skips (original tasks)
  std::int32_t owner = -1;  ///< a posteriori: the taboo list this root is on (sub-tasks)
  std::int32_t slot = -1;   ///< a posteriori: its place on that list
  std::int32_t stage = -1;  ///< weight-driven stage: index of its record in SplitResult::stage
  /// Untested: how its parent's visit would test it (narrow::child_root_test), or as a root.
  narrow::RootTest test = narrow::RootTest::as_root;

  /// How its traversal tests it (narrow::RootTest), as its parent's visit would.
  [[nodiscard]] narrow::RootTest root_test() const { return tested ? narrow::RootTest::done : test; }
};

/// A run-time task's roots: up to three held in place (nearly every task has one to three, and a
/// step cuts hundreds of tasks, whose allocations were serial work of the calibration), more on
/// the heap.
class RootList {
 public:
  RootList() = default;
  RootList(std::initializer_list<Root> roots) {
    for (const Root& r : roots) push_back(r);
  }
  /// Room for n roots (the heap only when n is more than are held in place).
  void reserve(std::size_t n) {
    if (n > kInPlace) mSpill.reserve(n);
  }
  void push_back(const Root& r) {
    if (mSize < kInPlace) {
      mInPlace[mSize] = r;
    } else {
      if (mSize == kInPlace) mSpill.assign(mInPlace.begin(), mInPlace.end());
      mSpill.push_back(r);
    }
    ++mSize;
  }
  [[nodiscard]] const Root* begin() const { return mSize > kInPlace ? mSpill.data() : mInPlace.data(); }
  [[nodiscard]] const Root* end() const { return begin() + mSize; }
  [[nodiscard]] std::size_t size() const { return mSize; }
  [[nodiscard]] bool empty() const { return mSize == 0; }
  [[nodiscard]] const Root& operator[](std::size_t i) const { return begin()[i]; }

 private:
  static constexpr std::size_t kInPlace = 3;
  std::array<Root, kInPlace> mInPlace{};
  std::vector<Root> mSpill;  ///< all of them once there are more than kInPlace
  std::size_t mSize = 0;
};

/// A run-time task: one or more roots, traversed depth first by one thread.
struct RunTask {
  RootList roots;       ///< never empty
  double weight = 0.0;  ///< sum of the roots' weights
};

/// What calibration does with a pair or a node of the weight-driven stage.
enum class Verdict { keep, split, cart };

/// keep when weight is in [omega - eps, omega + eps], split above, cart below.
Verdict classify(double weight, double omega, double eps);

/// Omega = total / (beta * threads); at least a tiny positive value so that a zero total is harmless.
double caliber_threshold(double total, double beta, int threads);

/// Merges the cart: sorted by weight (ties by pair, then node), the heaviest item takes the lightest
/// ones until their sum reaches omega; repeats until the cart is empty. No task comes out empty.
/// The tasks come out in that order (the first holds the heaviest item); each task's roots are in
/// their order in `cart`.
std::vector<RunTask> merge_cart(std::vector<Root> cart, double omega);

/// One node the weight-driven stage visited (every one passed its node test): what happened to it,
/// so that its subtree's node tests can be added up after the step (the node-history variant of
/// hybrid reuses them).
struct StageRecord {
  narrow::NodePair node;                         ///< the CD-tree node
  std::uint8_t children = 0;                     ///< expanded: how many children its visit tested
  std::uint8_t passed = 0;                       ///< expanded: bit k set when child k passed (and has a record)
  narrow::NodePair child[narrow::kMaxChildren];  ///< expanded: the children tested
  bool root = false;                             ///< became a sub-task root or a cart item (tested)
};

/// Measured node tests of CD subtrees at the previous step, per CD node, sorted by node.
using NodeCounts = std::vector<std::pair<narrow::NodePair, std::uint64_t>>;

/// The weight-driven stage's output for one split pair.
struct SplitResult {
  std::vector<Root> roots;                    ///< sub-task roots whose weight meets omega
  std::vector<Root> cart;                     ///< lighter tested nodes, for the cart
  std::vector<narrow::Candidate> candidates;  ///< leaf pairs found in the stage
  QueryStats stats;                           ///< node and leaf tests made in the stage
  std::size_t queue_peak = 0;                 ///< widest level of the stage (nodes waiting at once)
  std::vector<StageRecord> stage;             ///< every node that passed, level by level (parents first)
  /// Each level's node tests, per chunk of nodes handed to a thread at once (the root's own test
  /// is not in them).
  std::vector<std::vector<std::uint64_t>> levels;
  /// Wall time of the stage outside its levels' parallel parts (adding up each level's chunk
  /// tallies in order, sizing the outputs, the final sort): serial within the split pair.
  double serial_ms = 0.0;
};

/// The weight-driven partial traversal of one pair's CD tree (the paper's alternate traversal):
/// every node reached is tested (a failed test prunes it; a leaf pair gets its leaf test here); if
/// its weight meets omega it becomes a sub-task root, if heavier its children are reached, if
/// lighter it goes to the cart. The root enters with `root_weight`; a node's weight is `scale`
/// times its a priori weight, or, when `measured` holds it, the node tests its subtree took at the
/// previous step. The paper pops nodes heaviest first from a priority queue; since what happens to
/// a node does not depend on when, this runs the same cut level by level, each level's nodes in
/// parallel on the current executor (one heavy pair's stage is no longer serial work), with the
/// same result whatever the thread count.
SplitResult split_pair(const narrow::PairContext& ctx, std::uint32_t pair, double root_weight, double scale, double omega,
                       double eps, const NodeCounts* measured = nullptr);

/// After a step: the node tests of every subtree the stage tested, from its records and the
/// depth-first node tests of its roots (`root_tests[k]` for the root at record k). Sorted by node.
NodeCounts subtree_counts(const std::vector<StageRecord>& stage, const std::vector<std::uint64_t>& root_tests);

/// The a posteriori summary tree of one pair: the CD-tree nodes above the triangle pairs reported at
/// the previous step, each weighted by how many of them lie below it. Children are contiguous.
struct SummaryNode {
  narrow::NodePair node;                              ///< the CD-tree node
  std::uint32_t contacts = 0;                         ///< reported triangle pairs below it
  std::uint32_t first = 0;                            ///< index of its first child in the summary
  std::uint32_t children = 0;                         ///< how many children (only those with contacts below)
  narrow::RootTest test = narrow::RootTest::as_root;  ///< how its parent's visit tests it (narrow::child_root_test)
};

/// Builds the summary tree of pair context ctx's CD tree from the previous step's reported triangle
/// pairs (empty if there were none).
std::vector<SummaryNode> build_summary(const narrow::PairContext& ctx, const std::vector<TrianglePair>& reported);

/// The a posteriori split of one heavy pair: sub-task roots chosen on its summary tree by weight
/// (a node's weight is the pair's weight times its share of the contacts), the original task keeping
/// the rest of the tree with those roots on its taboo list (at most `taboo_cap` of them).
struct PosterioriSplit {
  std::vector<Root> roots;              ///< sub-task roots meeting omega (untested)
  std::vector<Root> cart;               ///< lighter sub-task roots (untested)
  std::vector<narrow::NodePair> taboo;  ///< every chosen root, sorted
  double rest = 0.0;                    ///< estimated weight left to the original task
};
PosterioriSplit split_aposteriori(const std::vector<SummaryNode>& summary, std::uint32_t pair, double weight, double omega,
                                  double eps, std::size_t taboo_cap);

}  // namespace caliber::plans
