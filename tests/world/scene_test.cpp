// Scene files: every error names the file and the key; motions interpolate as documented.

#include <numbers>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "caliber/error.h"
#include "caliber/scene.h"
#include "caliber/world.h"

namespace caliber {
namespace {

const std::filesystem::path kData = CALIBER_TEST_DATA;

/// Parses `json` (mesh paths relative to tests/data) and expects an Error whose message holds `words`.
void expect_scene_error(const std::string& json, const std::string& words) {
  try {
    (void)parse_scene(json, kData, "test.json");
    FAIL() << "no error for " << json;
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("test.json"), std::string::npos) << what;
    EXPECT_NE(what.find(words), std::string::npos) << "wanted '" << words << "' in: " << what;
  }
}

const std::string kObject = R"({"mesh": "tetra.off"})";

TEST(SceneFile, MinimalSceneHasDefaults) {
  const Scene s = parse_scene(R"({"objects": [)" + kObject + "]}", kData, "minimal.json");
  EXPECT_EQ(s.name, "minimal");
  EXPECT_EQ(s.steps, 150);
  EXPECT_EQ(s.dt, 0.01);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "object0");
  EXPECT_EQ(s.objects[0].mesh, (kData / "tetra.off").lexically_normal());
  EXPECT_EQ(s.objects[0].motion.type, Motion::Type::fixed);
  EXPECT_EQ(s.query.kind, QueryKind::interference);
}

TEST(SceneFile, ReadsEveryKey) {
  const Scene s = parse_scene(R"({
    "name": "full", "steps": 3, "dt": 0.5,
    "query": {"kind": "contact", "tolerance": 0.25, "angle": 45},
    "groups": {"compatible": [[0, 1]]},
    "ignore": [["a", "c"]],
    "objects": [
      {"name": "a", "mesh": "tetra.off", "scale": 2, "refine": 1, "position": [1, 2, 3], "orientation": [0, 0, 0, 2],
       "group": 1, "groups": [{"first": 0, "count": 2, "group": 3}]},
      {"name": "b", "mesh": "tetra.ply", "motion": {"type": "velocity", "linear": [1, 0, 0], "angular": [0, 0, 1]}},
      {"name": "c", "mesh": "tetra.obj", "motion": {"type": "keyframes", "keys": [
        {"time": 0, "position": [0, 0, 0]}, {"time": 1, "position": [2, 0, 0], "orientation": [0, 0, 0, 1]}]}}
    ]})",
                              kData, "full.json");
  EXPECT_EQ(s.name, "full");
  EXPECT_EQ(s.steps, 3);
  EXPECT_EQ(s.query.kind, QueryKind::contact);
  EXPECT_EQ(s.query.tolerance, 0.25);
  EXPECT_EQ(s.query.angle_deg, 45);
  EXPECT_TRUE(s.use_groups);
  EXPECT_TRUE(s.compatibility.allows(0, 1));
  EXPECT_TRUE(s.compatibility.allows(1, 0));
  EXPECT_FALSE(s.compatibility.allows(1, 1));
  ASSERT_EQ(s.ignore.size(), 1u);
  EXPECT_EQ(s.ignore[0], std::make_pair(0, 2));
  EXPECT_EQ(s.objects[0].scale, 2);
  EXPECT_EQ(s.objects[0].refine, 1);
  EXPECT_EQ(s.objects[0].pose.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.objects[0].pose.rotation.z(), 1.0) << "normalized";
  EXPECT_EQ(s.objects[0].group, 1);
  ASSERT_EQ(s.objects[0].groups.size(), 1u);
  EXPECT_EQ(s.objects[1].motion.type, Motion::Type::velocity);
  EXPECT_EQ(s.objects[2].motion.keys.size(), 2u);
}

