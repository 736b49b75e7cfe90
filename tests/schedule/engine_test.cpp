// Every method, every thread count, every step: the same contacts as the sequential reference, to
// the bit, and (for these methods, which cut the same tree) the same node tests per pair.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <gtest/gtest.h>

#include "support/results.h"
#include "bvh/model_data.h"
#include "caliber/engine.h"
#include "caliber/profile.h"
#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/world.h"
#include "support/temp_dir.h"
#include "support/reference_step.h"
#include "support/same_step.h"

namespace caliber {
namespace {

using test::expect_same_step;

/// Runs `steps` steps of the world with every method and thread count against the pairwise
/// reference (test::reference_step).
void expect_all_methods_identical(const World& world, int steps) {
  std::vector<StepResult> reference;
  for (int k = 0; k < steps; ++k) reference.push_back(test::reference_step(world, k));
  std::size_t contacts = 0;
  for (const auto& r : reference) contacts += r.contacts.size();
  EXPECT_GT(contacts, 0u) << "a test that compares empty answers proves nothing";
  const std::pair<Method, bool> configs[] = {
      {Method::sequential, false}, {Method::exploitation, false}, {Method::stealing, false}, {Method::aposteriori, false},
      {Method::apriori, false},    {Method::hybrid, false},       {Method::hybrid, true}};
  for (const auto& [method, node_history] : configs) {
    for (const int threads : {1, 2, 3, 4, 8}) {
      EngineOptions options;
      options.profile = true;  // the tests read the schedule
      options.method = method;
      options.node_history = node_history;
      options.threads = threads;
      options.stealing_depth = 3;  // shallow: many tasks, much stealing
      Engine engine(options);
      for (int k = 0; k < steps; ++k) {
        const StepResult got = step(world, engine, k);
        const std::string what = std::string(to_string(method)) + (node_history ? "+history" : "") + " x" +
                                 std::to_string(threads) + " step " + std::to_string(k);
        expect_same_step(got, reference[k], what, method != Method::aposteriori);
        if (::testing::Test::HasFatalFailure()) return;
        std::uint64_t units = got.schedule->split_node_tests;
        for (const std::uint64_t t : got.schedule->task_node_tests) units += t;
        for (const std::uint64_t t : got.schedule->stage_pair_node_tests) units += t;
        EXPECT_EQ(units, got.stats.node_tests) << what << ": the recorded work units must add up";
        // Conservation: every node sequential tests is tested once; a posteriori may add the work of
        // sub-tasks whose root the original task never reached, and says how much.
        EXPECT_EQ(got.stats.node_tests - got.schedule->taboo_unreached_node_tests, reference[k].stats.node_tests) << what;
        for (const PairRecord& t : got.pair_records)
          EXPECT_GE(t.candidates, t.contacts) << what << ": reported pairs are candidates";
        if (method == Method::apriori || method == Method::hybrid) {
          // The stage's levels hold its node tests (all but each split pair's root test).
          std::uint64_t levels = got.schedule->stage_pair_node_tests.size();
          for (const std::vector<std::uint64_t>& level : got.schedule->stage_levels) {
            for (const std::uint64_t chunk : level) levels += chunk;
          }
          EXPECT_EQ(levels, got.schedule->stage_node_tests) << what;
          EXPECT_EQ(got.schedule->stage_levels.size(), got.schedule->stage_level_pair.size()) << what;
          // Conservation: the weight-driven stage and the run-time tasks test every node once.
          std::uint64_t cut = got.schedule->stage_node_tests;
          for (const std::uint64_t t : got.schedule->task_node_tests) cut += t;
          EXPECT_EQ(cut, reference[k].stats.node_tests) << what;
          for (const std::uint64_t t : got.schedule->task_node_tests) EXPECT_GT(t, 0u) << what << ": an empty run-time task";
          EXPECT_EQ(got.schedule->generated, got.schedule->task_node_tests.size()) << what;
        }
      }
    }
  }
}

class EngineScenes : public ::testing::Test {
 protected:
  void SetUp() override {
    save_off(make_box(0.5, 0.5, 0.5, 3), dir / "cube.off");
    save_off(make_sphere(0.6, 10, 14), dir / "sphere.off");
    save_off(make_torus(0.8, 0.25, 16, 10), dir / "torus.off");
  }
  /// A torus and a sphere overlapping, proximity: one heavy pair.
  [[nodiscard]] World one_heavy_pair() const {
    return World(parse_scene(R"({"query": {"kind": "proximity", "tolerance": 0.05}, "objects": [
      {"name": "a", "mesh": "torus.off"}, {"name": "b", "mesh": "sphere.off", "position": [0.8, 0, 0], "motion": {"type": "velocity"}}]})",
                             dir, "single.json"));
  }
  test::TempDir temp{"engine"};
  const std::filesystem::path& dir = temp.path();
};

