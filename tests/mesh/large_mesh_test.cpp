// The bad-input catalog's 2-million-triangle mesh: written as OFF, loaded, built and queried, and
// the query checked against an independent brute force over the triangles near the probe.

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <gtest/gtest.h>

#include "support/results.h"
#include "bvh/model_data.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "support/temp_dir.h"

namespace caliber {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

TEST(LargeMesh, TwoMillionTrianglesLoadBuildAndQueryExactly) {
  test::TempDir temp{"large_mesh"};
  const auto path = temp.path() / "sphere_2m.off";
  auto t = std::chrono::steady_clock::now();
  save_off(make_sphere(1.0, 1001, 1000), path);
  const double write_s = seconds_since(t);
  t = std::chrono::steady_clock::now();
  const Mesh big = load_mesh(path);
  const double load_s = seconds_since(t);
  ASSERT_GE(big.triangles.size(), 2'000'000u);
  t = std::chrono::steady_clock::now();
  const auto model = build_model(big);
  const double build_s = seconds_since(t);
  const auto probe = build_model(make_box(0.01, 0.01, 0.01, 2));
  const Pose at_surface = Pose::from_values(0.6, 0.0, 0.8, 0.97, 0.1, 0.2, 0.05);
  std::printf("2M-triangle mesh: %zu triangles, write %.1f s, load %.1f s, BVH build %.1f s, %zu nodes\n", big.triangles.size(),
              write_s, load_s, build_s, data(*model).nodes.size());

  // Independent check: the big mesh's triangles whose box meets the probe's world box (grown by the
  // tolerance) form a small mesh; brute force on it must give exactly the pairs the BVH query gave.
  for (const QueryKind kind : {QueryKind::interference, QueryKind::proximity}) {
    QueryRequest request;
    request.kind = kind;
    request.tolerance = kind == QueryKind::proximity ? 0.004 : 0.0;
    const QueryResult fast = query(*model, Pose{}, *probe, at_surface, request);
    ASSERT_FALSE(fast.contacts.empty()) << "the probe must touch the sphere";
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
    for (const auto& v : probe->mesh().vertices) {
      const Eigen::Vector3d w = at_surface.apply(v);
      lo = lo.cwiseMin(w);
      hi = hi.cwiseMax(w);
    }
    lo.array() -= request.tolerance + 1e-9;
    hi.array() += request.tolerance + 1e-9;
    Mesh near;
    near.source = "near the probe";
    std::vector<std::uint32_t> original;
    for (std::uint32_t i = 0; i < big.triangles.size(); ++i) {
      Eigen::Vector3d tlo = big.vertices[big.triangles[i][0]], thi = tlo;
      for (const std::uint32_t v : big.triangles[i]) {
        tlo = tlo.cwiseMin(big.vertices[v]);
        thi = thi.cwiseMax(big.vertices[v]);
      }
      if ((tlo.array() > hi.array()).any() || (thi.array() < lo.array()).any()) continue;
      const auto base = static_cast<std::uint32_t>(near.vertices.size());
      for (const std::uint32_t v : big.triangles[i]) near.vertices.push_back(big.vertices[v]);
      near.triangles.push_back({base, base + 1, base + 2});
      original.push_back(i);
    }
    ASSERT_FALSE(near.triangles.empty());
    const QueryResult slow = query_brute_force(*build_model(near), Pose{}, *probe, at_surface, request);
    std::vector<TrianglePair> want;
    for (const Contact& p : slow.contacts) want.push_back({original[p.tri_a], p.tri_b});
    std::sort(want.begin(), want.end());
    EXPECT_EQ(test::pairs_of(fast), want) << to_string(kind);
    std::printf("  %s: %zu pairs, %llu node tests (brute force over %zu nearby triangles)\n",
                std::string(to_string(kind)).c_str(), fast.contacts.size(),
                static_cast<unsigned long long>(fast.stats.node_tests), near.triangles.size());
  }
}

}  // namespace
}  // namespace caliber
