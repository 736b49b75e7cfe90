#pragma once
// Whether a step equals another: the same pairs, the same work per pair, the same contacts bit for
// bit (the check every schedule's step is held to against the reference).

#include <string>

#include <gtest/gtest.h>

#include "caliber/engine.h"

namespace caliber::test {

/// `exact_work`: the method tests exactly the nodes sequential tests (all but a posteriori, whose
/// sub-tasks may test below a node that the original task pruned; see ScheduleRecord).
inline void expect_same_step(const StepResult& got, const StepResult& want, const std::string& what, bool exact_work = true) {
  ASSERT_EQ(got.pair_records.size(), want.pair_records.size()) << what;
  for (std::size_t i = 0; i < want.pair_records.size(); ++i) {
    ASSERT_EQ(got.pair_records[i].pair, want.pair_records[i].pair) << what;
    if (exact_work) {
      EXPECT_EQ(got.pair_records[i].stats.node_tests, want.pair_records[i].stats.node_tests) << what << " pair " << i;
      EXPECT_EQ(got.pair_records[i].stats.leaf_tests, want.pair_records[i].stats.leaf_tests) << what << " pair " << i;
    } else {
      EXPECT_GE(got.pair_records[i].stats.node_tests, want.pair_records[i].stats.node_tests) << what << " pair " << i;
    }
  }
  ASSERT_EQ(got.contacts.size(), want.contacts.size()) << what;
  for (std::size_t i = 0; i < want.contacts.size(); ++i) {
    const Contact& g = got.contacts[i];
    const Contact& w = want.contacts[i];
    ASSERT_EQ(g.object_a, w.object_a) << what;
    ASSERT_EQ(g.object_b, w.object_b) << what;
    ASSERT_EQ(g.tri_a, w.tri_a) << what;
    ASSERT_EQ(g.tri_b, w.tri_b) << what;
    ASSERT_EQ(g.distance, w.distance) << what;
    ASSERT_EQ(g.point_a, w.point_a) << what;
    ASSERT_EQ(g.point_b, w.point_b) << what;
    ASSERT_EQ(g.normal, w.normal) << what;
    ASSERT_EQ(g.depth, w.depth) << what;
  }
}

}  // namespace caliber::test