TEST_F(EngineScenes, SmallSceneEveryKind) {
  for (const char* kind : {"interference", "proximity", "contact"}) {
    const World world(parse_scene(std::string(R"({"steps": 6, "dt": 0.1, "query": {"kind": ")") + kind +
                                      R"(", "tolerance": 0.1, "angle": 40}, "objects": [
      {"name": "ring", "mesh": "torus.off", "motion": {"type": "velocity", "angular": [0, 0.5, 0]}},
      {"name": "ball", "mesh": "sphere.off", "position": [0.9, 0, 0.3], "motion": {"type": "velocity", "linear": [-0.2, 0, -0.1]}},
      {"name": "box", "mesh": "cube.off", "position": [-0.2, 0.8, 0], "motion": {"type": "velocity", "linear": [0.05, -0.1, 0]}},
      {"name": "box2", "mesh": "cube.off", "position": [0.3, -0.7, 0.1], "orientation": [0.9, 0.3, 0.1, 0.2]}]})",
                                  dir, "engine_test.json"));
    expect_all_methods_identical(world, 6);
  }
}

TEST(EngineRealScenes, PaperScenesFirstSteps) {
  const std::filesystem::path scenes = CALIBER_SCENES;
  if (!std::filesystem::exists(std::filesystem::path(CALIBER_MESH_DATA) / "dragknob.off")) {
    GTEST_SKIP() << "run scripts/fetch_meshes.sh first";
  }
  for (const char* name : {"two_small.json", "funnel.json", "front_car.json"}) {
    Scene scene = load_scene(scenes / name);
    const World world(std::move(scene));
    expect_all_methods_identical(world, 3);
  }
}

TEST_F(EngineScenes, ThreeHundredTinyPairsAndOnePair) {
  // 25 tetrahedra (4 triangles each) crowded together: 300 pairs, all light.
  const std::string tetra = (std::filesystem::path(CALIBER_TEST_DATA) / "tetra.off").string();
  std::string json = R"({"query": {"kind": "proximity", "tolerance": 0.05}, "objects": [)";
  for (int i = 0; i < 25; ++i) {
    char buf[512];
    std::snprintf(buf, sizeof buf, R"(%s{"name": "t%d", "mesh": "%s", "position": [%g, %g, 0], "motion": {"type": "velocity"}})",
                  i ? "," : "", i, tetra.c_str(), 0.03 * (i % 5), 0.03 * (i / 5));
    json += buf;
  }
  json += "]}";
  const World crowd(parse_scene(json, dir, "crowd.json"));
  EXPECT_EQ(crowd.broad_phase(crowd.poses_at(0)).size(), 300u);
  expect_all_methods_identical(crowd, 1);
  const World single = one_heavy_pair();
  expect_all_methods_identical(single, 2);
  // One heavy pair on two threads is split: more than one run-time task.
  EngineOptions options;
  options.profile = true;  // the tests read the schedule
  options.method = Method::apriori;
  options.threads = 2;
  Engine engine(options);
  const StepResult s = step(single, engine, 0);
  EXPECT_EQ(s.schedule->split, 1u);
  EXPECT_GT(s.schedule->generated, 1u);
  // A posteriori has nothing to go on at the first step; from the second, last step's contacts
  // give sub-task roots and the taboo list.
  options.method = Method::aposteriori;
  Engine temporal(options);
  const StepResult first = step(single, temporal, 0);
  EXPECT_EQ(first.schedule->taboo, 0u);
  const StepResult second = step(single, temporal, 1);
  EXPECT_GT(second.schedule->taboo, 0u);
  EXPECT_GT(second.schedule->generated, 1u);
}

TEST_F(EngineScenes, CutForOneThreadEveryPairRunsWhole) {
  // One heavy pair: cut for one thread, no method splits it (there is nothing to balance); cut for
  // two threads and run on one (the load-balance simulation), every method still splits it.
  const World single = one_heavy_pair();
  for (const Method method : {Method::stealing, Method::apriori, Method::aposteriori, Method::hybrid}) {
    for (const int plan_threads : {0, 2}) {
      EngineOptions options;
      options.profile = true;  // the tests read the schedule
      options.method = method;
      options.threads = 1;
      options.plan_threads = plan_threads;
      Engine engine(options);
      // The first step: a posteriori has no history yet.
      (void)step(single, engine, 0);
      const StepResult s = step(single, engine, 1);  // a posteriori splits from the second step
      const std::string what = std::string(to_string(method)) + " cut for " + std::to_string(plan_threads) + " threads";
      if (method == Method::stealing) {
        EXPECT_EQ(s.schedule->task_node_tests.size() == 1, plan_threads == 0) << what;
        EXPECT_EQ(s.schedule->split_node_tests == 0, plan_threads == 0) << what;
      } else {
        EXPECT_EQ(s.schedule->split, plan_threads == 0 ? 0u : 1u) << what;
        EXPECT_EQ(s.schedule->generated == 1, plan_threads == 0) << what;
      }
    }
  }
}

