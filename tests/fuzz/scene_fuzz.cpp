// Fuzz target: the scene parser, then the world it describes (models built, one step run) when it
// parses. Mesh paths resolve against tests/data, whose small meshes keep a step short.

#include <string>

#include "caliber/error.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    caliber::Scene scene = caliber::parse_scene(text, CALIBER_TEST_DATA, "fuzz.json");
    if (scene.objects.size() > 64) return 0;  // keep each run short
    for (const caliber::SceneObject& o : scene.objects) {
      if (o.refine > 3) return 0;
    }
    const caliber::World world(std::move(scene));
    caliber::Engine engine;
    (void)caliber::step(world, engine, 0);
    (void)caliber::step(world, engine, world.scene().steps - 1);
  } catch (const caliber::Error&) {
    // the documented answer to bad input
  }
  return 0;
}