TEST(SceneFile, ErrorsNameTheKey) {
  expect_scene_error("{", "not valid JSON");
  expect_scene_error("[]", "must be an object");
  expect_scene_error(R"({"objects": []})", "'objects': must be a non-empty array");
  expect_scene_error(R"({"objekts": []})", "'objekts': unknown key");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "colour": 1}]})", "'objects[0].colour': unknown key");
  expect_scene_error(R"({"objects": [{}]})", "'objects[0].mesh': is required");
  expect_scene_error(R"({"objects": [{"mesh": "missing.off"}]})", "'objects[0].mesh': no such mesh file");
  expect_scene_error(R"({"objects": [{"mesh": "bad"}]})", "(a directory)");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "scale": -1}]})", "'objects[0].scale': must be > 0");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "scale": "big"}]})", "'objects[0].scale': must be a number");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "refine": 9}]})", "'objects[0].refine': must be in [0, 6]");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "position": [1, 2]}]})",
                     "'objects[0].position': must be an array of 3");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "orientation": [0, 0, 0, 0]}]})", "quaternion is (nearly) zero");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "motion": {"type": "teleport"}}]})", "unknown motion 'teleport'");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "motion": {"type": "keyframes", "keys": []}}]})",
                     "'objects[0].motion.keys': must be a non-empty array");
  expect_scene_error(
      R"({"objects": [{"mesh": "tetra.off", "motion": {"type": "keyframes", "keys": [{"time": 1}, {"time": 1}]}}]})",
      "key times must increase");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off", "motion": {"type": "static", "linear": [1, 0, 0]}}]})",
                     "'objects[0].motion.linear': unknown key");
  expect_scene_error(R"({"query": {"kind": "collide"}, "objects": [)" + kObject + "]}", "unknown query kind");
  expect_scene_error(R"({"query": {"tolerance": -1}, "objects": [)" + kObject + "]}", "'query.tolerance': must be >= 0");
  expect_scene_error(R"({"query": {"angle": 270}, "objects": [)" + kObject + "]}", "'query.angle': must be in [0, 180]");
  expect_scene_error(R"({"steps": 0, "objects": [)" + kObject + "]}", "'steps': must be in [1,");
  expect_scene_error(R"({"dt": 0, "objects": [)" + kObject + "]}", "'dt': must be > 0");
  expect_scene_error(R"({"objects": [{"name": "x", "mesh": "tetra.off"}, {"name": "x", "mesh": "tetra.off"}]})",
                     "duplicate name 'x'");
  expect_scene_error(R"({"ignore": [["a", "b"]], "objects": [)" + kObject + "]}", "no object named 'a'");
  expect_scene_error(R"({"groups": {"compatible": [[0, 64]]}, "objects": [)" + kObject + "]}", "must be in [0, 63]");
}

TEST(SceneFile, LoadErrorsForFiles) {
  EXPECT_THROW((void)load_scene(kData / "no_such_scene.json"), Error);
  try {
    (void)load_scene(kData / "bad");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos);
  }
}

TEST(Motion, VelocityMovesAndTurns) {
  Motion m;
  m.type = Motion::Type::velocity;
  m.linear = Eigen::Vector3d(1, 2, 3);
  m.angular = Eigen::Vector3d(0, 0, std::numbers::pi / 2);  // a quarter turn per second
  const Pose p = pose_at(Pose{}, m, 2.0);
  EXPECT_EQ(p.translation, Eigen::Vector3d(2, 4, 6));
  const Eigen::Vector3d x = p.rotation * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(x.x(), -1.0, 1e-12);  // half a turn after 2 s
  EXPECT_NEAR(x.y(), 0.0, 1e-12);
}

TEST(Motion, AtTimeZeroThePoseIsTheInitialOneBitForBit) {
  const Pose initial = Pose::from_values(0.1, -2.3, 7.7, 0.9659258, 0.2312, 0.0, 0.1156);
  Motion m;
  m.type = Motion::Type::velocity;
  m.linear = Eigen::Vector3d(1, 2, 3);
  m.angular = Eigen::Vector3d(0.3, 0, 0);
  const Pose p = pose_at(initial, m, 0.0);
  EXPECT_EQ(p.translation, initial.translation);
  EXPECT_EQ(p.rotation.coeffs(), initial.rotation.coeffs());
  m.angular = Eigen::Vector3d::Zero();
  EXPECT_EQ(pose_at(initial, m, 5.0).rotation.coeffs(), initial.rotation.coeffs()) << "translation only";
}