TEST(LoadBalanceSimulation, ListSchedulingAndTheExploitationBound) {
  EXPECT_EQ(list_schedule_makespan({}, 4), 0.0);
  EXPECT_EQ(list_schedule_makespan({5, 5, 5, 5}, 2), 10.0);
  EXPECT_EQ(list_schedule_makespan({1, 1, 1, 9}, 2), 10.0) << "handout order, not sorted: the 9 lands on a loaded core";
  EXPECT_EQ(list_schedule_makespan({9, 1, 1, 1}, 2), 9.0);
  EXPECT_THROW((void)list_schedule_makespan({1}, 0), Error);
  EXPECT_THROW((void)list_schedule_makespan({1}, 65537), Error) << "a queue entry per core";
  StepResult step;
  EXPECT_THROW((void)simulated_speedup(step, Method::exploitation, 8), Error) << "a step run without a schedule";
  auto record = std::make_shared<ScheduleRecord>();
  step.schedule = record;
  step.stats.node_tests = 100;
  record->task_node_tests = {60, 30, 10};
  EXPECT_NEAR(simulated_speedup(step, Method::exploitation, 8), 100.0 / 60.0, 1e-12) << "bound by the heaviest pair";
  EXPECT_EQ(simulated_speedup(step, Method::sequential, 8), 1.0);
  record->task_node_tests = {20, 20, 20, 20};
  // One split pair: its root's test, then levels of 4 and 15 node tests (chunks 8 and 7: one core
  // each at most), 20 in all: a span of 1 + 4 + 8 = 13 on 4 cores, above 20 / 4.
  record->stage_pair_node_tests = {20};
  record->stage_levels = {{4}, {8, 7}};
  record->stage_level_pair = {0, 0};
  EXPECT_NEAR(simulated_speedup(step, Method::hybrid, 4), 100.0 / (13.0 + 20.0), 1e-12) << "stage, barrier, then the tasks";
  // Wide levels: the stage's tests spread evenly bound it (two split pairs sharing the cores).
  record->stage_pair_node_tests = {35, 35};
  record->stage_levels = {{2}, {4, 4, 4, 4, 4, 4, 4, 4}, {2}, {4, 4, 4, 4, 4, 4, 4, 4}};
  record->stage_level_pair = {0, 0, 1, 1};
  step.stats.node_tests = 150;
  EXPECT_NEAR(simulated_speedup(step, Method::apriori, 4), 150.0 / (70.0 / 4 + 20.0), 1e-12) << "each span 1 + 2 + 8";
  for (const int cores : {0, -3, 1 << 30}) {
    EXPECT_THROW((void)simulated_speedup(step, Method::apriori, cores), Error) << cores << " cores (the stage's schedule)";
  }
}

TEST(EngineRealScenes, HeavyPairFinalizedInParallel) {
  // two_large's one pair keeps thousands of candidates: its sort, local minima and transforms run
  // as parallel jobs in the calibrated and stealing methods; the contacts must not change.
  if (!std::filesystem::exists(std::filesystem::path(CALIBER_MESH_DATA) / "dragknob.off")) {
    GTEST_SKIP() << "run scripts/fetch_meshes.sh first";
  }
  const World world(load_scene(std::filesystem::path(CALIBER_SCENES) / "two_large.json"));
  const StepResult reference = test::reference_step(world, 3);
  ASSERT_GT(reference.contacts.size(), 100u);
  for (const Method method : {Method::stealing, Method::hybrid}) {
    for (const int threads : {2, 8}) {
      EngineOptions options;
      options.profile = true;  // the tests read the schedule
      options.method = method;
      options.threads = threads;
      Engine engine(options);
      expect_same_step(step(world, engine, 3), reference, std::string(to_string(method)) + " x" + std::to_string(threads));
    }
  }
}

