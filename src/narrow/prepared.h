#pragma once
/// \file
/// Nodes prepared for one object pair's tests (PairContext): what the node test and the distance
/// bound read of a node, computed once per node and traversal (B's brought into A's frame), and
/// PreparedNodes, the distance traversal's store of them.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace caliber::narrow {

/// What every prepared node of A holds: its sphere, its box, and that box seen from B's frame
/// (center, and extent along each of B's axes).
struct NodeA {
  std::uint32_t index;   ///< node index in A
  double center[3];      ///< sphere center (A's frame)
  double radius;         ///< sphere radius
  double box[3];         ///< box center (A's frame)
  double half[3];        ///< box half-extents (A's axes)
  double box_in_b[3];    ///< box center in B's frame
  double reach_on_b[3];  ///< half-extent of A's box along each of B's axes
};
/// What every prepared node of B holds, the same brought into A's frame.
struct NodeB {
  std::uint32_t index;   ///< node index in B
  double center[3];      ///< sphere center in A's frame
  double radius;         ///< sphere radius
  double box[3];         ///< box center (B's own frame)
  double half[3];        ///< box half-extents (B's axes)
  double box_in_a[3];    ///< box center in A's frame
  double reach_on_a[3];  ///< half-extent of B's box along each of A's axes
};
/// A box around a node's triangles, for the distance bound: its axes (orthonormal up to
/// rounding), center and half-extents along them. The box in the frame of the node's slab (the
/// slab and the lateral ranges) where the node has one, else its own box.
struct Frame {
  double axis[3][3];
  double center[3];
  double half[3];
};
/// A node of A prepared for the distance bound: NodeA and its Frame.
struct NearA : NodeA {
  Frame frame;
};
/// A node of B prepared for the distance bound: NodeB and its Frame brought into A's frame.
struct NearB : NodeB {
  Frame frame;
};

/// The nodes one traversal has prepared, by node index, so that each is prepared once however many
/// partners it meets (the distance traversal meets a node 7-10 times on the bunny): an open-
/// addressing table of indices over a store whose entries never move (so a reference to one
/// stays valid while others are added). Cleared per traversal: a prepared node depends on the
/// pair's relative pose.
template <class Prepared>
class PreparedNodes {
 public:
  /// Forgets every entry (keeps the memory).
  void clear() {
    std::fill(mKeys.begin(), mKeys.end(), kEmpty);
    mCount = 0;
  }
  /// Bytes held (the table and the store), for a caller that keeps the scratch between calls.
  [[nodiscard]] std::size_t footprint() const {
    return mKeys.size() * 2 * sizeof(std::uint32_t) + mChunks.size() * kChunk * sizeof(Prepared);
  }
  /// The entry of node `index`, made by prepare(index) the first time it is asked for.
  template <class Prepare>
  const Prepared& get(std::uint32_t index, Prepare&& prepare) {
    if (2 * (mCount + 1) > mKeys.size()) grow();
    const std::size_t mask = mKeys.size() - 1;
    for (std::size_t h = (index * std::size_t{0x9E3779B1u}) & mask;; h = (h + 1) & mask) {
      if (mKeys[h] == index) return at(mSlots[h]);
      if (mKeys[h] == kEmpty) {
        mKeys[h] = index;
        mSlots[h] = mCount;
        if (mCount / kChunk == mChunks.size()) mChunks.push_back(std::make_unique_for_overwrite<Prepared[]>(kChunk));
        Prepared& entry = at(mCount++);
        entry = prepare(index);
        return entry;
      }
    }
  }

 private:
  static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
  static constexpr std::size_t kChunk = 64;
  Prepared& at(std::size_t slot) { return mChunks[slot / kChunk][slot % kChunk]; }
  void grow() {
    const std::size_t size = std::max<std::size_t>(64, 2 * mKeys.size());
    std::vector<std::uint32_t> keys(size, kEmpty), slots(size);
    for (std::size_t h = 0; h < mKeys.size(); ++h) {
      if (mKeys[h] == kEmpty) continue;
      std::size_t g = (mKeys[h] * std::size_t{0x9E3779B1u}) & (size - 1);
      while (keys[g] != kEmpty) g = (g + 1) & (size - 1);
      keys[g] = mKeys[h];
      slots[g] = mSlots[h];
    }
    mKeys = std::move(keys);
    mSlots = std::move(slots);
  }
  std::vector<std::uint32_t> mKeys;   ///< node index per table slot, kEmpty when free
  std::vector<std::uint32_t> mSlots;  ///< its entry in the store
  std::vector<std::unique_ptr<Prepared[]>> mChunks;
  std::size_t mCount = 0;
};

}  // namespace caliber::narrow
