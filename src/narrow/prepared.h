#pragma once
/// \file
/// Nodes prepared for one object pair's tests (PairContext): what the node test and the distance
/// bound read of a node, computed once per node and traversal (B's brought into A's frame).

#include <cstdint>

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

}  // namespace caliber::narrow