TEST_F(EngineScenes, TimelineRecordsEveryPieceOfWork) {
  const World world(parse_scene(R"({"query": {"kind": "contact", "tolerance": 0.05}, "objects": [
      {"name": "a", "mesh": "torus.off"}, {"name": "b", "mesh": "sphere.off", "position": [0.8, 0, 0], "motion": {"type": "velocity"}},
      {"name": "c", "mesh": "cube.off", "position": [-0.6, 0.5, 0], "motion": {"type": "velocity"}}]})",
                                dir, "timeline.json"));
  const StepResult reference = test::reference_step(world, 0);
  for (const Method method : {Method::sequential, Method::exploitation, Method::stealing, Method::apriori, Method::hybrid}) {
    EngineOptions options;
    options.profile = true;  // the tests read the schedule
    options.method = method;
    options.threads = 3;
    options.timeline = true;
    Engine engine(options);
    const StepResult got = step(world, engine, 0);
    const std::string what(to_string(method));
    expect_same_step(got, reference, what);
    const ScheduleRecord& r = *got.schedule;
    std::size_t stage = 0, traverse = 0, finalize = 0;
    const std::size_t pairs = got.pair_records.size();
    std::vector<int> finalized(pairs, 0), traversed(r.task_node_tests.size(), 0);
    for (const TaskSpan& s : r.timeline) {
      if (s.phase == TaskSpan::Phase::finalize) {
        ASSERT_LT(s.unit, pairs) << what;
        ++finalized[s.unit];
      } else if (s.phase == TaskSpan::Phase::stage || method == Method::stealing) {
        EXPECT_LT(s.unit, pairs) << what << ": a stage or stealing piece names its pair";
      } else {
        ASSERT_LT(s.unit, traversed.size()) << what;
        ++traversed[s.unit];
      }
      EXPECT_GE(s.thread, 0) << what;
      EXPECT_LT(s.thread, engine.threads()) << what;
      EXPECT_LE(0.0, s.start_ms) << what;
      EXPECT_LE(s.start_ms, s.end_ms) << what;
      stage += s.phase == TaskSpan::Phase::stage;
      traverse += s.phase == TaskSpan::Phase::traverse;
      finalize += s.phase == TaskSpan::Phase::finalize;
    }
    ASSERT_GT(pairs, 0u);
    EXPECT_EQ(finalized, std::vector<int>(pairs, 1)) << what << ": each pair finalized once";
    if (method == Method::stealing) {
      EXPECT_TRUE(r.task_roots.empty()) << what << ": pieces are cut while it runs";
    } else {
      EXPECT_EQ(traversed, std::vector<int>(r.task_node_tests.size(), 1)) << what << ": each run-time task once";
      ASSERT_EQ(r.task_roots.size(), r.task_node_tests.size()) << what;
      for (const std::vector<TaskRoot>& roots : r.task_roots) {
        ASSERT_FALSE(roots.empty()) << what;
        for (const TaskRoot& root : roots) {
          ASSERT_LT(root.pair, pairs) << what;
          const ObjectPair& pair = got.pair_records[root.pair].pair;
          EXPECT_LT(root.node_a, world.model(pair.a).node_count()) << what;
          EXPECT_LT(root.node_b, world.model(pair.b).node_count()) << what;
        }
      }
    }
    if (method == Method::sequential || method == Method::exploitation) {
      EXPECT_EQ(traverse, pairs) << what << ": one traversal span per pair";
      EXPECT_EQ(stage, 0u) << what;
      EXPECT_EQ(finalize, pairs) << what;
    } else if (method == Method::stealing) {
      EXPECT_EQ(traverse, r.task_node_tests.size()) << what << ": one span per depth-first piece";
      EXPECT_EQ(finalize, pairs) << what;
    } else {
      EXPECT_EQ(stage, r.split) << what;
      EXPECT_EQ(traverse, r.generated) << what;
      EXPECT_EQ(finalize, pairs) << what;
    }
  }
  EngineOptions off;
  off.profile = true;  // the tests read the schedule
  off.method = Method::hybrid;
  off.threads = 2;
  Engine quiet(off);
  const StepResult plain = step(world, quiet, 0);
  EXPECT_TRUE(plain.schedule->timeline.empty()) << "off by default";
  EXPECT_TRUE(plain.schedule->task_roots.empty()) << "off by default";
}

TEST_F(EngineScenes, PlanThreadsCutsForThatManyThreadsOnOne) {
  const World world(parse_scene(R"({"steps": 3, "dt": 0.1, "query": {"kind": "contact", "tolerance": 0.05}, "objects": [
      {"name": "a", "mesh": "torus.off", "motion": {"type": "velocity", "angular": [0, 0.5, 0]}},
      {"name": "b", "mesh": "sphere.off", "position": [0.8, 0, 0], "motion": {"type": "velocity", "linear": [-0.1, 0, 0]}},
      {"name": "c", "mesh": "cube.off", "position": [-0.6, 0.5, 0]}]})",
                                dir, "plan_threads.json"));
  for (const Method method : {Method::apriori, Method::hybrid}) {
    EngineOptions wide;
    wide.profile = true;  // the tests read the schedule
    wide.method = method;
    wide.threads = 4;
    wide.plan_threads = 4;  // what 4 threads get (this machine may have fewer)
    EngineOptions narrow = wide;
    narrow.threads = 1;
    narrow.plan_threads = 4;
    Engine four(wide), one(narrow);
    EXPECT_EQ(one.threads(), 1);
    bool split = false;
    for (int k = 0; k < 3; ++k) {
      const StepResult a = step(world, four, k), b = step(world, one, k);
      const std::string what = std::string(to_string(method)) + " step " + std::to_string(k);
      expect_same_step(b, a, what);
      EXPECT_EQ(b.schedule->omega, a.schedule->omega) << what;
      EXPECT_EQ(b.schedule->task_node_tests, a.schedule->task_node_tests) << what << ": the same tasks, in the same order";
      EXPECT_EQ(b.schedule->stage_pair_node_tests, a.schedule->stage_pair_node_tests) << what;
      EXPECT_EQ(b.schedule->stage_levels, a.schedule->stage_levels) << what;
      split = split || a.schedule->split > 0;
    }
    EXPECT_TRUE(split) << to_string(method) << ": a cut with a weight-driven stage, or the test shows little";
  }
  EngineOptions bad;
  bad.profile = true;  // the tests read the schedule
  bad.plan_threads = -1;
  EXPECT_THROW(Engine{bad}, Error);
  bad.plan_threads = 2000;
  EXPECT_THROW(Engine{bad}, Error);
}

