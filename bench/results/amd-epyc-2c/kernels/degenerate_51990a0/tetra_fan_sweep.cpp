// Sweeps of tests/data/quad_fan.off from x = 3 to x = -3 through tests/data/tetra.off at rest
// (the fan's pentagon in the tetrahedron's base plane), run from the repository root:
//   tetra_fan_sweep [CALLS]
#include <caliber/caliber.h>
#include <cstdio>
#include <cstdlib>
using namespace caliber;
int main(int argc, char** argv) {
  auto pa = build_model(load_mesh("tests/data/tetra.off"));
  auto pb = build_model(load_mesh("tests/data/quad_fan.off"));
  SweptPose ma{Pose{}, Pose{}}, mb;
  mb.start.translation = Eigen::Vector3d(3, 0, 0);
  mb.end.translation = Eigen::Vector3d(-3, 0, 0);
  int n = argc > 1 ? atoi(argv[1]) : 100;
  double s = 0;
  for (int i = 0; i < n; ++i) {
    SweepResult r = sweep(*pa, ma, *pb, mb);
    s += r.time;
  }
  std::printf("%g\n", s / n);
}
