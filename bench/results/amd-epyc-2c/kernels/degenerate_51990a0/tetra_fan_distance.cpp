// Distance queries of tests/data/tetra.off against quad_fan.off moved by 3 along x (the fan's
// pentagon lies in the tetrahedron's base plane), run from the repository root:
//   tetra_fan_distance [CALLS]
#include <caliber/caliber.h>
#include <cstdio>
#include <vector>
using namespace caliber;
int main(int argc, char** argv) {
  auto pa_ = build_model(load_mesh("tests/data/tetra.off"));
  const Model& a = *pa_;
  auto pb_ = build_model(load_mesh("tests/data/quad_fan.off"));
  const Model& b = *pb_;
  QueryRequest r;
  r.kind = QueryKind::distance;
  r.tolerance = kUnbounded;
  int n = argc > 1 ? atoi(argv[1]) : 2000;
  Pose pb;
  pb.translation = Eigen::Vector3d(3, 0, 0);
  double s = 0;
  for (int i = 0; i < n; ++i) {
    QueryResult q = query(a, Pose{}, b, pb, r);
    s += q.contacts.empty() ? 0 : q.contacts[0].distance;
  }
  std::printf("%g\n", s);
}
