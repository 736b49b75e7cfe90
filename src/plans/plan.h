#pragma once
/// \file
/// Methods as plans: each method is a function from the step's pairs (and what the engine remembers
/// of them) to the run-time tasks, in the order they are handed out. One runner
/// (schedule/runner.h) executes any plan; plans need no threads to be tested (the weight-driven
/// stage uses the executor it is called in, with the same result on any number of threads).

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "caliber/engine.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"
#include "plans/calibration.h"

namespace caliber::plans {

/// A value per object pair, sorted by pair: what one step leaves for the next (its size follows the
/// step's pairs, not the run's).
template <class T>
class PairTable {
 public:
  /// The value of pair p, or null.
  [[nodiscard]] const T* find(const ObjectPair& p) const {
    const auto it = std::lower_bound(mKeys.begin(), mKeys.end(), p);
    return it == mKeys.end() || *it != p ? nullptr : &mValues[static_cast<std::size_t>(it - mKeys.begin())];
  }
  /// The values of `pairs` (in non-decreasing order), null where absent: one merge of the two sorted
  /// lists, not a search per pair.
  [[nodiscard]] std::vector<const T*> find_sorted(const std::vector<ObjectPair>& pairs) const {
    std::vector<const T*> out(pairs.size(), nullptr);
    std::size_t k = 0;
    for (std::size_t i = 0; i < pairs.size() && k < mKeys.size(); ++i) {
      while (k < mKeys.size() && mKeys[k] < pairs[i]) ++k;
      if (k < mKeys.size() && mKeys[k] == pairs[i]) out[i] = &mValues[k];
    }
    return out;
  }
  /// The value of pair p, inserted (value-initialized) if absent; at once when p comes after every
  /// pair held.
  T& operator[](const ObjectPair& p) {
    auto it = mKeys.empty() || mKeys.back() < p ? mKeys.end() : std::lower_bound(mKeys.begin(), mKeys.end(), p);
    const auto at = static_cast<std::size_t>(it - mKeys.begin());
    if (it == mKeys.end() || *it != p) {
      mKeys.insert(it, p);
      mValues.insert(mValues.begin() + static_cast<std::ptrdiff_t>(at), T{});
    }
    return mValues[at];
  }
  /// Keys `pairs` (sorted, each once), their values left for the caller to set (value(i) is
  /// pairs[i]'s; values keep their storage from the last call).
  void reset(const std::vector<ObjectPair>& pairs) {
    mKeys = pairs;
    mValues.resize(pairs.size());
  }
  [[nodiscard]] T& value(std::size_t i) { return mValues[i]; }
  void clear() {
    mKeys.clear();
    mValues.clear();
  }

 private:
  std::vector<ObjectPair> mKeys;
  std::vector<T> mValues;
};

/// What the engine remembers of each object pair of the last step (keyed by the pair's object
/// indices, Frame::pairs). Changes only how work is cut, never the contacts.
struct History {
  PairTable<std::uint64_t> node_tests;            ///< hybrid, a posteriori and stealing: its node tests
  PairTable<std::vector<TrianglePair>> reported;  ///< a posteriori: the triangle pairs it reported
  PairTable<NodeCounts> node_counts;              ///< hybrid with node history: stage subtrees' node tests
};

/// A method's plan for one step.
struct Plan {
  std::vector<RunTask> run;                ///< run-time tasks, in hand-out order
  std::vector<SplitResult> splits;         ///< the weight-driven stage of each split pair
  std::vector<std::uint32_t> split_pairs;  ///< the pair of each entry of `splits`
  std::vector<narrow::Taboo> taboos;       ///< a posteriori taboo lists (Root::taboo and Root::owner index them)
  bool weighted = false;                   ///< the tasks carry weight estimates (calibrated methods)
  double omega = 0.0;                      ///< the caliber (0 for a plan of whole pairs)
  std::size_t kept = 0;                    ///< pairs run as they are
  std::size_t split = 0;                   ///< pairs split
  std::size_t carted = 0;                  ///< items merged in the cart
  std::size_t taboo_nodes = 0;             ///< a posteriori: sub-task roots handed out
};

/// Sequential and exploitation: one run-time task per pair, whole, in pair order.
[[nodiscard]] Plan plan_pairs(std::size_t pairs);

/// The weights of the pairs (docs/design.md section 3): the root's a priori estimate times a
/// per-pair scale. A priori: scale 1. Hybrid and a posteriori: a pair with history weighs its node
/// tests at the previous step (its scale: those over its estimate); a pair with none takes the ratio
/// measured over the pairs that have one (over an evenly spaced sample of kRatioSample of them when
/// more have one; 1 if none has). The roots of pairs with history outside the sample are not
/// estimated: their scale is left 0, for scale_of.
struct InitialWeights {
  std::vector<double> weight;  ///< per pair
  std::vector<double> scale;   ///< per pair: what node weights are multiplied by (0: not estimated, see scale_of)
  double total = 0.0;
};
inline constexpr std::size_t kRatioSample = 4096;
/// What a pair costs beside its node tests (starting its traversal, its finalization), in node
/// tests: added to every pair's weight. Set on a scene of thousands of light pairs
/// (grid_32768, hybrid): in a merged task of whole pairs, the time a pair took beside its node
/// tests, over the time one of its node tests took.
inline constexpr double kPairWeight = 4.0;
/// The cart is merged to Omega / k, k = cart items / kCartItemsPerTask, between 1 and kCartFiner:
/// the paper's Omega for carts of up to a thousand items (the paper's scenes), up to 16 times
/// finer tasks for a cart of many thousands of light pairs.
inline constexpr std::size_t kCartItemsPerTask = 512;
inline constexpr std::size_t kCartFiner = 16;
[[nodiscard]] InitialWeights initial_weights(Method method, const std::vector<ObjectPair>& pairs, narrow::PairContexts contexts,
                                             const History& history);
/// Pair i's scale, its root estimated now if it was not (a pair with history that is split).
[[nodiscard]] double scale_of(const InitialWeights& w, narrow::PairContexts contexts, std::size_t i);

/// The calibrated methods (aposteriori, apriori, hybrid): weights, Omega = total / (beta * threads),
/// keep, split (the weight-driven stage, or the a posteriori summary tree and taboo lists) or cart
/// each pair, merge the cart, and hand the run-time tasks out heaviest first. A pair to split
/// whose distance query the first hit answers (narrow::answered_by_first_hit, run here on the
/// calling thread: the meshes intersect) is kept whole instead. `around_stage`,
/// if set, is called with each split pair's index and its weight-driven stage, and must run it
/// (the engine times it).
using StageWrapper = std::function<void(std::size_t, const std::function<void()>&)>;
[[nodiscard]] Plan plan_calibrated(const EngineOptions& options, const std::vector<ObjectPair>& pairs,
                                   narrow::PairContexts contexts, const History& history, const StageWrapper& around_stage = {});

}  // namespace caliber::plans
