#pragma once
// A torus and a sphere that interlock at most poses near the origin: many pairs of every kind,
// cheap enough to query hundreds of times in a test.

#include <memory>

#include "caliber/model.h"
#include "caliber/procedural.h"

namespace caliber::test {

struct TorusSphere {
  std::shared_ptr<const Model> torus = build_model(make_torus(1.0, 0.35, 24, 16));
  std::shared_ptr<const Model> sphere = build_model(make_sphere(0.9, 16, 24));
};

/// The models, built once per test program.
inline const TorusSphere& torus_sphere() {
  static const TorusSphere s;
  return s;
}

}  // namespace caliber::test