TEST_F(EngineScenes, PredictedStepTimeReplaysTheMeasuredPieces) {
  const World world(parse_scene(R"({"query": {"kind": "contact", "tolerance": 0.05}, "objects": [
      {"name": "a", "mesh": "torus.off"}, {"name": "b", "mesh": "sphere.off", "position": [0.8, 0, 0], "motion": {"type": "velocity"}},
      {"name": "c", "mesh": "cube.off", "position": [-0.6, 0.5, 0], "motion": {"type": "velocity"}}]})",
                                dir, "predicted.json"));
  for (const Method method :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    EngineOptions options;
    options.profile = true;  // the tests read the schedule
    options.method = method;
    options.threads = 1;
    options.plan_threads = 8;
    options.stealing_depth = 2;
    options.timeline = true;
    Engine engine(options);
    const StepResult s = step(world, engine, 0);
    const std::string what(to_string(method));
    // On one core the replay gives back the step as measured: every piece once, the rest serial.
    const double measured = s.broad_ms + s.narrow_ms + s.reduce_ms;
    EXPECT_NEAR(predicted_step_ms(s, method, 1), measured, 1e-9 * measured) << what;
    // More cores never take longer; the serial rest and the longest piece bound it from below.
    double longest = 0.0;
    for (const TaskSpan& t : s.schedule->timeline) {
      if (t.phase == TaskSpan::Phase::traverse) longest = std::max(longest, t.end_ms - t.start_ms);
    }
    const double four = predicted_step_ms(s, method, 4);
    EXPECT_LE(four, measured * (1 + 1e-12)) << what;
    EXPECT_LE(predicted_step_ms(s, method, 8), four * (1 + 1e-12)) << what;
    EXPECT_GE(four, longest) << what;
  }
  // Without a timeline there is nothing to replay.
  EngineOptions quiet;
  quiet.profile = true;  // the tests read the schedule
  quiet.method = Method::hybrid;
  quiet.threads = 1;
  Engine engine(quiet);
  EXPECT_THROW((void)predicted_step_ms(step(world, engine, 0), Method::hybrid, 4), Error);
}

TEST(LoadBalanceSimulation, PredictedStepTimeArithmetic) {
  // A hand-made step: a split pair whose stage took 2 ms for 20 node tests (its root test, then
  // levels of 4 and 15 tests), four run-time tasks of 1 ms, the pair's finalization 0.4 ms over
  // 256 candidates (two chunks: a proximity query's), and 0.45 ms outside every piece (broad phase
  // 0.1, the rest 0.35).
  StepResult step;
  step.pair_records.resize(2);
  step.pair_records[0].candidates = 256;
  step.stats.node_tests = 100;
  auto record = std::make_shared<ScheduleRecord>();
  ScheduleRecord& r = *record;
  step.schedule = record;
  r.kind = QueryKind::proximity;
  r.stage_pair_node_tests = {20};
  r.stage_levels = {{4}, {8, 7}};
  r.stage_level_pair = {0, 0};
  r.task_node_tests = {20, 20, 20, 20};
  r.timeline.push_back(TaskSpan{0, 0.0, 2.0, TaskSpan::Phase::stage, 0});
  for (std::uint32_t t = 0; t < 4; ++t) r.timeline.push_back(TaskSpan{0, 2.0 + t, 3.0 + t, TaskSpan::Phase::traverse, t});
  r.timeline.push_back(TaskSpan{0, 6.0, 6.4, TaskSpan::Phase::finalize, 0});
  step.broad_ms = 0.1;
  step.narrow_ms = 6.7;
  step.reduce_ms = 0.05;
  EXPECT_NEAR(predicted_step_ms(step, Method::hybrid, 1), 6.85, 1e-12) << "one core: the step as measured";
  // Four cores: the stage's levels in turn (0.1 ms a test: 1 + 4 + 8 tests deep), the four tasks at
  // once, the two finalization chunks at once.
  EXPECT_NEAR(predicted_step_ms(step, Method::hybrid, 4), 0.45 + 1.3 + 1.0 + 0.2, 1e-12);
  // An interference result of 256 pairs is sorted on one thread: its finalization is one piece.
  r.kind = QueryKind::interference;
  EXPECT_NEAR(predicted_step_ms(step, Method::hybrid, 4), 0.45 + 1.3 + 1.0 + 0.4, 1e-12);
  r.kind = QueryKind::proximity;
  // The traversal took 0.4 ms more than its four tasks (handing them out): each thread hands out
  // the tasks it takes, so that time is spread over the cores, not serial.
  r.traverse_ms = 4.4;
  step.narrow_ms += 0.4;
  EXPECT_NEAR(predicted_step_ms(step, Method::hybrid, 1), 7.25, 1e-12);
  EXPECT_NEAR(predicted_step_ms(step, Method::hybrid, 4), 0.45 + 1.3 + 1.0 + 0.1 + 0.2, 1e-12);
  // 0.5 ms of the stage was serial (taking its levels' outcomes in order): on the stage's path
  // whole, the other 1.5 ms shared by its 20 tests (0.075 ms each, 1 + 4 + 8 deep).
  r.stage_serial_ms = {0.5};
  EXPECT_NEAR(predicted_step_ms(step, Method::hybrid, 1), 7.25, 1e-12);
  EXPECT_NEAR(predicted_step_ms(step, Method::hybrid, 4), 0.45 + (0.075 * 13 + 0.5) + 1.0 + 0.1 + 0.2, 1e-12);
  EXPECT_THROW((void)predicted_step_ms(step, Method::hybrid, 0), Error);
}

