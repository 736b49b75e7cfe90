#pragma once
/// \file
/// The a priori weight of a CD-tree node: an estimate, from geometry only, of how many node tests
/// its subtree will take.
///
/// Derivation. Two nodes hold P_a and P_b triangles of surfaces that their spheres (radii r_a, r_b)
/// bound. Only the parts of the two surfaces near the lens where the spheres (grown by d) overlap can
/// lead the traversal deep; elsewhere it stops near the top. Let o be the depth of that overlap:
/// the smaller of the spheres' r_a + r_b + d - |c_a - c_b| and the boxes' least penetration over
/// the six face axes (0 when apart). Spheres alone overrate thin parts, whose spheres are large and
/// loose: on front_car that made the a priori method split the wrong pairs (1.08x at 2 threads,
/// against 1.6x once the boxes are used). A surface patch spread over a sphere of
/// radius r has about the fraction o / (2 r) of its area inside a cap of height o (the area of a
/// spherical cap is proportional to its height), so about n_a = P_a min(1, o / 2 r_a) triangles of A
/// and n_b = P_b min(1, o / 2 r_b) of B are in play. A depth-first traversal of two surfaces in
/// contact costs a few node tests per triangle in play (each one is reached by a path whose upper
/// part it shares with its neighbours), so the estimate is w = 1 + 2 (n_a + n_b): 1 for the test of
/// the node itself. Only ratios of weights matter to calibration (Omega is a fraction of their
/// sum, and the hybrid metric rescales them by measured counts), so the factor 2 is cosmetic.
/// The paper's printed formula is garbled; this one keeps its ingredients (P, r, the centers'
/// distance) and its behaviour (heavier when larger and deeper in contact).

#include "narrow/pair_context.h"
#include "narrow/traversal.h"

namespace caliber::tasks {

/// The a priori weight of CD-tree node n (see above). Reads the node's spheres only.
double apriori_weight(const narrow::PairContext& ctx, narrow::NodePair n);

}  // namespace caliber::tasks
