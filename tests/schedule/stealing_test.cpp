// Stealing cuts each heavy pair by its share of the work (a priori, and last step's node tests):
// the cut changes, the contacts and node and leaf tests do not.

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "caliber/engine.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/profile.h"
#include "caliber/world.h"
#include "support/reference_step.h"
#include "support/same_step.h"
#include "support/temp_dir.h"

namespace caliber {
namespace {

/// Stealing with its schedule recorded, cut for two threads and run on one (the pieces do not
/// depend on the threads' timing).
EngineOptions cut_for_two_on_one() {
  EngineOptions options;
  options.profile = true;  // the tests read the schedule
  options.method = Method::stealing;
  options.threads = 1;
  options.plan_threads = 2;
  return options;
}

TEST(Stealing, SplitsPairsWithHistoryByTheirShare) {
  // Four equal heavy pairs (a torus and a sphere overlapping), apart from one another and still.
  // Cut for two threads, stealing splits each to the full depth at the first step (no history);
  // from the second each holds a quarter of last step's node tests and is split less deep.
  const test::TempDir temp{"stealing"};
  save_off(make_sphere(0.6, 10, 14), temp.path() / "sphere.off");
  save_off(make_torus(0.8, 0.25, 16, 10), temp.path() / "torus.off");
  std::string json = R"({"query": {"kind": "proximity", "tolerance": 0.05}, "objects": [)";
  for (int i = 0; i < 4; ++i) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  R"(%s{"name": "t%d", "mesh": "torus.off", "position": [%d, 0, 0]},)"
                  R"({"name": "s%d", "mesh": "sphere.off", "position": [%g, 0, 0], "motion": {"type": "velocity"}})",
                  i ? "," : "", i, 5 * i, i, 5 * i + 0.8);
    json += buf;
  }
  json += "]}";
  const World four(parse_scene(json, temp.path(), "four.json"));
  ASSERT_EQ(four.broad_phase(four.poses_at(0)).size(), 4u);
  EngineOptions options = cut_for_two_on_one();
  Engine engine(options);
  const StepResult first = step(four, engine, 0);
  const StepResult second = step(four, engine, 1);
  EXPECT_LT(second.schedule->task_node_tests.size(), first.schedule->task_node_tests.size());
  EXPECT_GT(second.schedule->task_node_tests.size(), 4u) << "each pair is still split";
  const StepResult reference = test::reference_step(four, 1);
  EXPECT_GT(reference.contacts.size(), 0u) << "a test that compares empty answers proves nothing";
  test::expect_same_step(first, reference, "the first step");
  test::expect_same_step(second, reference, "the second step");
  // On two threads, the same.
  options.threads = 2;
  options.plan_threads = 0;
  Engine two(options);
  (void)step(four, two, 0);
  test::expect_same_step(step(four, two, 1), reference, "the second step on two threads");
}

TEST(Stealing, SplitsAPairThatHasJustComeIntoDeepContact) {
  // Two torus-sphere pairs. At the first step the first overlaps deeply and the second's sphere
  // lies apart from its torus (its root refused: one node test); at the second both overlap
  // alike. Last step's node tests alone would call the second light and run it whole; its share
  // of the a priori weight has it split as the first is: about twice the pieces.
  const std::shared_ptr<const Model> torus = build_model(make_torus(0.8, 0.25, 24, 12));
  const std::shared_ptr<const Model> sphere = build_model(make_sphere(0.6, 12, 16));
  Frame frame;
  frame.models = {torus, sphere, torus, sphere};
  const auto at = [](double x) { return Pose::from_values(x, 0, 0, 1, 0, 0, 0); };
  frame.poses = {at(0), at(0.75), at(8), at(10)};  // offsets exact in binary: the same work
  frame.pairs = {ObjectPair{0, 1}, ObjectPair{2, 3}};
  frame.request.kind = QueryKind::proximity;
  frame.request.tolerance = 0.05;
  EngineOptions options = cut_for_two_on_one();
  Engine engine(options);
  const StepResult first = engine.step(frame);
  ASSERT_LT(first.pair_records[1].stats.node_tests * 50, first.pair_records[0].stats.node_tests) << "the second pair is light";
  frame.poses[3] = at(8.75);
  const StepResult second = engine.step(frame);
  EXPECT_EQ(second.pair_records[1].stats.node_tests, second.pair_records[0].stats.node_tests) << "the same work";
  EXPECT_GT(2 * second.schedule->task_node_tests.size(), 3 * first.schedule->task_node_tests.size())
      << "the second pair split as the first";
  EXPECT_EQ(second.contacts.size(), 2 * first.pair_records[0].contacts);
}

