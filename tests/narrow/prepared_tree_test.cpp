// The distance traversal's store of prepared nodes: each node prepared once per traversal (its
// children made by the first visit that descends into it, found again by every later one), entries that
// stay put while others are added, and nothing left over after clear().

#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "narrow/traversal.h"

namespace caliber::narrow {
namespace {

struct Entry {
  std::uint32_t index;
  double value;
};
using Tree = PreparedTree<Entry>;

TEST(PreparedTree, EachNodePreparedOnceAndFoundAgain) {
  Tree tree;
  // A complete binary tree over heap indices (node i's children 2i + 1 and 2i + 2), walked down
  // random paths many times: far more entries than one chunk holds.
  constexpr std::uint32_t kDepth = 14;
  std::vector<int> made(std::size_t{1} << (kDepth + 1), 0);
  const auto prepare = [&](std::uint32_t i, Entry& out) {
    ++made[i];
    out = Entry{i, 0.5 * i};
  };
  std::mt19937 rng(9);
  for (int round = 0; round < 2; ++round) {
    tree.clear();
    std::fill(made.begin(), made.end(), 0);
    Tree::Node* root = tree.root(0, prepare);
    std::vector<std::pair<Tree::Node*, Tree::Node*>> seen;  // (parent, its kids) as first made
    for (int walk = 0; walk < 3000; ++walk) {
      Tree::Node* node = root;
      for (std::uint32_t depth = 0; depth < kDepth; ++depth) {
        const std::uint32_t first = 2 * node->index + 1;
        Tree::Node* kids = tree.kids(*node, first, prepare);
        ASSERT_EQ(kids[0].index, first);
        ASSERT_EQ(kids[1].index, first + 1);
        ASSERT_EQ(kids[1].value, 0.5 * (first + 1));
        seen.emplace_back(node, kids);
        node = &kids[rng() % 2];
      }
    }
    for (const auto& [parent, kids] : seen) {
      EXPECT_EQ(tree.kids(*parent, 2 * parent->index + 1, prepare), kids) << "an entry stays where it was made";
    }
    for (std::size_t i = 0; i < made.size(); ++i) ASSERT_LE(made[i], 1) << "node " << i << " prepared once";
    EXPECT_EQ(made[0], 1);
  }
}

TEST(PreparedTree, ClearForgetsEveryEntry) {
  Tree tree;
  int made = 0;
  const auto prepare = [&](std::uint32_t i, Entry& out) {
    ++made;
    out = Entry{i, double(made)};
  };
  Tree::Node* root = tree.root(7, prepare);
  EXPECT_EQ(tree.kids(*root, 20, prepare)[1].value, 3.0);
  EXPECT_EQ(tree.kids(*root, 20, prepare)[1].value, 3.0);
  tree.clear();
  root = tree.root(7, prepare);
  EXPECT_EQ(root->value, 4.0) << "made again after clear: a prepared node belongs to one pose";
  EXPECT_EQ(tree.kids(*root, 20, prepare)[0].value, 5.0);
  EXPECT_EQ(made, 6);
}

}  // namespace
}  // namespace caliber::narrow