TEST(Motion, KeyframesInterpolateWithSlerpAndHold) {
  Motion m;
  m.type = Motion::Type::keyframes;
  Keyframe k0, k1;
  k0.time = 1.0;
  k0.position = Eigen::Vector3d(0, 0, 0);
  k1.time = 3.0;
  k1.position = Eigen::Vector3d(4, 0, 0);
  k1.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()));
  m.keys = {k0, k1};
  EXPECT_EQ(pose_at(Pose{}, m, 0.0).translation, Eigen::Vector3d(0, 0, 0)) << "holds before the first key";
  EXPECT_EQ(pose_at(Pose{}, m, 5.0).translation, Eigen::Vector3d(4, 0, 0)) << "holds after the last key";
  const Pose mid = pose_at(Pose{}, m, 2.0);
  EXPECT_NEAR(mid.translation.x(), 2.0, 1e-15);
  const Eigen::Vector3d x = mid.rotation * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(x.y(), x.x()), std::numbers::pi / 4, 1e-12) << "slerp: half of a quarter turn";
  EXPECT_NEAR(mid.rotation.norm(), 1.0, 1e-15);
}

TEST(Motion, MovingBeyondTheCoordinateLimitIsAnErrorNamingTheObject) {
  const World world(parse_scene(R"({"name": "runaway", "dt": 1, "objects": [{"mesh": "tetra.off"},
      {"name": "rocket", "mesh": "tetra.off", "motion": {"type": "velocity", "linear": [1e14, 0, 0]}}]})",
                                CALIBER_TEST_DATA, "runaway.json"));
  EXPECT_NO_THROW((void)world.poses_at(10));
  try {
    (void)world.frame(20);
    FAIL() << "2e15 is beyond the limit";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'rocket'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("step 20"), std::string::npos) << e.what();
  }
}

TEST(SceneFile, AKeyGivenTwiceIsAnErrorNamingItsPath) {
  expect_scene_error(R"({"name": "a", "name": "b", "objects": [{"mesh": "tetra.off"}]})",
                     "'name': the key is given twice in one object");
  expect_scene_error(R"({"objects": [{"mesh": "tetra.off"}, {"mesh": "tetra.off", "motion": {"type": "velocity",
      "linear": [1, 0, 0], "type": "fixed"}}]})",
                     "'objects[1].motion.type': the key is given twice");
  expect_scene_error(R"({"objects": [[], {"mesh": "tetra.off", "mesh": "tetra.off"}]})",
                     "'objects[1].mesh': the key is given twice");
  // The same key in two objects is not a duplicate.
  EXPECT_EQ(parse_scene(R"({"objects": [{"name": "a", "mesh": "tetra.off"}, {"name": "b", "mesh": "tetra.off"}]})",
                        CALIBER_TEST_DATA, "two.json")
                .objects.size(),
            2u);
}

TEST(Motion, AnOverflowingTurnIsAnErrorNamingTheFileObjectAndKey) {
  const auto file = std::filesystem::temp_directory_path() / "caliber_scene_test_spin.json";
  std::ofstream(file) << R"({"dt": 0.5, "objects": [{"mesh": ")" << CALIBER_TEST_DATA << R"(/tetra.off"},
      {"name": "spinner", "mesh": ")"
                      << CALIBER_TEST_DATA << R"(/tetra.off",
       "motion": {"type": "velocity", "linear": [0, 0, 0], "angular": [1e308, 1e308, 0]}}]})";
  const World world(load_scene(file));
  EXPECT_NO_THROW((void)world.poses_at(0));
  try {
    (void)world.poses_at(1);
    FAIL() << "|angular| overflows";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(file.string() + ": object 'spinner' (objects[1].motion.angular): the turn by step 1", 0), 0u) << what;
  }
}

}  // namespace
}  // namespace caliber