TEST(Stealing, ADistancePairAtContactIsAnsweredByTheFirstHit) {
  // A torus through a sphere, a distance query: where the meshes intersect, caliber::query answers
  // with the first hit. Cut for two threads, stealing and the calibrated methods ask for it too
  // before they cut the pair (its pieces would each look for a contact with the distance bounds):
  // the same contact, the same node tests, one piece. Apart, the pair is cut as before.
  const std::shared_ptr<const Model> torus = build_model(make_torus(0.8, 0.25, 48, 24));
  const std::shared_ptr<const Model> sphere = build_model(make_sphere(0.6, 24, 32));
  for (const Method method : {Method::stealing, Method::apriori, Method::aposteriori, Method::hybrid}) {
    const std::string what{to_string(method)};
    Frame frame;
    frame.models = {torus, sphere};
    frame.poses = {Pose{}, Pose::from_values(0.75, 0, 0, 1, 0, 0, 0)};
    frame.pairs = {ObjectPair{0, 1}};
    frame.request.kind = QueryKind::distance;
    frame.request.tolerance = kUnbounded;
    EngineOptions options = cut_for_two_on_one();
    options.method = method;
    Engine engine(options);
    const QueryResult one = query(*torus, frame.poses[0], *sphere, frame.poses[1], frame.request);
    ASSERT_EQ(one.contacts.size(), 1u);
    ASSERT_EQ(one.contacts[0].distance, 0.0) << "the meshes must intersect";
    // Twice: the first step without history, the second with the first's (aposteriori's summary).
    for (int k = 0; k < 2; ++k) {
      const StepResult touching = engine.step(frame);
      ASSERT_EQ(touching.contacts.size(), 1u) << what;
      EXPECT_EQ(touching.contacts[0].tri_a, one.contacts[0].tri_a) << what;
      EXPECT_EQ(touching.contacts[0].tri_b, one.contacts[0].tri_b) << what;
      EXPECT_EQ(touching.pair_records[0].stats.node_tests, one.stats.node_tests) << what << " step " << k;
      EXPECT_EQ(touching.schedule->task_node_tests.size(), 1u) << what << " step " << k << ": one piece, the first hit";
    }
    frame.poses[1] = Pose::from_values(2.5, 0, 0, 1, 0, 0, 0);
    const QueryResult far = query(*torus, frame.poses[0], *sphere, frame.poses[1], frame.request);
    const StepResult apart = engine.step(frame);
    ASSERT_EQ(apart.contacts.size(), 1u) << what;
    ASSERT_GT(far.contacts[0].distance, 0.0);
    EXPECT_EQ(apart.contacts[0].distance, far.contacts[0].distance) << what;
    EXPECT_EQ(apart.contacts[0].tri_a, far.contacts[0].tri_a) << what;
    EXPECT_EQ(apart.contacts[0].tri_b, far.contacts[0].tri_b) << what;
    EXPECT_GT(apart.schedule->task_node_tests.size(), method == Method::stealing ? 4u : 1u) << what << ": apart, it is cut";
    // Stealing cuts a distance pair to depth 2 on 2 threads: at most 16 pieces (a visit of the
    // binary CD tree has up to four children), and the first hit; cut to depth 10, hundreds.
    if (method == Method::stealing) EXPECT_LE(apart.schedule->task_node_tests.size(), 17u);
  }
}

}  // namespace
}  // namespace caliber
