// World::sweep follows the scene's own motion: turns of more than half a turn a step, keyframes
// inside a step, the scene's groups; and a vertex no triangle uses moves nothing in any sweep.
// Checked by dense exact sampling: where the sampled motion overlaps, the sweep reports a contact
// no later.

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/scene.h"
#include "caliber/sweep.h"
#include "caliber/world.h"
#include "support/temp_dir.h"

namespace caliber {
namespace {

class WorldSweep : public ::testing::Test {
 protected:
  void SetUp() override {
    save_off(make_box(1.0, 0.02, 0.02, 1), dir / "rod.off");
    save_off(make_box(0.1, 0.1, 0.1, 1), dir / "block.off");
    Mesh arm = make_box(0.475, 0.02, 0.02, 1);  // a bar from x = 0.05 to 1: on one side of its origin
    for (auto& v : arm.vertices) v.x() += 0.525;
    save_off(arm, dir / "arm.off");
  }

  World world(const std::string& json) const { return World(parse_scene(json, dir, "world_sweep_test.json")); }

  test::TempDir temp{"world_sweep"};
  const std::filesystem::path& dir = temp.path();
};

/// The first of `samples` evenly spaced times of step k (a fraction of the step) at which objects
/// a and b overlap, following the scene's motions exactly; none if they never do.
std::optional<double> first_sampled_overlap(const World& world, int k, std::uint32_t a, std::uint32_t b, int samples) {
  const Scene& s = world.scene();
  QueryRequest interference;
  interference.kind = QueryKind::interference;
  interference.max_pairs = 1;
  for (int i = 0; i <= samples; ++i) {
    const double f = static_cast<double>(i) / samples;
    const double t = (k + f) * s.dt;
    const Pose pa = pose_at(s.objects[a].pose, s.objects[a].motion, t);
    const Pose pb = pose_at(s.objects[b].pose, s.objects[b].motion, t);
    if (!query(world.model(a), pa, world.model(b), pb, interference).contacts.empty()) return f;
  }
  return std::nullopt;
}

/// Every pair the sampling finds overlapping is reported in contact no later than the sample, and
/// every reported contact is within the sweep's tolerance; returns the reported pairs.
std::vector<PairSweep> check_against_sampling(const World& world, int k, Engine& engine) {
  const std::vector<PairSweep> found = world.sweep(k, engine);
  const auto n = static_cast<std::uint32_t>(world.object_count());
  for (std::uint32_t a = 0; a < n; ++a) {
    for (std::uint32_t b = a + 1; b < n; ++b) {
      const std::optional<double> overlap = first_sampled_overlap(world, k, a, b, 720);
      const PairSweep* reported = nullptr;
      for (const PairSweep& p : found) reported = p.pair.a == a && p.pair.b == b ? &p : reported;
      if (!overlap) continue;
      EXPECT_NE(reported, nullptr) << "pair (" << a << ", " << b << ") overlaps at " << *overlap << " of step " << k;
      if (reported == nullptr) continue;
      EXPECT_EQ(reported->result.status, SweepStatus::contact);
      EXPECT_LE(reported->result.time, *overlap) << "late: pair (" << a << ", " << b << ")";
    }
  }
  for (const PairSweep& p : found) {
    EXPECT_GE(p.result.time, 0.0);
    EXPECT_LE(p.result.time, 1.0);
  }
  return found;
}

TEST_F(WorldSweep, ARodTurningMoreThanHalfATurnAStepHitsWhatItsOwnTurnPasses) {
  // 400 rad/s for 0.01 s: 229 degrees counterclockwise. The block sits at 90 degrees; the shorter
  // arc between the step's two poses (131 degrees clockwise) never passes it.
  const World w = world(R"({"steps": 3, "dt": 0.01, "objects": [
      {"name": "rod", "mesh": "rod.off", "motion": {"type": "velocity", "angular": [0, 0, 400]}},
      {"name": "block", "mesh": "block.off", "position": [0, 0.7, 0]}]})");
  Engine engine;
  const std::vector<PairSweep> found = check_against_sampling(w, 0, engine);
  ASSERT_EQ(found.size(), 1u);
  // The rod's end reaches the block's near corner (0.1, 0.6) at about atan2(0.6, 0.1) = 80.5
  // degrees of the step's 229.
  EXPECT_GT(found[0].result.time, 0.33);
  EXPECT_LT(found[0].result.time, 0.36);
  for (int k = 1; k < 3; ++k) (void)check_against_sampling(w, k, engine);
  // Every method and thread count gives the same answer.
  for (const Method m : {Method::sequential, Method::stealing, Method::hybrid}) {
    EngineOptions o;
    o.method = m;
    o.threads = 2;
    Engine other(o);
    const std::vector<PairSweep> again = w.sweep(0, other);
    ASSERT_EQ(again.size(), 1u);
    EXPECT_EQ(again[0].result.time, found[0].result.time);
  }
}

