#pragma once
// What the swept-query benchmarks share: the mesh pairs (A still at the identity, B centred and
// scaled against A) and the random motions of B through or past A.

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "caliber/mesh.h"
#include "caliber/procedural.h"
#include "caliber/sweep.h"
#include "bench_support.h"

namespace caliber::bench {

struct SweepCase {
  std::string name;
  Mesh a, b;
  double da = 0.0, db = 0.0;  ///< the box diagonals of A and B once centred and scaled
};

/// The plate and needle, the torus and sphere, and CGAL's bunny and blade (left out, said on
/// stderr, when the meshes are not in `dir`): both meshes centred on the origin, B scaled to a
/// third of A's box diagonal (the needle kept as it is).
inline std::vector<SweepCase> sweep_cases(const std::filesystem::path& dir, const std::string& only) {
  std::vector<SweepCase> cases;
  cases.push_back({"plate x needle", make_plate(1.0, 0.002, 8), make_box(0.002, 0.002, 0.2, 2)});
  cases.push_back({"torus x sphere", make_torus(1.0, 0.25, 48, 24), make_sphere(0.3, 16, 24)});
  try {
    cases.push_back({"bunny x blade", load_mesh(dir / "bunny00.off"), load_mesh(dir / "blade.off")});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s (scripts/fetch_meshes.sh extracts CGAL's meshes); that case is left out\n", e.what());
  }
  std::erase_if(cases, [&](const SweepCase& c) { return !only.empty() && c.name.find(only) == std::string::npos; });
  for (SweepCase& c : cases) {
    Eigen::Vector3d center;
    box_center(c.a, center, c.da);
    for (auto& v : c.a.vertices) v -= center;
    box_center(c.b, center, c.db);
    for (auto& v : c.b.vertices) v = (v - center) * (c.name == "plate x needle" ? 1.0 : c.da / (3.0 * c.db));
    box_center(c.b, center, c.db);
  }
  return cases;
}

/// Random motions of B from one side of A to the other, through a random point near A's middle,
/// turned up to 90 degrees at each end.
class SweepMotions {
 public:
  SweepMotions(const SweepCase& c, unsigned seed) : mCase(c), mRng(seed) {}

  SweptPose next() {
    Eigen::Vector3d dir(u(), u(), u());
    if (dir.norm() < 1e-3) dir = Eigen::Vector3d::UnitX();
    dir.normalize();
    const Eigen::Vector3d through(0.3 * mCase.da * u(), 0.3 * mCase.da * u(), 0.3 * mCase.da * u());
    const double reach = 0.5 * mCase.da + mCase.db;
    SweptPose motion;
    motion.start.translation = through + reach * dir;
    motion.start.rotation = turn();
    motion.end.translation = through - reach * dir;
    motion.end.rotation = turn();
    return motion;
  }

 private:
  double u() { return mU(mRng); }
  Eigen::Quaterniond turn() {
    Eigen::Vector3d axis(u(), u(), u());
    if (axis.norm() < 1e-3) axis = Eigen::Vector3d::UnitZ();
    return Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI * u(), axis.normalized()));
  }

  const SweepCase& mCase;
  std::mt19937_64 mRng;
  std::uniform_real_distribution<double> mU{-1.0, 1.0};
};

}  // namespace caliber::bench