TEST(EngineOptionsValidation, RejectsBadValues) {
  EngineOptions options;
  options.profile = true;  // the tests read the schedule
  options.threads = -1;
  EXPECT_THROW(Engine{options}, Error);
  options.threads = 5000;
  EXPECT_THROW(Engine{options}, Error);
  options.threads = 0;
  EXPECT_GE(Engine{options}.threads(), 1);
  options.method = Method::sequential;
  options.threads = 4;
  EXPECT_EQ(Engine{options}.threads(), 1) << "sequential runs on one thread";
  options.method = Method::hybrid;
  options.beta = 0;
  EXPECT_THROW(Engine{options}, Error);
  options.beta = 2;
  options.epsilon = -0.1;
  EXPECT_THROW(Engine{options}, Error);
  EXPECT_THROW((void)parse_method("calibrated"), Error);
  EXPECT_EQ(parse_method("stealing"), Method::stealing);
}

/// Three in-memory objects (no file): a torus, a sphere moving through it, a box beside them.
Frame memory_frame(double t) {
  Frame frame;
  frame.models = {build_model(make_torus(0.8, 0.25, 24, 12)), build_model(make_sphere(0.5, 12, 16)),
                  build_model(make_box(0.3, 0.3, 0.3, 2))};
  frame.poses = {Pose{}, Pose::from_values(-1.2 + t, 0.1, 0.0, 1, 0, 0, 0), Pose::from_values(1.0, 0.9, 0.0, 1, 0, 0, 0)};
  frame.pairs = {ObjectPair{0, 1}, ObjectPair{0, 2}, ObjectPair{1, 2}};
  frame.request.kind = QueryKind::contact;
  frame.request.tolerance = 0.05;
  return frame;
}

TEST(EngineFrames, InMemoryFramesGiveThePairwiseAnswerWithEveryMethod) {
  const Frame base = memory_frame(0.0);
  std::size_t contacts = 0;
  for (const Method method :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    EngineOptions options;
    options.profile = true;  // the tests read the schedule
    options.method = method;
    options.threads = 3;
    options.stealing_depth = 2;
    Engine engine(options);
    for (int k = 0; k < 6; ++k) {
      Frame frame = base;  // the same models every frame; only the sphere's pose changes
      frame.poses[1] = Pose::from_values(-1.2 + 0.4 * k, 0.1, 0.0, 1, 0, 0, 0);
      const StepResult got = engine.step(frame);
      ASSERT_EQ(got.pair_records.size(), frame.pairs.size());
      std::size_t at = 0;
      for (std::size_t i = 0; i < frame.pairs.size(); ++i) {
        const ObjectPair t = frame.pairs[i];
        const QueryResult want = query(*frame.models[t.a], frame.poses[t.a], *frame.models[t.b], frame.poses[t.b], frame.request);
        ASSERT_EQ(got.pair_records[i].contacts, want.contacts.size()) << to_string(method) << " frame " << k << " pair " << i;
        for (const Contact& c : want.contacts) {
          const Contact& g = got.contacts[at++];
          ASSERT_EQ(g.object_a, t.a);
          ASSERT_EQ(g.object_b, t.b);
          ASSERT_EQ(g.tri_a, c.tri_a);
          ASSERT_EQ(g.tri_b, c.tri_b);
          ASSERT_EQ(g.point_a, c.point_a);
          ASSERT_EQ(g.normal, c.normal);
          ASSERT_EQ(g.distance, c.distance);
        }
      }
      ASSERT_EQ(at, got.contacts.size());
      contacts += at;
    }
  }
  EXPECT_GT(contacts, 0u) << "a test that compares empty answers proves nothing";
}

TEST(EngineFrames, AFrameOfOnePairGivesThatPairsAnswerWithEveryMethod) {
  // One pair: the step's contacts are the pair's (moved, not copied, into the step), as the query
  // gives them, with the frame's object ids.
  // The box first, so that the pair's object ids (1, 2) are not the query's own (0, 1).
  Frame frame = memory_frame(0.4);  // the torus's tube through the sphere
  std::swap(frame.models[0], frame.models[2]);
  std::swap(frame.poses[0], frame.poses[2]);
  std::swap(frame.models[1], frame.models[2]);
  std::swap(frame.poses[1], frame.poses[2]);
  frame.pairs = {ObjectPair{1, 2}};
  frame.request.kind = QueryKind::interference;
  const QueryResult want = query(*frame.models[1], frame.poses[1], *frame.models[2], frame.poses[2], frame.request);
  ASSERT_GT(want.contacts.size(), 0u) << "a test that compares empty answers proves nothing";
  for (const Method method :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    EngineOptions options;
    options.method = method;
    options.threads = 2;
    Engine engine(options);
    for (int k = 0; k < 2; ++k) {
      const StepResult got = engine.step(frame);
      ASSERT_EQ(got.pair_records.size(), 1u);
      EXPECT_EQ(got.pair_records[0].contacts, want.contacts.size()) << to_string(method);
      EXPECT_EQ(got.stats.node_tests, got.pair_records[0].stats.node_tests) << to_string(method);
      ASSERT_EQ(got.contacts.size(), want.contacts.size()) << to_string(method);
      for (std::size_t i = 0; i < want.contacts.size(); ++i) {
        const Contact &g = got.contacts[i], &c = want.contacts[i];
        ASSERT_EQ(g.object_a, 1u) << to_string(method);
        ASSERT_EQ(g.object_b, 2u) << to_string(method);
        ASSERT_EQ(g.tri_a, c.tri_a) << to_string(method) << " contact " << i;
        ASSERT_EQ(g.tri_b, c.tri_b) << to_string(method) << " contact " << i;
        ASSERT_EQ(g.point_a, c.point_a);
        ASSERT_EQ(g.normal, c.normal);
        ASSERT_EQ(g.distance, c.distance);
      }
    }
  }
}

