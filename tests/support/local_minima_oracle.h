#pragma once
// An independent contact reduction for the tests: of a proximity query's pairs (every pair within
// the tolerance), those no closer pair (ties: lower ids) dominates by sharing one triangle and
// having the other share a vertex position with its own (as the adjacency welds a seam's repeated
// vertices). Quadratic: for meshes of a few thousand pairs.

#include <cstdint>
#include <utility>
#include <vector>

#include "caliber/mesh.h"
#include "caliber/query.h"

namespace caliber::test {

/// The (tri_a, tri_b) of the pairs of `within` the reduction keeps, in within's order.
inline std::vector<std::pair<std::uint32_t, std::uint32_t>> local_minima_oracle(const std::vector<Contact>& within, const Mesh& a,
                                                                                const Mesh& b) {
  const auto neighbours = [](const Mesh& m, std::uint32_t t, std::uint32_t u) {
    if (t == u) return false;
    for (const std::uint32_t v : m.triangles[t]) {
      for (const std::uint32_t w : m.triangles[u]) {
        if (m.vertices[v] == m.vertices[w]) return true;
      }
    }
    return false;
  };
  std::vector<std::pair<std::uint32_t, std::uint32_t>> kept;
  for (const Contact& c : within) {
    bool dominated = false;
    for (const Contact& o : within) {
      const bool closer =
          o.distance != c.distance ? o.distance < c.distance : std::pair(o.tri_a, o.tri_b) < std::pair(c.tri_a, c.tri_b);
      if (closer &&
          ((o.tri_b == c.tri_b && neighbours(a, o.tri_a, c.tri_a)) || (o.tri_a == c.tri_a && neighbours(b, o.tri_b, c.tri_b)))) {
        dominated = true;
        break;
      }
    }
    if (!dominated) kept.emplace_back(c.tri_a, c.tri_b);
  }
  return kept;
}

/// The (tri_a, tri_b) of `contacts`, in order.
inline std::vector<std::pair<std::uint32_t, std::uint32_t>> pair_ids(const std::vector<Contact>& contacts) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  for (const Contact& c : contacts) out.emplace_back(c.tri_a, c.tri_b);
  return out;
}

}  // namespace caliber::test
