#pragma once
// A world whose objects keep touching forever: a box, a ball and a ring turning in place (pure
// rotations, so contacts come and go without anything drifting away). The box spins against the
// ball; the ring tumbles around the ball, touching it and the box by turns. Used by the soak and
// the allocation test.

#include <memory>
#include <string>

#include "caliber/mesh.h"
#include "caliber/procedural.h"
#include "caliber/world.h"
#include "support/temp_dir.h"

namespace caliber::test {

/// The world, its meshes `fineness` times finer along each direction (1: 6x6 box faces, a 16x24
/// sphere, a 32x16 torus).
inline std::unique_ptr<World> touching_world(int fineness, const std::string& name) {
  const TempDir dir(name);
  save_off(make_box(0.5, 0.5, 0.5, 6 * fineness), dir.path() / "box.off");
  save_off(make_sphere(0.6, 16 * fineness, 24 * fineness), dir.path() / "sphere.off");
  save_off(make_torus(0.8, 0.25, 32 * fineness, 16 * fineness), dir.path() / "torus.off");
  return std::make_unique<World>(parse_scene(R"({"name": ")" + name + R"(", "dt": 0.01,
    "query": {"kind": "contact", "tolerance": 0.02, "angle": 30}, "objects": [
      {"name": "box", "mesh": "box.off", "motion": {"type": "velocity", "angular": [0, 0, 2.1]}},
      {"name": "ball", "mesh": "sphere.off", "position": [1.05, 0, 0], "motion": {"type": "velocity", "angular": [0.7, 0.3, 0]}},
      {"name": "ring", "mesh": "torus.off", "position": [1.05, 0.1, 0], "motion": {"type": "velocity", "angular": [0.31, 1.3, 0.2]}}]})",
                                             dir.path(), name + ".json"));
}

}  // namespace caliber::test
