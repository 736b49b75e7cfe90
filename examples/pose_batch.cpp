// A planner's question, many times at once: does B, moved along a path, touch A, and how far apart
// are they? One batch call per query, on every thread the process allows; each entry is what
// caliber::query answers at its pose (checked here for a few).
//   pose_batch A.off B.off

#include <cstdio>
#include <vector>

#include <caliber/caliber.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s A B\n", argv[0]);
    return 2;
  }
  try {
    const auto a = caliber::build_model(caliber::load_mesh(argv[1]));
    const auto b = caliber::build_model(caliber::load_mesh(argv[2]));
    // 1000 poses of B as rows of seven numbers: translation, then the quaternion (x, y, z, w).
    std::vector<double> rows;
    for (int i = 0; i < 1000; ++i) {
      const double s = i / 999.0;
      for (const double v : {2.0 * s - 1.0, 0.1, 0.0, 0.0, 0.0, 0.3 * s, 1.0}) rows.push_back(v);
    }
    const std::vector<caliber::Pose> path = caliber::poses_from_vectors(rows, caliber::QuaternionOrder::xyzw, "path");
    const std::vector<caliber::Pose> fixed{caliber::Pose{}};
    // [readme]
    caliber::Engine engine;  // the default method, on the threads of the arena it is called from
    caliber::QueryRequest first_hit;
    first_hit.max_pairs = 1;
    caliber::QueryRequest distance;
    distance.kind = caliber::QueryKind::distance;
    distance.tolerance = caliber::kUnbounded;
    const caliber::BatchResult hits = engine.query_many(*a, fixed, *b, path, first_hit);
    const caliber::BatchResult gaps = engine.query_many(*a, fixed, *b, path, distance);
    // [/readme]
    std::size_t touching = 0;
    for (std::size_t i = 0; i < hits.size(); ++i) touching += hits.hit(i) ? 1 : 0;
    for (std::size_t i = 0; i < path.size(); i += 250) {
      const caliber::QueryResult one = caliber::query(*a, caliber::Pose{}, *b, path[i], distance);
      if (one.contacts.front().distance != gaps.contacts_of(i).front().distance) {
        std::fprintf(stderr, "pose_batch: entry %zu differs from the single query\n", i);
        return 1;
      }
    }
    std::printf("%zu of %zu poses touch; distance at the first pose %.6g\n", touching, path.size(),
                gaps.contacts_of(0).front().distance);
    return 0;
  } catch (const caliber::Error& e) {
    std::fprintf(stderr, "pose_batch: %s\n", e.what());
    return 2;
  }
}
