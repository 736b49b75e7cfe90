// The world: shared models, broad phase against the all-pairs check, steps against the oracle.

#include <filesystem>
#include <vector>
#include <limits>
#include <functional>
#include <fstream>
#include <random>
#include <set>
#include <thread>

#include <gtest/gtest.h>

#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "support/random_poses.h"
#include "support/temp_dir.h"
#include "support/reference_step.h"
#include "support/results.h"

namespace caliber {
namespace {

/// A temporary folder with a cube, a sphere and a torus saved as OFF files.
class WorldFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    save_off(make_box(0.5, 0.5, 0.5, 2), dir / "cube.off");
    save_off(make_box(0.5, 0.5, 0.5, 2), dir / "cube_copy.off");
    save_off(make_sphere(0.6, 8, 12), dir / "sphere.off");
    save_off(make_torus(0.8, 0.25, 12, 8), dir / "torus.off");
  }

  Scene scene(const std::string& json) const { return parse_scene(json, dir, "world_test.json"); }

  test::TempDir temp{"world"};
  const std::filesystem::path& dir = temp.path();
};

/// Each step's contacts must equal, bit for bit, the oracle run on every object pair.
void expect_steps_match_oracle(const World& world, int steps) {
  for (int k = 0; k < steps; ++k) {
    const StepResult s = test::reference_step(world, k);
    const std::vector<Pose> poses = world.poses_at(k);
    std::vector<Contact> want;
    for (std::uint32_t a = 0; a < world.object_count(); ++a) {
      for (std::uint32_t b = a + 1; b < world.object_count(); ++b) {
        if (world.scene().objects[a].motion.type == Motion::Type::fixed &&
            world.scene().objects[b].motion.type == Motion::Type::fixed) {
          continue;
        }
        const QueryResult r = query_brute_force(world.model(a), poses[a], world.model(b), poses[b], world.request());
        for (const Contact& c : test::between(r, a, b)) want.push_back(c);
      }
    }
    ASSERT_EQ(s.contacts.size(), want.size()) << "step " << k;
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(s.contacts[i].object_a, want[i].object_a) << "step " << k;
      ASSERT_EQ(s.contacts[i].object_b, want[i].object_b) << "step " << k;
      ASSERT_EQ(s.contacts[i].tri_a, want[i].tri_a) << "step " << k;
      ASSERT_EQ(s.contacts[i].tri_b, want[i].tri_b) << "step " << k;
      ASSERT_EQ(s.contacts[i].distance, want[i].distance) << "step " << k;
      ASSERT_EQ(s.contacts[i].point_a, want[i].point_a) << "step " << k;
      ASSERT_EQ(s.contacts[i].normal, want[i].normal) << "step " << k;
    }
  }
}

TEST_F(WorldFiles, CubeSlidingIntoCubeHasContactsExactlyWhenTheyOverlap) {
  // B moves along x from a gap of 0.5 into A at 0.1 per step: faces meet at step 5.
  const World world(scene(R"({"steps": 10, "dt": 1, "objects": [
      {"name": "a", "mesh": "cube.off"},
      {"name": "b", "mesh": "cube.off", "position": [1.5, 0.25, 0.125], "motion": {"type": "velocity", "linear": [-0.125, 0, 0]}}]})"));
  EXPECT_EQ(world.distinct_models(), 1u);
  for (int k = 0; k < 10; ++k) {
    const StepResult s = test::reference_step(world, k);
    const double gap = 1.5 - 0.125 * k - 1.0;  // exact in binary
    EXPECT_EQ(s.contacts.empty(), gap > 0.0) << "step " << k << " gap " << gap;
  }
  expect_steps_match_oracle(world, 10);
}

TEST_F(WorldFiles, ProximityAndContactStepsMatchTheOracle) {
  for (const char* kind : {"proximity", "contact"}) {
    const World world(scene(std::string(R"({"steps": 12, "dt": 0.1, "query": {"kind": ")") + kind +
                            R"(", "tolerance": 0.15, "angle": 40}, "objects": [
      {"name": "ring", "mesh": "torus.off", "motion": {"type": "velocity", "angular": [0, 0.5, 0]}},
      {"name": "ball", "mesh": "sphere.off", "position": [0.9, 0, 0.3], "motion": {"type": "velocity", "linear": [-0.2, 0, -0.1]}},
      {"name": "box", "mesh": "cube.off", "position": [-0.2, 1.0, 0], "motion": {"type": "keyframes", "keys": [
        {"time": 0, "position": [-0.2, 1.0, 0]}, {"time": 1.2, "position": [0.1, 0.4, 0.2], "orientation": [0.9, 0.1, 0.3, 0.2]}]}}]})"));
    expect_steps_match_oracle(world, 12);
    int with_contacts = 0;
    for (int k = 0; k < 12; ++k) with_contacts += test::reference_step(world, k).contacts.empty() ? 0 : 1;
    EXPECT_GT(with_contacts, 6) << kind;
  }
}