TEST(EngineFrames, EveryMethodRecordsItsTraversalAndFinalization) {
  const Frame frame = memory_frame(0.8);
  for (const Method method :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    EngineOptions options;
    options.profile = true;  // the tests read the schedule
    options.method = method;
    options.threads = 2;
    Engine engine(options);
    for (int k = 0; k < 2; ++k) {  // the second step: a posteriori and hybrid have history
      const StepResult got = engine.step(frame);
      const ScheduleRecord& r = *got.schedule;
      ASSERT_GT(got.stats.node_tests, 0u);
      EXPECT_GT(r.traverse_ms, 0.0) << to_string(method);
      EXPECT_GT(r.finalize_ms, 0.0) << to_string(method);
      EXPECT_FALSE(r.task_node_tests.empty()) << to_string(method);
      EXPECT_FALSE(r.thread_node_tests.empty()) << to_string(method);
      if (method != Method::stealing) {
        EXPECT_GT(r.calibrate_ms, 0.0) << to_string(method) << ": planning is timed too";
        EXPECT_EQ(r.generated, r.task_node_tests.size()) << to_string(method);
      }
    }
  }
}

TEST(EngineFrames, AFrameOfManyPairsGivesEachPairItsOwnAnswer) {
  // 17 objects, every one of the 136 pairs asked for: more pairs than one chunk of the step's
  // context building, so the contexts are made on several threads; each pair's result must still
  // be the pairwise query of its own two objects.
  Frame frame;
  const std::shared_ptr<const Model> sphere = build_model(make_sphere(0.5, 10, 14));
  const std::shared_ptr<const Model> box = build_model(make_box(0.4, 0.3, 0.35, 2));
  for (int i = 0; i < 17; ++i) {
    frame.models.push_back(i % 3 == 0 ? box : sphere);
    const double angle = 0.37 * i;
    frame.poses.push_back(Pose::from_values(0.45 * (i % 4), 0.5 * (i / 4), 0.05 * i, std::cos(angle), 0, std::sin(angle), 0));
  }
  for (std::uint32_t a = 0; a < 17; ++a) {
    for (std::uint32_t b = a + 1; b < 17; ++b) frame.pairs.push_back(ObjectPair{a, b});
  }
  frame.request.kind = QueryKind::proximity;
  frame.request.tolerance = 0.02;
  std::vector<std::size_t> want;
  std::size_t total = 0;
  for (const ObjectPair& t : frame.pairs) {
    want.push_back(
        query(*frame.models[t.a], frame.poses[t.a], *frame.models[t.b], frame.poses[t.b], frame.request).contacts.size());
    total += want.back();
  }
  ASSERT_GT(total, 0u) << "some pairs are within the tolerance";
  ASSERT_GT(std::count(want.begin(), want.end(), std::size_t{0}), 0) << "and some are not";
  for (const Method method : {Method::exploitation, Method::stealing, Method::hybrid}) {
    EngineOptions options;
    options.profile = true;  // the tests read the schedule
    options.method = method;
    options.threads = 3;
    Engine engine(options);
    for (int repeat = 0; repeat < 2; ++repeat) {  // the second step reuses the contexts' storage
      const StepResult got = engine.step(frame);
      ASSERT_EQ(got.pair_records.size(), frame.pairs.size());
      for (std::size_t i = 0; i < frame.pairs.size(); ++i) {
        EXPECT_EQ(got.pair_records[i].contacts, want[i]) << to_string(method) << " pair " << i;
      }
    }
  }
}

TEST(EngineFrames, ForgetDropsTheTemporalState) {
  EngineOptions options;
  options.profile = true;  // the tests read the schedule
  options.method = Method::aposteriori;
  options.threads = 2;
  options.beta = 8;
  Engine engine(options);
  Frame frame = memory_frame(0.9);
  frame.pairs = {ObjectPair{0, 1}};
  EXPECT_EQ(engine.step(frame).schedule->taboo, 0u) << "nothing to go on at the first step";
  EXPECT_GT(engine.step(frame).schedule->taboo, 0u) << "last step's contacts give sub-task roots";
  engine.forget();
  EXPECT_EQ(engine.step(frame).schedule->taboo, 0u) << "forgotten";
}

