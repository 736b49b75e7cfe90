// The broad phase's tree: Morton order, refit, and the ordered pair search (broad/box_tree.h).

#include "broad/box_tree.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>

#include "parallel/executor.h"

namespace caliber::broad {
namespace {

/// The most objects in a leaf of the tree (2 and 8 did about as well on grids of boxes).
constexpr std::size_t kLeaf = 4;
/// Leaves per parallel chunk of the pair search (on a grid of parts, a short piece of work, yet
/// large beside the cost of handing it out).
constexpr std::size_t kChunk = 256;
/// Refitting over the old order is kept while the tree's boxes have grown by less than this
/// factor of their area right after the last sort.
constexpr double kResortGrowth = 1.25;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr FlatBox kEmpty{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};  ///< overlaps nothing

inline bool overlap(const FlatBox& x, const FlatBox& b) {
  return x.lo[0] <= b.hi[0] && b.lo[0] <= x.hi[0] && x.lo[1] <= b.hi[1] && b.lo[1] <= x.hi[1] && x.lo[2] <= b.hi[2] &&
         b.lo[2] <= x.hi[2];
}

inline FlatBox merge(const FlatBox& x, const FlatBox& y) {
  FlatBox m;
  for (int i = 0; i < 3; ++i) {
    m.lo[i] = std::min(x.lo[i], y.lo[i]);
    m.hi[i] = std::max(x.hi[i], y.hi[i]);
  }
  return m;
}

/// The 10 low bits of v spread to every third bit.
inline std::uint32_t spread(std::uint32_t v) {
  v = (v | (v << 16)) & 0x030000FFu;
  v = (v | (v << 8)) & 0x0300F00Fu;
  v = (v | (v << 4)) & 0x030C30C3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

}  // namespace

void BoxTree::sort_order(std::span<const WorldBox> boxes) {
  const std::size_t n = boxes.size();
  std::array<double, 3> lo{kInf, kInf, kInf};
  std::array<double, 3> hi{-kInf, -kInf, -kInf};
  for (const WorldBox& b : boxes) {
    for (int i = 0; i < 3; ++i) {
      const double c = 0.5 * (b.lo[i] + b.hi[i]);
      lo[i] = std::min(lo[i], c);
      hi[i] = std::max(hi[i], c);
    }
  }
  std::array<double, 3> scale{};
  for (int i = 0; i < 3; ++i) scale[i] = hi[i] > lo[i] ? 1023.0 / (hi[i] - lo[i]) : 0.0;
  mCodes.resize(n);
  parallel::parallel_for(0, n, 8192, [&](std::size_t first, std::size_t last) {
    for (std::size_t j = first; j != last; ++j) {
      std::uint32_t code = 0;
      for (int i = 0; i < 3; ++i) {
        const double c = (0.5 * (boxes[j].lo[i] + boxes[j].hi[i]) - lo[i]) * scale[i];
        code |= spread(static_cast<std::uint32_t>(std::clamp(c, 0.0, 1023.0))) << (2 - i);
      }
      mCodes[j] = code;
    }
  });
  // A stable radix sort of the previous order (or the objects' own) by code: 3 passes of 10 bits.
  if (mOrder.size() != n) {
    mOrder.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) mOrder[i] = i;
  }
  mScratch.resize(n);
  std::array<std::uint32_t, 1025> count{};
  for (int shift = 0; shift < 30; shift += 10) {
    count.fill(0);
    for (const std::uint32_t o : mOrder) ++count[((mCodes[o] >> shift) & 1023u) + 1];
    for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
    for (const std::uint32_t o : mOrder) mScratch[count[(mCodes[o] >> shift) & 1023u]++] = o;
    mOrder.swap(mScratch);
  }
}

void BoxTree::build_nodes(std::uint32_t first, std::uint32_t count) {
  const std::size_t index = mNodes.size();
  mNodes.push_back(Node{kEmpty, first, count, 0});
  if (count <= kLeaf) return;
  // Partition where the highest bit that differs between the run's first and last codes turns on (the
  // codes are sorted); a run of equal codes is halved.
  const auto code = [&](std::uint32_t p) { return mCodes[mOrder[p]]; };
  const std::uint32_t lo = code(first), hi = code(first + count - 1);
  std::uint32_t left = count / 2;
  if (lo != hi) {
    const std::uint32_t bit = std::uint32_t{1} << (31 - std::countl_zero(lo ^ hi));
    std::uint32_t a = first, b = first + count - 1;  // code(a) lacks the bit, code(b) has it
    while (b - a > 1) {
      const std::uint32_t m = a + (b - a) / 2;
      (code(m) & bit) != 0 ? b = m : a = m;
    }
    left = b - first;
  }
  build_nodes(first, left);
  mNodes[index].right = static_cast<std::uint32_t>(mNodes.size());
  build_nodes(first + left, count - left);
}

void BoxTree::refit() {
  // Preorder: every node's children come after it, so a backward pass meets them first.
  for (std::size_t k = mNodes.size(); k-- > 0;) {
    Node& node = mNodes[k];
    if (node.right == 0) {
      FlatBox b = mSorted[node.first];
      for (std::uint32_t i = 1; i < node.count; ++i) b = merge(b, mSorted[node.first + i]);
      node.box = b;
    } else {
      node.box = merge(mNodes[k + 1].box, mNodes[node.right].box);
    }
  }
}

double BoxTree::node_area() const {
  double area = 0.0;
  for (const Node& node : mNodes) {
    if (node.right == 0) continue;
    const FlatBox& b = node.box;
    const double x = b.hi[0] - b.lo[0];
    const double y = b.hi[1] - b.lo[1];
    const double z = b.hi[2] - b.lo[2];
    area += x * y + y * z + z * x;
  }
  return area;
}

void BoxTree::pairs(std::span<const WorldBox> boxes, const PairFilter& filter, std::vector<ObjectPair>& out) {
  out.clear();
  const std::size_t n = boxes.size();
  if (n < 2) {
    mOrder.clear();
    return;
  }
  mSorted.resize(n);
  const auto fill = [&] {
    parallel::parallel_for(0, n, 8192, [&](std::size_t first, std::size_t last) {
      for (std::size_t p = first; p != last; ++p) {
        const WorldBox& b = boxes[mOrder[p]];
        mSorted[p] = FlatBox{{b.lo.x(), b.lo.y(), b.lo.z()}, {b.hi.x(), b.hi.y(), b.hi.z()}};
      }
    });
    refit();
  };
  const auto rebuild = [&] {
    sort_order(boxes);
    mNodes.clear();
    build_nodes(0, static_cast<std::uint32_t>(n));
    mLeaves.clear();
    for (std::uint32_t k = 0; k < mNodes.size(); ++k) {
      if (mNodes[k].right == 0) mLeaves.push_back(k);  // preorder: in the order of their positions
    }
    fill();
    mSortedArea = node_area();
  };
  if (mOrder.size() != n) {
    rebuild();
  } else {
    fill();
    if (node_area() > kResortGrowth * mSortedArea) rebuild();
  }
  collect(filter, n, out);
}

void BoxTree::collect(const PairFilter& filter, std::size_t n, std::vector<ObjectPair>& out) {
  const std::size_t chunks = (mLeaves.size() + kChunk - 1) / kChunk;
  if (mFound.size() < chunks) mFound.resize(chunks);
  const auto keep = [&](std::uint32_t a, std::uint32_t b) {
    if (filter.fixed != nullptr && (*filter.fixed)[a] && (*filter.fixed)[b]) return false;
    return filter.ignored == nullptr ||
           !std::binary_search(filter.ignored->begin(), filter.ignored->end(), std::uint64_t{a} << 32 | b);
  };
  // The boxes of one leaf are queried together: one walk of the tree with the leaf's box (the union
  // of its boxes), and each box tested at the leaves the walk reaches. Each pair (p < q) is met
  // once: from p's leaf, at q's.
  parallel::parallel_for(0, chunks, 1, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c != c1; ++c) {
      std::vector<std::uint64_t>& found = mFound[c];
      found.clear();
      for (std::size_t l = c * kChunk; l != std::min(mLeaves.size(), (c + 1) * kChunk); ++l) {
        const Node& leaf = mNodes[mLeaves[l]];
        const std::size_t first = leaf.first, end = leaf.first + leaf.count;
        // Only the nodes that hold positions after the leaf's first.
        std::array<std::uint32_t, 128> stack;  // depth <= 30 code bits + 32 halvings
        std::size_t top = 0;
        stack[top++] = 0;
        while (top != 0) {
          const Node& node = mNodes[stack[--top]];
          if (node.first + node.count <= first + 1 || !overlap(node.box, leaf.box)) continue;
          if (node.right != 0) {
            stack[top++] = node.right;
            stack[top++] = static_cast<std::uint32_t>(&node - mNodes.data()) + 1;
            continue;
          }
          for (std::size_t q = std::max(node.first, leaf.first + 1); q != node.first + node.count; ++q) {
            const FlatBox& b = mSorted[q];
            for (std::size_t p = first; p != std::min(end, q); ++p) {
              if (!overlap(mSorted[p], b)) continue;
              const std::uint32_t a = std::min(mOrder[p], mOrder[q]);
              const std::uint32_t z = std::max(mOrder[p], mOrder[q]);
              if (keep(a, z)) found.push_back(std::uint64_t{a} << 32 | z);
            }
          }
        }
      }
    }
  });
  // A counting sort by the first object, then each object's few partners sorted.
  mStart.assign(n + 1, 0);
  std::size_t total = 0;
  for (std::size_t c = 0; c != chunks; ++c) {
    total += mFound[c].size();
    for (const std::uint64_t v : mFound[c]) ++mStart[(v >> 32) + 1];
  }
  for (std::size_t a = 1; a <= n; ++a) mStart[a] += mStart[a - 1];
  out.resize(total);
  for (std::size_t c = 0; c != chunks; ++c) {
    for (const std::uint64_t v : mFound[c]) {
      out[mStart[v >> 32]++] = ObjectPair{static_cast<std::uint32_t>(v >> 32), static_cast<std::uint32_t>(v)};
    }
  }
  // mStart[a] is now the end of a's run (and the start of a + 1's).
  parallel::parallel_for(0, n, 4096, [&](std::size_t first, std::size_t last) {
    for (std::size_t a = first; a != last; ++a) {
      std::sort(out.begin() + static_cast<std::ptrdiff_t>(a == 0 ? 0 : mStart[a - 1]),
                out.begin() + static_cast<std::ptrdiff_t>(mStart[a]));
    }
  });
}

}  // namespace caliber::broad
