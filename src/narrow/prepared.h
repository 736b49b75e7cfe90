#pragma once
/// \file
/// Nodes prepared for one object pair's tests (PairContext): what the node test and the distance
/// bound read of a node, computed once per node and traversal (B's brought into A's frame), and
/// PreparedTree, the distance traversal's store of them.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "bvh/model_data.h"

namespace caliber::narrow {

/// A prepared node of A's box: its box, and that box seen from B's frame (center, and extent
/// along each of B's axes).
struct BoxA {
  std::uint32_t index;   ///< node index in A
  double box[3];         ///< box center (A's frame)
  double half[3];        ///< box half-extents (A's axes)
  double box_in_b[3];    ///< box center in B's frame
  double reach_on_b[3];  ///< half-extent of A's box along each of B's axes
};
/// The same of B, brought into A's frame.
struct BoxB {
  std::uint32_t index;   ///< node index in B
  double box[3];         ///< box center (B's own frame)
  double half[3];        ///< box half-extents (B's axes)
  double box_in_a[3];    ///< box center in A's frame
  double reach_on_a[3];  ///< half-extent of B's box along each of A's axes
};
/// What the node test's prepared node of A holds: its box and its sphere.
struct NodeA : BoxA {
  double center[3];  ///< sphere center (A's frame)
  double radius;     ///< sphere radius
};
/// The same of B, its sphere brought into A's frame.
struct NodeB : BoxB {
  double center[3];  ///< sphere center in A's frame
  double radius;     ///< sphere radius
};
/// A node of A with what the node-node test needs of it precomputed (PairContext::prepare_a).
/// Prepared once per node and reused against every node of B it meets (the traversal tests two
/// children of A against two of B).
struct SideA : NodeA {
  double slab_axis[3];  ///< slab axis (A's frame), 0 when the node has none
  double slab_on_b[3];  ///< |slab axis . B's axis k|: how much of B's half-extent k it sees
  double slab_lo, slab_hi;
  // Its disk (disks.h), filled by PairContext::prepare_disk_a: for the four-at-once tests only.
  double center_from_b[3];  ///< sphere center less B's origin (A's frame): what B's slab sees of it
  double disk_lo, disk_hi;  ///< slab bounds less slab axis . sphere center
  double axis_len2;         ///< slab axis . slab axis (0 when the node has no slab)
};
/// A node of B, prepared the same way (PairContext::prepare_b): centers brought into A's frame.
struct SideB : NodeB {
  double slab_axis[3];  ///< slab axis (B's own frame), 0 when the node has none
  double slab_on_a[3];  ///< |slab axis . A's axis k|
  double slab_lo, slab_hi;
  double axis_in_a[3];  ///< slab axis brought into A's frame (rotated)
  // Its disk, filled by PairContext::prepare_disk_b.
  double disk_lo, disk_hi;  ///< slab bounds less slab axis . sphere center (B's own frame)
  double axis_len2;         ///< slab axis . slab axis (0 when the node has no slab)
};
/// A box around a node's triangles, for the distance bound: its axes (orthonormal up to
/// rounding), center and half-extents along them (caliber::node_oriented_box).
using OrientedBox = BvhNodeOrientedBox;
/// A node of A prepared for the distance bound: its box and its OrientedBox (no sphere: the bound does not
/// use it).
struct NearA : BoxA {
  OrientedBox frame;
};
/// A node of B prepared for the distance bound: its box and its OrientedBox brought into A's frame.
struct NearB : BoxB {
  OrientedBox frame;
};

/// The nodes one distance traversal has prepared, kept as a tree that follows the BVH's: a
/// prepared node links to its two children (adjacent in the BVH, so prepared together) once a
/// visit has descended into it, and every later visit that descends into it follows the link. So each node is
/// prepared once however many partners it meets (the traversal meets a node several times), with
/// no lookup by index (a hash table by index made the distance query slower on every case of the
/// bench). A node is only ever reached through its parent's link (or as the traversal's root), so
/// it has one entry. Entries never move, so a pointer to one stays valid while others are added.
/// Cleared per traversal: a prepared node depends on the pair's relative pose.
template <class Prepared>
class PreparedTree {
 public:
  /// A prepared node and the link to its children's entries (two adjacent ones; null until made).
  struct Node : Prepared {
    Node* kids;
  };

  /// Forgets every entry (keeps the memory).
  void clear() {
    mChunk = 0;
    mUsed = 0;
  }
  /// Bytes held, for a caller that keeps the scratch between calls.
  [[nodiscard]] std::size_t footprint() const { return mChunks.size() * kChunk * sizeof(Node); }

  /// A new entry for node `index` (a traversal's root), filled by prepare(index, entry).
  template <class Prepare>
  Node* root(std::uint32_t index, Prepare&& prepare) {
    return hold(take(1), index, prepare);
  }
  /// The entries of the children `first` and `first + 1` of `parent`'s node, each filled by
  /// prepare(index, entry) the first time they are asked for (from then on, the same two).
  template <class Prepare>
  Node* kids(Node& parent, std::uint32_t first, Prepare&& prepare) {
    if (parent.kids == nullptr) {
      Node* pair = take(2);
      for (std::uint32_t i = 0; i < 2; ++i) hold(pair + i, first + i, prepare);
      parent.kids = pair;
    }
    return parent.kids;
  }

 private:
  static constexpr std::size_t kChunk = 64;
  /// Fills a taken entry where it lies (no copy of the prepared node): node `index` prepared, no
  /// children yet.
  template <class Prepare>
  static Node* hold(Node* node, std::uint32_t index, Prepare& prepare) {
    prepare(index, static_cast<Prepared&>(*node));
    node->kids = nullptr;
    return node;
  }
  /// n (1 or 2) adjacent entries in the current chunk, or at the start of the next.
  Node* take(std::size_t n) {
    if (mUsed + n > kChunk) {
      ++mChunk;
      mUsed = 0;
    }
    if (mChunk == mChunks.size()) mChunks.push_back(std::make_unique_for_overwrite<Node[]>(kChunk));
    Node* node = &mChunks[mChunk][mUsed];
    mUsed += n;
    return node;
  }
  std::vector<std::unique_ptr<Node[]>> mChunks;
  std::size_t mChunk = 0;  ///< the chunk entries are taken from
  std::size_t mUsed = 0;   ///< entries taken from it
};

}  // namespace caliber::narrow
