#include "plans/calibration.h"

#include <algorithm>
#include <functional>
#include <map>
#include <queue>

#include "bvh/model_data.h"
#include "parallel/executor.h"
#include "util/assert.h"
#include "util/timing.h"

#include "plans/weights.h"

namespace caliber::plans {

Verdict classify(double weight, double omega, double eps) {
  if (weight > omega + eps) return Verdict::split;
  if (weight < omega - eps) return Verdict::cart;
  return Verdict::keep;
}

double caliber_threshold(double total, double beta, int threads) {
  const double omega = total / (beta * static_cast<double>(threads));
  return omega > 0.0 ? omega : 1e-300;
}

namespace {

/// Nodes of one level of the stage handed to a thread at a time: a visit is up to eight node tests,
/// so a chunk is a short piece of work, and a level of a hundred nodes spreads over a dozen
/// threads. Fixed chunks (not the partitioner's), so that the load-balance simulation replays the
/// very pieces that ran.
constexpr std::size_t kStageGrain = 8;

/// A node waiting in the stage, with its weight.
struct StageItem {
  double weight;
  narrow::NodePair node;
};

/// What the stage found at one node of a level (filled in parallel, read in the level's order).
/// Every node of a level has passed its node test (made by its parent's visit, or the root's).
struct StageOutcome {
  enum class Kind : std::uint8_t { leaf, split, root } kind = Kind::root;
  bool reported = false;                       ///< leaf: the leaf test kept the pair
  bool keep = false;                           ///< root: kept as a sub-task root (else it goes to the cart)
  std::uint8_t children = 0;                   ///< split: how many children passed their test
  std::uint8_t tested = 0;                     ///< split: how many children were tested
  StageItem child[narrow::kMaxChildren];       ///< split: the children that passed, and their weights
  narrow::NodePair all[narrow::kMaxChildren];  ///< split: every child tested (cd_children order)
  QueryStats stats;                            ///< the visit's node and leaf tests
  narrow::Candidate candidate;                 ///< leaf, reported: the pair
};

/// What one chunk of a level produced: its tests, and how many of each output it adds (so that
/// every chunk knows where its outputs go once the chunks before it are counted).
struct ChunkTally {
  QueryStats stats;
  std::size_t children = 0, candidates = 0, roots = 0, cart = 0;
};

/// Visits every node of one level, a chunk of kStageGrain nodes per thread at a time: a pair of
/// leaves gets its leaf test, a heavy node is split (its children tested, those that pass
/// weighed), any other becomes a root or a cart item by its weight. Each node's outcome goes to its
/// slot, its record to out.stage[base + i] (out.stage already sized), each chunk's counts to its
/// tally.
void visit_level(const narrow::PairContext& ctx, const std::vector<StageItem>& level, double omega, double eps,
                 const std::function<double(narrow::NodePair)>& weight_of, std::size_t base, std::vector<StageOutcome>& outcome,
                 std::vector<ChunkTally>& tally, SplitResult& out) {
  outcome.assign(level.size(), StageOutcome{});
  const std::size_t chunks = (level.size() + kStageGrain - 1) / kStageGrain;
  tally.assign(chunks, ChunkTally{});
  parallel::parallel_for(0, chunks, 1, [&](std::size_t first, std::size_t last) {
    std::vector<narrow::Candidate> found;
    for (std::size_t i = first * kStageGrain; i != std::min(last * kStageGrain, level.size()); ++i) {
      const StageItem& e = level[i];
      StageOutcome& o = outcome[i];
      StageRecord& record = out.stage[base + i];
      ChunkTally& t = tally[i / kStageGrain];
      record = StageRecord{};
      record.node = e.node;
      const bool leaves = ctx.a().nodes[e.node.a].is_leaf() && ctx.b().nodes[e.node.b].is_leaf();
      const Verdict verdict = classify(e.weight, omega, eps);
      if (!leaves && verdict != Verdict::split) {
        o.kind = StageOutcome::Kind::root;
        o.keep = verdict == Verdict::keep;
        record.root = true;
        ++(o.keep ? t.roots : t.cart);
        continue;
      }
      found.clear();
      narrow::NodePair passed[narrow::kMaxChildren];
      const int count = narrow::visit(ctx, e.node, found, o.stats, passed);
      t.stats.node_tests += o.stats.node_tests;
      t.stats.leaf_tests += o.stats.leaf_tests;
      if (count < 0) {
        o.kind = StageOutcome::Kind::leaf;
        o.reported = !found.empty();
        if (o.reported) o.candidate = found.front();
        t.candidates += o.reported ? 1 : 0;
        continue;
      }
      o.kind = StageOutcome::Kind::split;
      o.tested = static_cast<std::uint8_t>(narrow::cd_children(ctx, e.node, o.all));
      CALIBER_ASSERT(o.stats.node_tests == o.tested, "a visit tests each child once");
      o.children = static_cast<std::uint8_t>(count);
      t.children += static_cast<std::size_t>(count);
      for (int k = 0; k < count; ++k) o.child[k] = StageItem{weight_of(passed[k]), passed[k]};
      record.children = o.tested;
      for (int k = 0, p = 0; k < o.tested; ++k) {
        record.child[k] = o.all[k];
        if (p < o.children && o.child[p].node == o.all[k]) {
          record.passed |= static_cast<std::uint8_t>(1u << k);
          ++p;
        }
      }
    }
  });
}

/// Takes one level's outcomes in the level's order (so the cut does not depend on the thread
/// count): the counts, candidates, roots and cart items, and the next level. Only the chunks'
/// tallies are added up in order here; each chunk then writes its outputs at its offsets in
/// parallel (timed into `parallel_ms`), so the serial part is per chunk, not per node.
std::vector<StageItem> gather_level(const std::vector<StageItem>& level, const std::vector<StageOutcome>& outcome,
                                    const std::vector<ChunkTally>& tally, std::uint32_t pair, std::size_t base, SplitResult& out,
                                    double& parallel_ms) {
  const std::size_t chunks = tally.size();
  std::vector<std::uint64_t>& tests = out.levels.emplace_back(chunks, 0);
  std::vector<ChunkTally> at(chunks);  // where each chunk's outputs start
  ChunkTally total{{}, 0, out.candidates.size(), out.roots.size(), out.cart.size()};
  for (std::size_t c = 0; c < chunks; ++c) {
    at[c] = total;
    tests[c] = tally[c].stats.node_tests;
    total.stats.node_tests += tally[c].stats.node_tests;
    total.stats.leaf_tests += tally[c].stats.leaf_tests;
    total.children += tally[c].children;
    total.candidates += tally[c].candidates;
    total.roots += tally[c].roots;
    total.cart += tally[c].cart;
  }
  out.stats.node_tests += total.stats.node_tests;
  out.stats.leaf_tests += total.stats.leaf_tests;
  std::vector<StageItem> next(total.children);
  out.candidates.resize(total.candidates);
  out.roots.resize(total.roots);
  out.cart.resize(total.cart);
  const auto writing = util::Clock::now();
  parallel::parallel_for(0, chunks, 1, [&](std::size_t first, std::size_t last) {
    for (std::size_t c = first; c != last; ++c) {
      ChunkTally w = at[c];
      for (std::size_t i = c * kStageGrain; i != std::min((c + 1) * kStageGrain, level.size()); ++i) {
        const StageOutcome& o = outcome[i];
        switch (o.kind) {
          case StageOutcome::Kind::leaf:
            if (o.reported) out.candidates[w.candidates++] = o.candidate;
            break;
          case StageOutcome::Kind::split:
            for (int k = 0; k < o.children; ++k) next[w.children++] = o.child[k];
            break;
          case StageOutcome::Kind::root: {
            Root r{pair, level[i].node, true, level[i].weight};
            r.stage = static_cast<std::int32_t>(base + i);
            (o.keep ? out.roots[w.roots++] : out.cart[w.cart++]) = r;
            break;
          }
        }
      }
    }
  });
  parallel_ms += util::ms_since(writing);
  return next;
}

}  // namespace

SplitResult split_pair(const narrow::PairContext& ctx, std::uint32_t pair, double root_weight, double scale, double omega,
                       double eps, const NodeCounts* measured) {
  const auto weight_of = [&](narrow::NodePair n) {
    if (measured != nullptr) {
      const auto it = std::lower_bound(measured->begin(), measured->end(), n,
                                       [](const auto& entry, narrow::NodePair key) { return entry.first < key; });
      if (it != measured->end() && it->first == n) return static_cast<double>(it->second);
    }
    return scale * apriori_weight(ctx, n);
  };
  // The paper pops the heaviest node of a priority queue until none is left. What happens to a node
  // (pruned, leaf-tested, split into its children, or made a root or a cart item by its weight)
  // depends on the node alone, never on when it is popped, so the stage is the same cut when run
  // level by level: every node of a level visited in parallel (narrow::visit, which tests its
  // children), the children that pass the next level.
  const auto started = util::Clock::now();
  double parallel_ms = 0.0;  // the levels' parallel parts: the visits, the outputs' writing
  SplitResult out;
  std::vector<StageItem> level;
  if (narrow::test_root(ctx, narrow::NodePair{0, 0}, out.stats)) level.push_back(StageItem{root_weight, narrow::NodePair{0, 0}});
  std::vector<StageOutcome> outcome;
  std::vector<ChunkTally> tally;
  while (!level.empty()) {
    out.queue_peak = std::max(out.queue_peak, level.size());
    const std::size_t base = out.stage.size();
    out.stage.resize(base + level.size());
    const auto visiting = util::Clock::now();
    visit_level(ctx, level, omega, eps, weight_of, base, outcome, tally, out);
    parallel_ms += util::ms_since(visiting);
    level = gather_level(level, outcome, tally, pair, base, out, parallel_ms);
  }
  // The priority queue popped every root after the last split node (from then on nothing heavier
  // is pushed), so in order of weight, heaviest first, ties by node: the same order here, so that
  // the run-time task list is the one the queue made, ties included.
  const auto popped_before = [](const Root& x, const Root& y) {
    if (x.weight != y.weight) return x.weight > y.weight;
    if (x.node.a != y.node.a) return x.node.a < y.node.a;
    return x.node.b < y.node.b;
  };
  std::sort(out.roots.begin(), out.roots.end(), popped_before);
  // (The cart is left in level order: merge_cart sorts every cart item by a total order.)
  out.serial_ms = std::max(0.0, util::ms_since(started) - parallel_ms);
  return out;
}

NodeCounts subtree_counts(const std::vector<StageRecord>& stage, const std::vector<std::uint64_t>& root_tests) {
  // Children are recorded after their parent: add up in reverse record order.
  std::vector<std::pair<narrow::NodePair, std::uint64_t>> counts;
  std::map<narrow::NodePair, std::uint64_t> known;
  for (std::size_t k = stage.size(); k-- > 0;) {
    const StageRecord& r = stage[k];
    std::uint64_t total = 1;  // its own test
    if (r.root) total += root_tests[k];
    for (int c = 0; c < r.children; ++c) {
      if ((r.passed >> c & 1u) == 0) {
        known[r.child[c]] = 1;  // tested by this visit, failed: its subtree is its one test
        ++total;
        continue;
      }
      const auto it = known.find(r.child[c]);
      CALIBER_ASSERT(it != known.end(), "a child that passed has its record after its parent's");
      total += it->second;
    }
    known[r.node] = total;
  }
  counts.assign(known.begin(), known.end());
  return counts;
}

namespace {

/// Fills summary[slot] for CD node n (tested as `test` says) with the reported pairs in [first,
/// last) below it, then its children. The pairs are partitioned in place (each goes to the first
/// child that holds both triangles, as a traversal would meet it), so the tree costs no allocation
/// per node.
void fill_summary(const narrow::PairContext& ctx, std::uint32_t slot, narrow::NodePair n, narrow::RootTest test,
                  TrianglePair* first, TrianglePair* last, std::vector<SummaryNode>& summary) {
  const ModelData& a = ctx.a();
  const ModelData& b = ctx.b();
  summary[slot].node = n;
  summary[slot].test = test;
  summary[slot].contacts = static_cast<std::uint32_t>(last - first);
  if (a.nodes[n.a].is_leaf() && b.nodes[n.b].is_leaf()) return;
  narrow::NodePair kids[narrow::kMaxChildren];
  const int count = narrow::cd_children(ctx, n, kids);
  TrianglePair* bounds[narrow::kMaxChildren + 1] = {first};
  for (int k = 0; k < count; ++k) {
    const narrow::NodePair leaves{a.first_leaf(kids[k].a), b.first_leaf(kids[k].b)};
    bounds[k + 1] = std::partition(bounds[k], last, [&](const TrianglePair& p) {
      return a.holds(kids[k].a, leaves.a, p.tri_a) && b.holds(kids[k].b, leaves.b, p.tri_b);
    });
  }
  const auto at = static_cast<std::uint32_t>(summary.size());
  std::uint32_t children = 0;
  for (int k = 0; k < count; ++k) children += bounds[k + 1] != bounds[k] ? 1 : 0;
  summary[slot].first = at;
  summary[slot].children = children;
  summary.resize(summary.size() + children);
  std::uint32_t next = at;
  for (int k = 0; k < count; ++k) {
    if (bounds[k + 1] != bounds[k]) {
      fill_summary(ctx, next++, kids[k], narrow::child_root_test(ctx, n, kids[k]), bounds[k], bounds[k + 1], summary);
    }
  }
}

}  // namespace

std::vector<SummaryNode> build_summary(const narrow::PairContext& ctx, const std::vector<TrianglePair>& reported) {
  std::vector<SummaryNode> summary;
  // The pairs reported last step, by triangle ids of last step's models: a frame may have given the
  // pair other models since (without Engine::forget), so ids past these models' triangles are left
  // out. The summary only weighs the split; no answer depends on it.
  std::vector<TrianglePair> items;
  items.reserve(reported.size());
  const std::size_t triangles_a = ctx.a().leaf_position.size(), triangles_b = ctx.b().leaf_position.size();
  for (const TrianglePair& p : reported) {
    if (p.tri_a < triangles_a && p.tri_b < triangles_b) items.push_back(p);
  }
  if (items.empty()) return summary;
  summary.reserve(2 * items.size() + 1);
  summary.resize(1);
  fill_summary(ctx, 0, narrow::NodePair{0, 0}, narrow::RootTest::as_root, items.data(), items.data() + items.size(), summary);
  return summary;
}

PosterioriSplit split_aposteriori(const std::vector<SummaryNode>& summary, std::uint32_t pair, double weight, double omega,
                                  double eps, std::size_t taboo_cap) {
  PosterioriSplit out;
  out.rest = weight;
  if (summary.empty() || summary[0].contacts == 0 || summary[0].children == 0) return out;
  const double per_contact = weight / summary[0].contacts;
  struct Entry {
    double weight;
    std::uint32_t index;
    bool operator<(const Entry& o) const { return weight != o.weight ? weight < o.weight : index > o.index; }
  };
  std::priority_queue<Entry> queue;
  // The root itself is the original task: start from its children.
  for (std::uint32_t c = 0; c < summary[0].children; ++c) {
    const std::uint32_t k = summary[0].first + c;
    queue.push(Entry{per_contact * summary[k].contacts, k});
  }
  while (!queue.empty() && out.taboo.size() < taboo_cap) {
    const Entry e = queue.top();
    queue.pop();
    const SummaryNode& s = summary[e.index];
    const Verdict v = classify(e.weight, omega, eps);
    if (v == Verdict::split && s.children > 0) {
      for (std::uint32_t c = 0; c < s.children; ++c) queue.push(Entry{per_contact * summary[s.first + c].contacts, s.first + c});
      continue;
    }
    Root r{pair, s.node, false, e.weight};
    r.test = s.test;
    (v == Verdict::cart ? out.cart : out.roots).push_back(r);
    out.taboo.push_back(s.node);
    out.rest -= e.weight;
  }
  std::sort(out.taboo.begin(), out.taboo.end());
  out.rest = std::max(out.rest, 1.0);
  return out;
}

}  // namespace caliber::plans
