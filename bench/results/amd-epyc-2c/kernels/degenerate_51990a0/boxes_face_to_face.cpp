// Two make_box(1, 1, 1, DIV) meshes, B moved by (0.25, 0.5, 2) so that its bottom face lies on
// A's top face: queries of one kind, CALLS times.
//   boxes_face_to_face [CALLS [DIV [interference|contact|distance]]]
#include <caliber/caliber.h>
#include <caliber/procedural.h>
#include <cstdio>
#include <cstdlib>
using namespace caliber;
int main(int argc, char** argv) {
  const int div = argc > 2 ? atoi(argv[2]) : 20;
  auto pa = build_model(make_box(1, 1, 1, div));
  auto pb = build_model(make_box(1, 1, 1, div));
  const char* kind = argc > 3 ? argv[3] : "interference";
  QueryRequest r;
  r.kind = std::string(kind) == "contact"    ? QueryKind::contact
           : std::string(kind) == "distance" ? QueryKind::distance
                                             : QueryKind::interference;
  if (r.kind == QueryKind::contact) r.tolerance = 0.01;
  Pose pb_;
  pb_.translation = Eigen::Vector3d(0.25, 0.5, 2.0);
  int n = argc > 1 ? atoi(argv[1]) : 20;
  size_t s = 0;
  for (int i = 0; i < n; ++i) {
    QueryResult q = query(*pa, Pose{}, *pb, pb_, r);
    s += q.contacts.size();
  }
  std::printf("%zu contacts/query %zu\n", s, s / n);
}
