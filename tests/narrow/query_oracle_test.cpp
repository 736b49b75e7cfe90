// The traversal against the brute-force oracle: over 1000 random poses on procedural and real
// meshes, for every query kind, the results must be identical to the last bit.

#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/random_poses.h"

namespace caliber {
namespace {

struct Shapes {
  std::shared_ptr<const Model> sphere = build_model(make_sphere(1.0, 8, 12));
  std::shared_ptr<const Model> torus = build_model(make_torus(1.0, 0.35, 12, 8));
  std::shared_ptr<const Model> box = build_model(make_box(0.8, 0.5, 0.3, 2));
  std::shared_ptr<const Model> plate = build_model(make_plate(1.0, 0.02, 4));
};

const Shapes& shapes() {
  static const Shapes s;
  return s;
}

QueryRequest random_request(std::mt19937_64& rng, QueryKind kind) {
  QueryRequest request;
  request.kind = kind;
  request.tolerance = std::uniform_real_distribution<double>(0.0, 0.2)(rng);
  request.angle_deg = std::uniform_real_distribution<double>(5.0, 80.0)(rng);
  return request;
}

/// Runs `poses` random poses of (a, b), cycling the query kind; returns how many gave a non-empty
/// result per kind, so a test can make sure it did not only compare empty answers.
std::array<int, 3> compare_with_oracle(const Model& a, const Model& b, int poses, double spread, std::uint64_t seed,
                                       const std::string& name) {
  std::mt19937_64 rng(seed);
  std::array<int, 3> non_empty{0, 0, 0};
  for (int i = 0; i < poses; ++i) {
    const auto kind = static_cast<QueryKind>(i % 3);
    const QueryRequest request = random_request(rng, kind);
    const Pose pa = test::random_pose(rng, spread);
    const Pose pb = test::random_pose(rng, spread);
    const QueryResult fast = query(a, pa, b, pb, request);
    const QueryResult slow = query_brute_force(a, pa, b, pb, request);
    test::expect_identical(fast, slow, name + " pose " + std::to_string(i) + " kind " + std::string(to_string(kind)));
    if (::testing::Test::HasFatalFailure()) return non_empty;
    EXPECT_LE(fast.stats.leaf_tests, slow.stats.leaf_tests);
    if (!fast.contacts.empty()) ++non_empty[i % 3];
  }
  return non_empty;
}

void expect_mostly_non_empty(const std::array<int, 3>& non_empty, int poses) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_GE(non_empty[k], poses / 3 / 4) << "kind " << k << ": too few poses with a result to be a real test";
  }
}

TEST(QueryOracle, SphereAgainstTorus) {
  const auto n = compare_with_oracle(*shapes().sphere, *shapes().torus, 300, 0.8, 1, "sphere-torus");
  expect_mostly_non_empty(n, 300);
}

TEST(QueryOracle, TorusAgainstTorus) {
  const auto n = compare_with_oracle(*shapes().torus, *shapes().torus, 300, 0.8, 2, "torus-torus");
  expect_mostly_non_empty(n, 300);
}

TEST(QueryOracle, BoxAgainstThinPlate) {
  const auto n = compare_with_oracle(*shapes().box, *shapes().plate, 300, 0.6, 3, "box-plate");
  expect_mostly_non_empty(n, 300);
}

TEST(QueryOracle, PlateAgainstSphere) {
  const auto n = compare_with_oracle(*shapes().plate, *shapes().sphere, 300, 0.8, 4, "plate-sphere");
  expect_mostly_non_empty(n, 300);
}

TEST(QueryOracle, AxisAlignedBoxesTouchingAndCoplanar) {
  // Exact binary-fraction offsets and right-angle rotations: faces lie in common planes, edges
  // touch, vertices meet. This is where non-robust tests disagree with themselves.
  const Model& box = *shapes().box;
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> step(-9, 9);
  const double half = 0.70710678118654752440;
  const Eigen::Quaterniond turns[6] = {Eigen::Quaterniond(1, 0, 0, 0),       Eigen::Quaterniond(0, 1, 0, 0),
                                       Eigen::Quaterniond(0, 0, 1, 0),       Eigen::Quaterniond(0, 0, 0, 1),
                                       Eigen::Quaterniond(half, half, 0, 0), Eigen::Quaterniond(half, 0, 0, half)};
  std::array<int, 3> non_empty{0, 0, 0};
  const int poses = 300;
  for (int i = 0; i < poses; ++i) {
    const auto kind = static_cast<QueryKind>(i % 3);
    QueryRequest request = random_request(rng, kind);
    request.tolerance = 0.125 * (i % 2);  // exact touching distances
    Pose pa, pb;
    pb.rotation = turns[i % 6];
    pb.rotation.normalize();
    const Eigen::Vector3d steps(step(rng), step(rng), step(rng));
    pb.translation = steps * (i % 2 == 0 ? 0.125 : 0.1);  // exact binary fractions, or not
    if (i % 4 < 2) {
      // Put B against one face of A: faces in contact, or a binary fraction apart.
      const Eigen::Vector3d half_a(0.8, 0.5, 0.3);
      const Eigen::Vector3d half_b = pb.rotation.toRotationMatrix().cwiseAbs() * half_a;
      const int axis = (i / 3) % 3;
      pb.translation[axis] = (half_a[axis] + half_b[axis] + 0.0625 * (i % 3)) * (i % 8 < 4 ? 1 : -1);
    }
    const QueryResult fast = query(box, pa, box, pb, request);
    const QueryResult slow = query_brute_force(box, pa, box, pb, request);
    test::expect_identical(fast, slow, "aligned boxes pose " + std::to_string(i));
    if (HasFatalFailure()) return;
    if (!fast.contacts.empty()) ++non_empty[i % 3];
  }
  expect_mostly_non_empty(non_empty, poses);
}

TEST(QueryOracle, RealMeshes) {
  const std::filesystem::path dir = CALIBER_MESH_DATA;
  if (!std::filesystem::exists(dir / "dragknob.off")) GTEST_SKIP() << "run scripts/fetch_meshes.sh first";
  auto knob = load_mesh(dir / "dragknob.off");
  auto eight = load_mesh(dir / "eight.off");
  // Scale both to about unit size so that the random poses overlap.
  const auto size = [](const Mesh& m) {
    Eigen::Vector3d lo = m.vertices[0], hi = lo;
    for (const auto& v : m.vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    return (hi - lo).norm();
  };
  scale_mesh(knob, 2.0 / size(knob));
  scale_mesh(eight, 2.0 / size(eight));
  const auto mk = build_model(knob);
  const auto me = build_model(eight);
  const auto n = compare_with_oracle(*mk, *me, 120, 0.4, 6, "knob-eight");
  expect_mostly_non_empty(n, 120);
}

}  // namespace
}  // namespace caliber