TEST_F(WorldSweep, FastRandomSpinsAgreeWithDenseSampling) {
  for (int seed = 0; seed < 6; ++seed) {
    const double w = 150.0 + 60.0 * seed;  // 86 to 258 degrees a step
    const std::string json = R"({"steps": 2, "dt": 0.01, "objects": [
      {"name": "rod", "mesh": "rod.off", "orientation": [1, 0, 0, )" +
                             std::to_string(0.1 * seed) + R"(], "motion": {"type": "velocity", "angular": [)" +
                             std::to_string(0.2 * w) + ", " + std::to_string(-0.3 * w) + ", " + std::to_string(w) +
                             R"(], "linear": [0.5, 0, 0]}},
      {"name": "b1", "mesh": "block.off", "position": [0, 0.7, 0]},
      {"name": "b2", "mesh": "block.off", "position": [-0.6, -0.3, 0.05]},
      {"name": "b3", "mesh": "block.off", "position": [0.3, -0.8, -0.05]}]})";
    const World world_of_seed = world(json);
    Engine engine;
    for (int k = 0; k < 2; ++k) (void)check_against_sampling(world_of_seed, k, engine);
  }
}

TEST_F(WorldSweep, KeyframesInsideAStepAreFollowed) {
  // The rod goes through the block and back within one step: the step's two poses are the same.
  const World w = world(R"({"steps": 2, "dt": 0.01, "objects": [
      {"name": "rod", "mesh": "rod.off", "motion": {"type": "keyframes", "keys": [
          {"time": 0, "position": [0, -1, 0]}, {"time": 0.005, "position": [0, 1, 0]},
          {"time": 0.01, "position": [0, -1, 0]}]}},
      {"name": "block", "mesh": "block.off"}]})");
  Engine engine;
  const std::vector<PairSweep> found = check_against_sampling(w, 0, engine);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].result.status, SweepStatus::contact);
  EXPECT_LT(found[0].result.time, 0.5);
  EXPECT_TRUE(check_against_sampling(w, 1, engine).empty()) << "after the last key the rod holds still, away";
}

TEST_F(WorldSweep, TheScenesGroupsApplyToSweeps) {
  const std::string objects = R"("objects": [
      {"name": "rod", "mesh": "rod.off", "group": 1, "position": [0, -1, 0],
       "motion": {"type": "velocity", "linear": [0, 200, 0]}},
      {"name": "block", "mesh": "block.off", "group": 2}]})";
  Engine engine;
  const World apart = world(R"({"dt": 0.01, "groups": {"compatible": [[1, 1], [2, 2]]}, )" + objects);
  EXPECT_TRUE(apart.sweep(0, engine).empty()) << "groups 1 and 2 never touch";
  const World together = world(R"({"dt": 0.01, "groups": {"compatible": [[1, 2]]}, )" + objects);
  EXPECT_EQ(together.sweep(0, engine).size(), 1u);
  // A request's own table wins over the scene's.
  GroupCompatibility none;
  none.compatible.fill(0);
  SweepRequest request;
  request.groups = &none;
  EXPECT_TRUE(together.sweep(0, engine, request).empty());
}

TEST(SweepGroups, PairAndEngineSweepsHonourTheRequestsGroups) {
  Mesh a = make_box(0.5, 0.5, 0.5, 1), b = make_box(0.5, 0.5, 0.5, 1);
  a.groups.assign(a.triangles.size(), 1);
  b.groups.assign(b.triangles.size(), 2);
  const auto ma = build_model(std::move(a)), mb = build_model(std::move(b));
  SweptPose still, through;
  through.start.translation = Eigen::Vector3d(-3, 0, 0);
  through.end.translation = Eigen::Vector3d(3, 0, 0);
  GroupCompatibility apart;
  apart.compatible.fill(0);
  apart.compatible[1] = 1u << 1;
  apart.compatible[2] = 1u << 2;
  SweepRequest request;
  EXPECT_EQ(sweep(*ma, still, *mb, through, request).status, SweepStatus::contact);
  request.groups = &apart;
  EXPECT_EQ(sweep(*ma, still, *mb, through, request).status, SweepStatus::free);
  Engine engine;
  EXPECT_TRUE(engine.sweep({ma, mb}, {still.start, through.start}, {still.end, through.end}, request).empty());
  const SweptPose motions[] = {through};
  EXPECT_EQ(engine.sweep_many(*ma, {&still, 1}, *mb, motions, request)[0].status, SweepStatus::free);
}

