#pragma once
/// \file
/// Task calibration (DESIGN.md section 3): from the step's initial tasks and their weights, a
/// run-time task list whose tasks all have about the same weight, the caliber Omega.
///   Omega = sum of weights / (beta * threads); a task within [Omega - eps, Omega + eps] runs as is,
///   a heavier one is split by the weight-driven stage, a lighter one goes to the cart; the cart is
///   sorted and its heaviest item is merged with the lightest ones until the merge reaches Omega.

#include <cstdint>
#include <vector>

#include "caliber/query.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"

namespace caliber::tasks {

/// A piece of work for one thread: a CD-tree node of one pair, and whether the weight-driven stage
/// already tested it (then the depth-first traversal starts below it, so no node is tested twice).
struct Root {
  std::uint32_t pair;      ///< index of the initial task (object pair)
  narrow::NodePair node;   ///< CD-tree node
  bool tested;             ///< already tested (and passed) in the weight-driven stage
  double weight;           ///< its estimated weight
};

/// A run-time task: one or more roots, traversed depth first by one thread.
struct RunTask {
  std::vector<Root> roots;  ///< never empty
  double weight = 0.0;      ///< sum of the roots' weights
};

/// What calibration does with an initial task or a node of the weight-driven stage.
enum class Verdict { keep, split, cart };

/// keep when weight is in [omega - eps, omega + eps], split above, cart below.
Verdict classify(double weight, double omega, double eps);

/// Omega = total / (beta * threads); at least a tiny positive value so that a zero total is harmless.
double caliber_threshold(double total, double beta, int threads);

/// Merges the cart: sorted by weight (ties by pair, then node), the heaviest item takes the lightest
/// ones until their sum reaches omega; repeats until the cart is empty. No task comes out empty.
std::vector<RunTask> merge_cart(std::vector<Root> cart, double omega);

/// The weight-driven stage's output for one split task.
struct SplitResult {
  std::vector<Root> roots;                    ///< sub-task roots whose weight meets omega
  std::vector<Root> cart;                     ///< lighter tested nodes, for the cart
  std::vector<narrow::Candidate> candidates;  ///< leaf pairs found in the stage
  QueryStats stats;                           ///< node and leaf tests made in the stage
  std::size_t queue_peak = 0;                 ///< longest the priority queue grew
};

/// The weight-driven partial traversal of one pair's CD tree (the paper's alternate traversal):
/// a priority queue of untested nodes keyed by weight; pop the heaviest, test it (a failed test
/// prunes it; a leaf pair gets its leaf test here); if its weight meets omega it becomes a sub-task
/// root, if heavier its children are pushed, if lighter it goes to the cart. The root enters with
/// `root_weight`; a node's weight is `scale` times its a priori weight.
SplitResult split_task(const narrow::PairContext& ctx, std::uint32_t pair, double root_weight, double scale,
                       double omega, double eps);

}  // namespace caliber::tasks