TEST_F(WorldFiles, SharedModelsGiveTheSameContactsAsSeparateOnes) {
  const std::string shared = R"({"steps": 8, "dt": 0.1, "query": {"kind": "proximity", "tolerance": 0.05}, "objects": [
      {"name": "a", "mesh": "cube.off"},
      {"name": "b", "mesh": "cube.off", "position": [0.8, 0.3, 0], "orientation": [0.95, 0.1, 0.2, 0.1], "motion": {"type": "velocity", "linear": [0.05, 0, 0]}},
      {"name": "c", "mesh": "cube.off", "position": [-0.7, -0.2, 0.4], "motion": {"type": "velocity", "angular": [0, 0, 1]}}]})";
  std::string separate = shared;
  separate.replace(separate.find("cube.off", separate.find("\"b\"")), 8, "cube_copy.off");
  const World one(scene(shared));
  const World two(scene(separate));
  EXPECT_EQ(one.distinct_models(), 1u);
  EXPECT_EQ(two.distinct_models(), 2u);
  int total = 0;
  for (int k = 0; k < 8; ++k) {
    const StepResult x = test::reference_step(one, k), y = test::reference_step(two, k);
    ASSERT_EQ(x.contacts.size(), y.contacts.size());
    for (std::size_t i = 0; i < x.contacts.size(); ++i) {
      EXPECT_EQ(x.contacts[i].tri_a, y.contacts[i].tri_a);
      EXPECT_EQ(x.contacts[i].point_b, y.contacts[i].point_b);
    }
    total += static_cast<int>(x.contacts.size());
  }
  EXPECT_GT(total, 0);
}

/// A host of two threads that runs every range itself, on the calling thread, and counts the calls
/// and the threads they came from.
class CountingHost final : public HostExecutor {
 public:
  int thread_count() const override { return 2; }
  void* enqueue(const Job& job, std::size_t count, std::size_t grain) override {
    ++calls;
    callers.insert(std::this_thread::get_id());
    for (std::size_t b = 0; b < count; b += grain) job(b, std::min(count, b + grain), 1);
    return nullptr;
  }
  void finish(void*) override { ADD_FAILURE() << "finish() of a call that ran inline"; }
  int calls = 0;
  std::set<std::thread::id> callers;
};

TEST_F(WorldFiles, ModelsBuildOnTheHostsThreadsAndAreTheSame) {
  const std::string json = R"({"steps": 12, "dt": 0.1, "query": {"kind": "proximity", "tolerance": 0.15}, "objects": [
      {"name": "ring", "mesh": "torus.off"},
      {"name": "ball", "mesh": "sphere.off", "position": [0.9, 0, 0.3], "motion": {"type": "velocity", "linear": [-0.2, 0, -0.1]}}]})";
  CountingHost host;
  WorldOptions options;
  options.host = &host;
  const World lent(scene(json), options);
  const World own(scene(json));
  EXPECT_EQ(host.calls, 2) << "one build per distinct model, each on the host";
  EXPECT_EQ(host.callers, std::set<std::thread::id>{std::this_thread::get_id()});
  ASSERT_EQ(lent.distinct_models(), own.distinct_models());
  for (std::size_t i = 0; i < lent.object_count(); ++i) {
    EXPECT_EQ(lent.model(i).node_count(), own.model(i).node_count());
    EXPECT_EQ(lent.model(i).height(), own.model(i).height());
    EXPECT_EQ(lent.model(i).has_adjacency(), own.model(i).has_adjacency());
  }
  int total = 0;
  for (int k = 0; k < 12; ++k) {
    const StepResult x = test::reference_step(lent, k), y = test::reference_step(own, k);
    ASSERT_EQ(x.contacts.size(), y.contacts.size()) << "step " << k;
    for (std::size_t i = 0; i < x.contacts.size(); ++i) {
      EXPECT_EQ(x.contacts[i].tri_b, y.contacts[i].tri_b);
      EXPECT_EQ(x.contacts[i].point_a, y.contacts[i].point_a);
    }
    total += static_cast<int>(x.contacts.size());
  }
  EXPECT_GT(total, 0);
  WorldOptions bad;
  bad.threads = -1;
  EXPECT_THROW(World(scene(json), bad), Error);
}

