#pragma once
/// \file
/// Scene descriptions: objects (mesh, scale, pose, motion), the query, the time steps. Read from
/// JSON scene files (see docs/scenes.md) or built by hand.

#include "caliber/export.h"
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "caliber/pose.h"
#include "caliber/query.h"

namespace caliber {

/// A pose at a given time, for keyframed motion.
struct Keyframe {
  double time = 0.0;                                                ///< seconds
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               ///< translation at that time
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< unit quaternion at that time
};

/// How an object moves.
struct Motion {
  /// static: never moves; velocity: constant linear and angular velocity; keyframes: interpolated.
  enum class Type { fixed, velocity, keyframes };
  Type type = Type::fixed;
  /// Linear velocity (world units per second), for velocity motion.
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  /// Angular velocity (radians per second, world axes, about the object's origin), for velocity motion.
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
  /// Keyframes sorted by time (at least one), for keyframe motion: positions interpolated linearly,
  /// orientations by slerp; before the first and after the last key the object holds still.
  std::vector<Keyframe> keys;
};

/// The pose at time t of an object that starts at `initial` and moves by `motion`.
/// (Keyframes ignore `initial`: the keys are absolute poses; Error when there is none.)
[[nodiscard]] CALIBER_EXPORT Pose pose_at(const Pose& initial, const Motion& motion, double t);

/// A run of triangles (by id) put in one primitive group.
struct GroupRange {
  std::uint32_t first = 0;  ///< first triangle id
  std::uint32_t count = 0;  ///< how many triangles
  std::uint8_t group = 0;   ///< group 0..63
};

/// One object of a scene.
struct SceneObject {
  std::string name;                ///< unique name (defaults to "object<i>")
  std::filesystem::path mesh;      ///< mesh file (made absolute relative to the scene file)
  double scale = 1.0;              ///< uniform scale applied to the mesh
  int refine = 0;                  ///< 1-to-4 subdivision levels applied after loading (0..6)
  Pose pose;                       ///< pose at time 0
  Motion motion;                   ///< how it moves
  std::uint8_t group = 0;          ///< group of every triangle not in `groups`
  std::vector<GroupRange> groups;  ///< triangle ranges in other groups
};

/// The most time steps a scene file may ask for (and the command line's --steps).
inline constexpr int kMaxSceneSteps = 100000000;

/// A whole scene: objects, the query every pair runs, and the time steps.
struct Scene {
  std::string name;                         ///< scene name (defaults to the file's stem)
  std::filesystem::path file;               ///< where it was read from (empty if built by hand)
  QueryRequest query;                       ///< kind, tolerance, angle (groups: see `compatibility`)
  bool use_groups = false;                  ///< whether `compatibility` applies
  GroupCompatibility compatibility;         ///< which primitive groups may touch
  int steps = 150;                          ///< time steps to run
  double dt = 0.01;                         ///< seconds per step
  std::vector<SceneObject> objects;         ///< the objects, in id order
  std::vector<std::pair<int, int>> ignore;  ///< object pairs never tested (ids, lower first)
};

/// Reads a JSON scene file. Throws caliber::Error naming the file and the key on a missing file,
/// a JSON syntax error, an unknown key, a missing or ill-typed value, a value out of range, a
/// missing mesh file, or a duplicate object name. Meshes are not loaded here.
[[nodiscard]] CALIBER_EXPORT Scene load_scene(const std::filesystem::path& file);

/// Parses scene JSON text; mesh paths are relative to `base_dir`. `source` names it in errors.
[[nodiscard]] CALIBER_EXPORT Scene parse_scene(const std::string& text, const std::filesystem::path& base_dir,
                                               const std::string& source);

}  // namespace caliber