TEST(EngineFrames, APairGivenOtherModelsWithoutForgetGetsThePairwiseAnswer) {
  // The a posteriori method splits a pair by the triangle pairs it reported last step, by last
  // step's models' ids. Here the pair's models become two 12-triangle boxes without forget(): the
  // old ids are past their triangles (they were read past the end of the boxes' tables).
  EngineOptions options;
  options.method = Method::aposteriori;
  options.threads = 2;
  options.beta = 8;
  options.profile = true;
  Engine engine(options);
  Frame frame = memory_frame(0.9);
  frame.pairs = {ObjectPair{0, 1}};
  (void)engine.step(frame);
  ASSERT_GT(engine.step(frame).schedule->taboo, 0u) << "last step's contacts split the pair";
  frame.models[0] = build_model(make_box(0.3, 0.3, 0.3, 1));
  frame.models[1] = build_model(make_box(0.3, 0.3, 0.3, 1));
  frame.poses[1] = Pose::from_values(-0.61, 0.1, 0.0, 1, 0, 0, 0);  // faces 0.01 apart, within the tolerance
  const StepResult got = engine.step(frame);
  const QueryResult want = query(*frame.models[0], frame.poses[0], *frame.models[1], frame.poses[1], frame.request);
  ASSERT_FALSE(want.contacts.empty());
  ASSERT_EQ(got.contacts.size(), want.contacts.size());
  for (std::size_t i = 0; i < want.contacts.size(); ++i) {
    EXPECT_EQ(got.contacts[i].tri_a, want.contacts[i].tri_a);
    EXPECT_EQ(got.contacts[i].tri_b, want.contacts[i].tri_b);
    EXPECT_EQ(got.contacts[i].point_a, want.contacts[i].point_a);
    EXPECT_EQ(got.contacts[i].distance, want.contacts[i].distance);
  }
}

TEST(EngineFrames, AContactQueryOnModelsWithoutAdjacencyIsRefusedBeforeAnyWork) {
  BuildOptions bare;
  bare.adjacency = false;
  Frame frame = memory_frame(0.0);
  frame.models[1] = build_model(make_sphere(0.5, 12, 16), bare);
  Engine engine;
  try {
    (void)engine.step(frame);
    FAIL() << "a contact query needs adjacency";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "contact query: object 1's model was built without adjacency (BuildOptions::adjacency), which the contacts' "
              "reduction needs");
  }
  const std::vector<Pose> fixed{Pose{}}, poses{Pose{}, Pose{}};
  try {
    (void)engine.query_many(*frame.models[0], fixed, *frame.models[1], poses, frame.request);
    FAIL() << "a contact batch needs adjacency";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "contact query: model B was built without adjacency (BuildOptions::adjacency), which the contacts' reduction "
              "needs");
  }
  // A single query and the brute force refuse it before any work too, naming both models where both lack it.
  const auto bare_a = build_model(make_sphere(0.5, 12, 16), bare);
  for (const bool brute : {false, true}) {
    try {
      (void)(brute ? query_brute_force : query)(*bare_a, Pose{}, *frame.models[1], Pose{}, frame.request);
      FAIL() << "a contact query needs adjacency";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()),
                "contact query: model A and model B were built without adjacency (BuildOptions::adjacency), which the "
                "contacts' reduction needs");
    }
  }
}

TEST(EngineFrames, BadFramesAreRejectedWithTheProblem) {
  Engine engine;
  const auto message = [&](const Frame& f) {
    try {
      (void)engine.step(f);
    } catch (const Error& e) {
      EXPECT_EQ(e.source(), "frame") << e.what();
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  Frame f = memory_frame(0.0);
  f.poses.pop_back();
  EXPECT_NE(message(f).find("3 models but 2 poses"), std::string::npos) << message(f);
  f = memory_frame(0.0);
  f.models[2] = nullptr;
  EXPECT_NE(message(f).find("object 2 has no model"), std::string::npos) << message(f);
  f = memory_frame(0.0);
  f.poses[1].translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(f).find("pose of object 1: pose has a non-finite value"), std::string::npos) << message(f);
  f = memory_frame(0.0);
  f.poses[2].rotation.coeffs() *= 2.0;
  EXPECT_NE(message(f).find("pose of object 2: quaternion is not unit length"), std::string::npos) << message(f);
  f = memory_frame(0.0);
  f.pairs = {ObjectPair{0, 3}};
  EXPECT_NE(message(f).find("a < b < 3"), std::string::npos) << message(f);
  f.pairs = {ObjectPair{1, 1}};
  EXPECT_NE(message(f).find("a < b < 3"), std::string::npos) << message(f);
  f.pairs = {ObjectPair{1, 2}, ObjectPair{0, 1}};
  EXPECT_NE(message(f).find("sorted and distinct"), std::string::npos) << message(f);
  f.pairs = {ObjectPair{0, 1}, ObjectPair{0, 1}};
  EXPECT_NE(message(f).find("sorted and distinct"), std::string::npos) << message(f);
  f = memory_frame(0.0);
  f.request.tolerance = -1;
  EXPECT_THROW((void)engine.step(f), Error);
  f = memory_frame(0.0);
  f.pairs.clear();
  const StepResult none = engine.step(f);
  EXPECT_TRUE(none.contacts.empty()) << "no pairs: an empty step, not an error";
}

}  // namespace
}  // namespace caliber
