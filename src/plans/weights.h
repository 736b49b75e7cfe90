#pragma once
/// \file
/// The a priori weight of a CD-tree node: an estimate, from geometry only, of how many node tests
/// its subtree will take.
///
/// Derivation. Two nodes hold P_a and P_b triangles of surfaces that their spheres (radii r_a, r_b)
/// and boxes bound. Only the parts of the two surfaces inside the region where the two volumes
/// (grown by d) overlap can lead the traversal deep; elsewhere it stops near the top. A depth-first
/// traversal of two surfaces in contact costs a few node tests per triangle in play (each one is
/// reached by a path whose upper part it shares with its neighbours), so the estimate is
/// w = 1 + 2 (s_a P_a + s_b P_b), where s is the share of a node's triangles in play (1 for the
/// test of the node itself). Only ratios of weights matter to calibration (Omega is a fraction of
/// their sum, and the hybrid metric rescales them by measured counts), so the factor 2 is cosmetic.
///
/// The share is estimated twice, the two estimates failing in opposite directions, and s is their
/// geometric mean (their average in the log domain, where a factor too high and a factor too low
/// weigh alike):
///  - depth: with o the least penetration (of the spheres, r_a + r_b + d - |c_a - c_b|, and of the
///    boxes on the six face axes), a patch spread over a sphere of radius r has about o / 2r of its
///    area inside a cap of height o (a cap's area is proportional to its height). Spheres alone
///    overrate thin parts, whose spheres are large and loose (on front_car that made the a priori
///    method split the wrong pairs, and gain far less than once the boxes were used); but dividing
///    a long part's least penetration (its thickness) by its diameter underrates it: two crossing
///    rods, or the heavy pairs of front_car, weighed no more than light pairs (the two pairs that
///    took the most node tests weighed less than some light ones, and neither was ever split).
///  - axes: along each of the six box axes, the part of the node's extent inside the other's grown
///    box, the least of them (and of the sphere cap o / 2r): exact for a box-shaped spread of
///    triangles cut by one axis, but it overrates flat patches whose boxes overlap though their
///    surfaces do not come near (with this share alone, two_large's simulated speed-up at P = 2
///    fell below the depth share's).
/// Measured (bench/results/amd-epyc-2c/scaling/weights.md): against the depth share alone, the log
/// correlation with the node tests each CD node's subtree takes rises on every scene (nodes with
/// >= 1,000 tests).
/// The paper's printed formula is garbled; this one keeps its ingredients (P, r, the centers'
/// distance) and its behaviour (heavier when larger and deeper in contact).

#include <vector>

#include "narrow/pair_context.h"
#include "narrow/traversal.h"

namespace caliber::plans {

/// The a priori weight of CD-tree node n (see above). Reads the node's spheres only.
double apriori_weight(const narrow::PairContext& ctx, narrow::NodePair n);

/// The a priori weight of every pair's root, in parallel on the caller's executor.
std::vector<double> root_weights(narrow::PairContexts contexts);

}  // namespace caliber::plans