TEST_F(WorldFiles, BroadPhaseEqualsTheAllPairsCheckAndKeepsEveryTouchingPair) {
  std::mt19937_64 rng(9);
  const char* meshes[3] = {"cube.off", "sphere.off", "torus.off"};
  for (int trial = 0; trial < 8; ++trial) {
    std::string json = R"({"query": {"kind": "proximity", "tolerance": 0.1}, "ignore": [["o0", "o1"]], "objects": [)";
    const int n = 12;
    for (int i = 0; i < n; ++i) {
      const Pose p = test::random_pose(rng, 2.0);
      const bool fixed = i % 4 == 0;
      char buf[512];
      std::snprintf(
          buf, sizeof buf,
          R"(%s{"name": "o%d", "mesh": "%s", "position": [%.17g, %.17g, %.17g], "orientation": [%.17g, %.17g, %.17g, %.17g]%s})",
          i ? "," : "", i, meshes[i % 3], p.translation.x(), p.translation.y(), p.translation.z(), p.rotation.w(), p.rotation.x(),
          p.rotation.y(), p.rotation.z(), fixed ? "" : R"(, "motion": {"type": "velocity", "linear": [0, 0, 1]})");
      json += buf;
    }
    json += "]}";
    const World world(scene(json));
    const std::vector<Pose> poses = world.poses_at(0);
    const std::vector<ObjectPair> pairs = world.broad_phase(poses);
    std::vector<ObjectPair> want;
    for (std::uint32_t a = 0; a < n; ++a) {
      for (std::uint32_t b = a + 1; b < n; ++b) {
        const auto [alo, ahi] = world.bounds(a, poses[a], 0.05);
        const auto [blo, bhi] = world.bounds(b, poses[b], 0.05);
        const bool overlap = (alo.array() <= bhi.array()).all() && (blo.array() <= ahi.array()).all();
        const bool both_fixed = a % 4 == 0 && b % 4 == 0;
        const bool ignored = a == 0 && b == 1;
        if (overlap && !both_fixed && !ignored) want.push_back(ObjectPair{a, b});
        if (!both_fixed && !ignored &&
            !query_brute_force(world.model(a), poses[a], world.model(b), poses[b], world.request()).contacts.empty()) {
          EXPECT_TRUE(std::find(pairs.begin(), pairs.end(), ObjectPair{a, b}) != pairs.end()) << "touching pair dropped";
        }
      }
    }
    EXPECT_EQ(pairs, want) << "trial " << trial;
  }
}

TEST_F(WorldFiles, GroupsInScenesFilterContacts) {
  const std::string base = R"({"query": {"kind": "interference"}, %s "objects": [
      {"name": "a", "mesh": "cube.off", "group": 1},
      {"name": "b", "mesh": "cube.off", "position": [0.6, 0.2, 0.1], "group": 2, "motion": {"type": "velocity"}}]})";
  char with[1024], without[1024];
  std::snprintf(with, sizeof with, base.c_str(), R"("groups": {"compatible": [[1, 1], [2, 2]]},)");
  std::snprintf(without, sizeof without, base.c_str(), "");
  EXPECT_TRUE(test::reference_step(World(scene(with)), 0).contacts.empty());
  EXPECT_FALSE(test::reference_step(World(scene(without)), 0).contacts.empty());
}

TEST_F(WorldFiles, CopiedAndMovedWorldsKeepTheirOwnGroupTable) {
  const World world(scene(R"({"query": {"kind": "interference"}, "groups": {"compatible": [[1, 1], [2, 2]]}, "objects": [
      {"name": "a", "mesh": "cube.off", "group": 1},
      {"name": "b", "mesh": "cube.off", "position": [0.6, 0.2, 0.1], "group": 2, "motion": {"type": "velocity"}}]})"));
  ASSERT_EQ(world.request().groups, &world.scene().compatibility);
  World copy(world);
  EXPECT_EQ(copy.request().groups, &copy.scene().compatibility) << "not the original's table";
  const World moved(std::move(copy));
  EXPECT_EQ(moved.request().groups, &moved.scene().compatibility);
  // A vector that grows moves its worlds and frees the old storage: each keeps filtering by groups.
  std::vector<World> worlds;
  for (int i = 0; i < 9; ++i) worlds.push_back(world);
  for (const World& w : worlds) {
    EXPECT_EQ(w.request().groups, &w.scene().compatibility);
    EXPECT_TRUE(test::reference_step(w, 0).contacts.empty()) << "groups 1 and 2 never touch";
  }
  World assigned = world;
  assigned = worlds.back();
  EXPECT_EQ(assigned.request().groups, &assigned.scene().compatibility);
}

