#pragma once
// Shared helpers for tests: reproducible random poses and exact result comparison.

#include <random>

#include <gtest/gtest.h>

#include "support/results.h"
#include "caliber/pose.h"
#include "caliber/query.h"

namespace caliber::test {

/// A uniformly random rotation and a translation uniform in a cube of half-size `spread`.
inline Pose random_pose(std::mt19937_64& rng, double spread) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(-spread, spread);
  const double qw = gauss(rng), qx = gauss(rng), qy = gauss(rng), qz = gauss(rng);
  const double tx = uni(rng), ty = uni(rng), tz = uni(rng);
  return Pose::from_values(tx, ty, tz, qw, qx, qy, qz);
}

/// Bitwise equality of two results: same kind, same pairs, same contacts (every double equal).
inline void expect_identical(const QueryResult& got, const QueryResult& want, const std::string& what) {
  ASSERT_EQ(got.kind, want.kind) << what;
  ASSERT_EQ(test::pairs_of(got), test::pairs_of(want)) << what;
  ASSERT_EQ(got.contacts.size(), want.contacts.size()) << what;
  for (std::size_t i = 0; i < got.contacts.size(); ++i) {
    const Contact& g = got.contacts[i];
    const Contact& w = want.contacts[i];
    ASSERT_EQ(g.tri_a, w.tri_a) << what;
    ASSERT_EQ(g.tri_b, w.tri_b) << what;
    ASSERT_EQ(g.distance, w.distance) << what << " contact " << i;
    ASSERT_EQ(g.point_a, w.point_a) << what << " contact " << i;
    ASSERT_EQ(g.point_b, w.point_b) << what << " contact " << i;
    ASSERT_EQ(g.normal, w.normal) << what << " contact " << i;
    ASSERT_EQ(g.depth, w.depth) << what << " contact " << i;
  }
}

}  // namespace caliber::test