TEST(SweepStrayVertex, AVertexNoTriangleUsesMovesNothing) {
  // Two still cubes 0.5 apart; one mesh carries a vertex at (1e6, 0, 0) that no triangle uses.
  Mesh stray = make_box(0.5, 0.5, 0.5, 1);
  stray.vertices.emplace_back(1e6, 0.0, 0.0);
  const auto ma = build_model(make_box(0.5, 0.5, 0.5, 1)), mb = build_model(std::move(stray));
  SweptPose a, b;
  b.start.translation = b.end.translation = Eigen::Vector3d(1.5, 0, 0);
  const SweepResult r = sweep(*ma, a, *mb, b);
  EXPECT_EQ(r.status, SweepStatus::free);
  Engine engine;
  EXPECT_TRUE(engine.sweep({ma, mb}, {a.start, b.start}, {a.end, b.end}).empty());
  const SweptPose motions[] = {b};
  EXPECT_EQ(engine.sweep_many(*ma, {&a, 1}, *mb, motions)[0].status, SweepStatus::free);
  // Turning still only about what the triangles span: a quarter turn of the cube 0.5 away.
  b.end.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(sweep(*ma, a, *mb, b).status, SweepStatus::free);
}

TEST_F(WorldSweep, ATurnTooFastToFollowIsAnErrorNamingTheObject) {
  const World w = world(R"({"dt": 0.01, "objects": [
      {"name": "spinner", "mesh": "rod.off", "motion": {"type": "velocity", "angular": [0, 0, 1e7]}},
      {"name": "block", "mesh": "block.off", "position": [0, 0.7, 0]}]})");
  Engine engine;
  try {
    (void)w.sweep(0, engine);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'spinner'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("smaller dt"), std::string::npos) << e.what();
  }
}

TEST(KeyframeLookup, ThePoseBetweenAnyTwoOfManyKeysIsTheirInterpolation) {
  Motion m;
  m.type = Motion::Type::keyframes;
  for (int i = 0; i < 1000; ++i) {
    Keyframe k;
    k.time = 0.5 * i;
    k.position = Eigen::Vector3d(i * i, -i, 0.25 * i);
    m.keys.push_back(k);
  }
  for (int i = 0; i + 1 < 1000; i += 37) {
    for (const double s : {0.0, 0.25, 0.5, 1.0}) {
      const double t = 0.5 * i + 0.5 * s;
      const Eigen::Vector3d want = (1.0 - s) * m.keys[i].position + s * m.keys[i + 1].position;
      EXPECT_LT((pose_at(Pose{}, m, t).translation - want).norm(), 1e-9) << "t = " << t;
    }
  }
  EXPECT_EQ(pose_at(Pose{}, m, -1.0).translation, m.keys.front().position);
  EXPECT_EQ(pose_at(Pose{}, m, 1e9).translation, m.keys.back().position);
}

TEST_F(WorldSweep, AHalfTurnBetweenKeysIsTurnedTheScenesWay) {
  // Keys at whole steps; the second interval is an exact half turn about z, and the first ends on
  // the negation of its start quaternion. The sweep turns the arm as pose_at does (through the
  // block at +y), whichever sign the interval's start pose comes in.
  const World w = world(R"({"steps": 3, "dt": 1.0, "objects": [
      {"name": "arm", "mesh": "arm.off", "motion": {"type": "keyframes", "keys": [
          {"time": 0, "orientation": [-1, 0, 0, 0]}, {"time": 1, "orientation": [1, 0, 0, 0]},
          {"time": 2, "orientation": [0, 0, 0, 1]}]}},
      {"name": "block", "mesh": "block.off", "position": [0, 0.7, 0]}]})");
  Engine engine;
  EXPECT_TRUE(check_against_sampling(w, 0, engine).empty());
  const std::vector<PairSweep> found = check_against_sampling(w, 1, engine);
  ASSERT_EQ(found.size(), 1u) << "the arm passes the block at a quarter turn";
  EXPECT_EQ(found[0].result.status, SweepStatus::contact);
}

TEST_F(WorldSweep, AFastTurnCutsOnlyItsOwnPairs) {
  // A cube spinning fast far from two slow neighbours: their pair is swept whole, as without it.
  const std::string objects = R"(
      {"name": "a", "mesh": "block.off", "motion": {"type": "velocity", "linear": [20, 0, 0]}},
      {"name": "b", "mesh": "block.off", "position": [0.35, 0.05, 0]})";
  const World alone = world(R"({"dt": 0.01, "objects": [)" + objects + "]}");
  const World with = world(R"({"dt": 0.01, "objects": [)" + objects + R"(,
      {"name": "spinner", "mesh": "rod.off", "position": [50, 50, 0], "motion": {"type": "velocity", "angular": [0, 0, 5000]}}]})");
  Engine engine;
  const std::vector<PairSweep> base = alone.sweep(0, engine);
  const std::vector<PairSweep> got = with.sweep(0, engine);
  ASSERT_EQ(base.size(), 1u);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].result.time, base[0].result.time);
  EXPECT_EQ(got[0].result.queries, base[0].result.queries) << "not once per piece of the spinner's 32";
}

}  // namespace
}  // namespace caliber