TEST_F(WorldFiles, HandBuiltScenesAreCheckedAsSceneFilesAre) {
  const Scene base = scene(R"({"objects": [{"name": "a", "mesh": "cube.off"},
      {"name": "b", "mesh": "cube.off", "motion": {"type": "velocity", "linear": [1, 0, 0]}}]})");
  const auto refused = [&](const std::function<void(Scene&)>& change, const std::string& words) {
    Scene s = base;
    change(s);
    try {
      const World world(std::move(s));
      FAIL() << "accepted: " << words;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused([](Scene& s) { s.objects[1].motion.type = Motion::Type::keyframes; },
          "object 'b' (objects[1]): a keyframe motion needs at least one key");
  refused(
      [](Scene& s) {
        s.objects[1].motion.type = Motion::Type::keyframes;
        s.objects[1].motion.keys.resize(2);
      },
      "key 1: key times must be finite and increase");
  refused([](Scene& s) { s.objects[1].scale = std::numeric_limits<double>::quiet_NaN(); }, "scale must be finite and > 0");
  refused([](Scene& s) { s.objects[1].scale = -2.0; }, "scale must be finite and > 0");
  refused([](Scene& s) { s.objects[0].refine = 7; }, "refine must be in [0, 6]");
  refused([](Scene& s) { s.dt = 0.0; }, "dt must be finite and > 0");
  refused([](Scene& s) { s.objects[1].motion.linear.x() = std::numeric_limits<double>::infinity(); },
          "velocities must be finite");
  refused([](Scene& s) { s.objects[0].pose.translation.y() = std::numeric_limits<double>::quiet_NaN(); },
          "object 'a' (objects[0]): its pose must be finite");
  EXPECT_THROW((void)pose_at(Pose{}, Motion{Motion::Type::keyframes}, 0.0), Error) << "no key to hold";
  // A key far away that the steps never reach is no error (where a motion takes an object is
  // checked at each step), as in a scene file.
  Scene far = base;
  far.objects[1].motion.type = Motion::Type::keyframes;
  far.objects[1].motion.keys = {Keyframe{0.0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()},
                                Keyframe{1000.0, Eigen::Vector3d(2e15, 0.0, 0.0), Eigen::Quaterniond::Identity()}};
  EXPECT_NO_THROW((void)World(far));
  const World world(base);
  EXPECT_THROW((void)world.model(2), Error);
  EXPECT_THROW((void)world.bounds(2, Pose{}, 0.0), Error);
  EXPECT_THROW((void)world.bounds(0, Pose{}, std::numeric_limits<double>::quiet_NaN()), Error);
  Pose bad;
  bad.translation.x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)world.bounds(0, bad, 0.0), Error);
  EXPECT_EQ(&world.model(1), &world.model(0)) << "one cube, shared";
}

TEST_F(WorldFiles, AMeshThatIsNotAMeshFailsClearly) {
  std::ofstream(dir / "self.json") << R"({"objects": [{"mesh": "self.json"}]})";
  try {
    const World world(load_scene(dir / "self.json"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("self.json"), std::string::npos) << e.what();
  }
}

TEST(ProceduralMeshes, InfiniteSizesAndHugeCountsAreErrors) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)make_sphere(inf, 8, 8), Error);
  EXPECT_THROW((void)make_torus(inf, 0.2, 8, 8), Error);
  EXPECT_THROW((void)make_box(1.0, inf, 1.0, 1), Error);
  EXPECT_THROW((void)make_sphere(1.0, 100000, 100000), Error) << "10^10 vertices";
  EXPECT_THROW((void)make_box(1.0, 1.0, 1.0, 100000), Error);
  EXPECT_EQ(make_sphere(1.0, 8, 8).vertices.size(), 9u * 8u);
}

TEST(RefineMesh, SplitsEachTriangleIntoFourInPlace) {
  const Mesh box = make_box(1, 1, 1, 1);
  const Mesh fine = refine_mesh(box, 2);
  ASSERT_EQ(fine.triangles.size(), box.triangles.size() * 16);
  const auto area = [](const Mesh& m, std::size_t t) {
    const auto& tri = m.triangles[t];
    return 0.5 * (m.vertices[tri[1]] - m.vertices[tri[0]]).cross(m.vertices[tri[2]] - m.vertices[tri[0]]).norm();
  };
  for (std::size_t t = 0; t < box.triangles.size(); ++t) {
    double sum = 0.0;
    for (std::size_t k = 0; k < 16; ++k) sum += area(fine, 16 * t + k);
    EXPECT_NEAR(sum, area(box, t), 1e-12) << "triangle " << t << " becomes triangles 16t .. 16t+15";
  }
  EXPECT_EQ(fine.vertices[fine.triangles[0][0]], box.vertices[box.triangles[0][0]]) << "corner triangle first";
  EXPECT_THROW((void)refine_mesh(box, -1), Error);
  Mesh bad = box;
  bad.triangles[3][1] = 1000;  // a corner past the vertices: refused, not read
  EXPECT_THROW((void)refine_mesh(bad, 1), Error);
  bad = box;
  bad.groups.assign(2, 1);  // fewer groups than triangles
  EXPECT_THROW((void)refine_mesh(bad, 1), Error);
}

}  // namespace
}  // namespace caliber
