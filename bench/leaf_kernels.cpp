// Leaf kernels against FCL's, on the triangle pairs the scenes really send to the leaf test.
//
// The pairs: every leaf pair whose node test passes, at step 50 of two_small, funnel, front_car and
// two_large (every object pair of the broad phase), with B's triangle in A's frame exactly
// as caliber's leaf test sees it (up to kMaxPairs per scene, taken evenly). Each benchmark runs one
// kernel over all of a scene's pairs; items/s is triangle pairs per second.
//
//   closest_points/SCENE   caliber::geometry::closest_points_triangles (the contact kernel; AVX2
//                          where the CPU has it)
//   closest_points_portable/SCENE  the same kernel's portable form (the same bits, no AVX2)
//   closest_points_batch/SCENE  closest_points_triangles_batch, 8 pairs a call (AVX-512 where the
//                          CPU has it; the same bits): the pairs copied into the batch, in order,
//                          as the contact leaf test buffers them, the copying timed too
//   fcl_tri_distance/SCENE fcl::detail::TriangleDistance<double>::triDistance (FCL's, PQP's)
//   intersect/SCENE        caliber::geometry::triangles_intersect (exact; the interference kernel)
//   fcl_intersect/SCENE    fcl::detail::Intersect<double>::intersect_Triangle (FCL's collide kernel)
//   leaf_test/SCENE        PairContext::leaf_test, the scene's contact query: the whole leaf test
//   leaf_test_buffered/SCENE the same through a buffer (the depth-first traversal's way: the refusal
//                          and the closest points eight pairs at a time); the same pairs kept
//
//   bench_leaf_kernels [--scenes DIR] [google benchmark flags, e.g. --benchmark_repetitions=5]
//   bench_leaf_kernels --census [--scenes DIR]
//
// --census times nothing: for each scene's pairs it counts the kernel's feature pairs that a
// plane-distance bound shows cannot win (see census()), what skipping them could save at most.
//
// Before timing, the distances of both kernels are compared on every pair (they must agree to
// 1e-9 of the scene's size) and the interference verdicts counted (FCL's is not exact: a
// difference is reported, not an error).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <fcl/narrowphase/detail/primitive_shape_algorithm/triangle_distance.h>
#include <fcl/narrowphase/detail/traversal/collision/intersect.h>

#include "caliber/scene.h"
#include "caliber/world.h"
#include "geometry/triangle_distance.h"
#include "geometry/triangle_intersect.h"
#include "narrow/leaf_buffer.h"
#include "narrow/pair_context.h"
#include "narrow/traversal.h"

namespace {

using Vec3 = Eigen::Vector3d;

constexpr std::size_t kMaxPairs = 200000;
constexpr int kStep = 50;

struct TrianglePair {
  Vec3 a[3];
  Vec3 b[3];
  std::uint32_t context;  ///< which object pair (index into Sample::contexts)
  std::uint32_t ta, tb;
};

struct Sample {
  std::unique_ptr<caliber::World> world;
  std::vector<std::unique_ptr<caliber::narrow::PairContext>> contexts;
  std::vector<TrianglePair> pairs;
  double size = 1.0;  ///< largest model extent (distances are compared relative to it)
};

std::string g_scenes = CALIBER_BENCH_SCENES;
std::map<std::string, Sample> g_samples;

/// Every leaf pair of the CD tree whose node test passes and whose normals face each other (what
/// traverse_depth_first hands to the leaf test, less what its normal test refuses before any
/// kernel), in the traversal's order.
void collect_leaf_pairs(const caliber::narrow::PairContext& ctx, std::uint32_t context, std::vector<TrianglePair>& out) {
  using caliber::narrow::NodePair;
  // Each node with its parent (the root's its own: tested by node_test).
  std::vector<std::pair<NodePair, NodePair>> stack{{NodePair{0, 0}, NodePair{0, 0}}};
  while (!stack.empty()) {
    const auto [n, parent] = stack.back();
    stack.pop_back();
    if (!caliber::narrow::child_test(ctx, parent, n)) continue;
    const caliber::BvhNode& a = ctx.a().nodes[n.a];
    const caliber::BvhNode& b = ctx.b().nodes[n.b];
    if (a.is_leaf() && b.is_leaf()) {
      if (!ctx.normals_allow(a.index, b.index)) continue;
      TrianglePair p;
      const auto& tri = ctx.a().mesh.triangles[a.index];
      for (int k = 0; k < 3; ++k) {
        p.a[k] = ctx.a().mesh.vertices[tri[k]];
        p.b[k] = ctx.b_vertex(b.index, k);
      }
      p.context = context;
      p.ta = a.index;
      p.tb = b.index;
      out.push_back(p);
      continue;
    }
    NodePair children[caliber::narrow::kMaxChildren];
    const int count = caliber::narrow::cd_children(ctx, n, children);
    for (int i = count - 1; i >= 0; --i) stack.emplace_back(children[i], n);
  }
}

const Sample& sample(const std::string& scene) {
  auto it = g_samples.find(scene);
  if (it != g_samples.end()) return it->second;
  Sample s;
  s.world = std::make_unique<caliber::World>(caliber::load_scene(std::filesystem::path(g_scenes) / (scene + ".json")));
  const std::vector<caliber::Pose> poses = s.world->poses_at(kStep);
  std::vector<TrianglePair> all;
  for (const caliber::ObjectPair& t : s.world->broad_phase(poses)) {
    s.contexts.push_back(std::make_unique<caliber::narrow::PairContext>(s.world->model(t.a), poses[t.a], s.world->model(t.b),
                                                                        poses[t.b], s.world->request()));
    collect_leaf_pairs(*s.contexts.back(), static_cast<std::uint32_t>(s.contexts.size() - 1), all);
    s.size = std::max({s.size, s.world->model(t.a).extent(), s.world->model(t.b).extent()});
  }
  const std::size_t stride = all.size() > kMaxPairs ? (all.size() + kMaxPairs - 1) / kMaxPairs : 1;
  for (std::size_t i = 0; i < all.size(); i += stride) s.pairs.push_back(all[i]);

  // The kernels must agree before their times mean anything.
  std::size_t far = 0, verdicts = 0;
  double worst = 0.0;
  for (const TrianglePair& p : s.pairs) {
    const double ours = caliber::geometry::closest_points_triangles(p.a, p.b).distance;
    Vec3 P, Q;
    const double theirs = fcl::detail::TriangleDistance<double>::triDistance(p.a, p.b, P, Q);
    const bool hit = caliber::geometry::triangles_intersect(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2]);
    Vec3 a[3] = {p.a[0], p.a[1], p.a[2]}, b[3] = {p.b[0], p.b[1], p.b[2]};
    const bool fcl_hit = fcl::detail::Intersect<double>::intersect_Triangle(a[0], a[1], a[2], b[0], b[1], b[2]);
    verdicts += hit != fcl_hit;
    if (hit) continue;  // FCL's points are arbitrary for overlapping triangles, its distance 0
    const double diff = std::abs(ours - theirs);
    worst = std::max(worst, diff);
    far += diff > 1e-9 * s.size;
  }
  std::fprintf(stderr,
               "%s step %d: %zu leaf pairs (%zu taken); distance ours vs FCL: worst difference %.3g (%zu over 1e-9 of "
               "size %.3g); interference verdicts differing: %zu\n",
               scene.c_str(), kStep, all.size(), s.pairs.size(), worst, far, s.size, verdicts);
  return g_samples.emplace(scene, std::move(s)).first->second;
}

template <caliber::geometry::ClosestPoints (*kernel)(const Vec3*, const Vec3*)>
void closest_points(benchmark::State& state, const std::string& scene) {
  const Sample& s = sample(scene);
  for (auto _ : state) {
    for (const TrianglePair& p : s.pairs) benchmark::DoNotOptimize(kernel(p.a, p.b));
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.pairs.size()));
}

void closest_points_batch(benchmark::State& state, const std::string& scene) {
  const Sample& s = sample(scene);
  caliber::geometry::TriangleBatch batch;
  caliber::geometry::ClosestPointsBatch out;
  for (auto _ : state) {
    for (const TrianglePair& p : s.pairs) {
      batch.add(p.a, p.b);
      if (batch.full()) {
        caliber::geometry::closest_points_triangles_batch(batch, out);
        benchmark::DoNotOptimize(out.distance);
        batch.size = 0;
      }
    }
    caliber::geometry::closest_points_triangles_batch(batch, out);
    benchmark::DoNotOptimize(out.distance);
    batch.size = 0;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.pairs.size()));
}

void fcl_tri_distance(benchmark::State& state, const std::string& scene) {
  const Sample& s = sample(scene);
  for (auto _ : state) {
    for (const TrianglePair& p : s.pairs) {
      Vec3 P, Q;
      benchmark::DoNotOptimize(fcl::detail::TriangleDistance<double>::triDistance(p.a, p.b, P, Q));
      benchmark::DoNotOptimize(P);
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.pairs.size()));
}

void intersect(benchmark::State& state, const std::string& scene) {
  const Sample& s = sample(scene);
  for (auto _ : state) {
    for (const TrianglePair& p : s.pairs) {
      benchmark::DoNotOptimize(caliber::geometry::triangles_intersect(p.a[0], p.a[1], p.a[2], p.b[0], p.b[1], p.b[2]));
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.pairs.size()));
}

void fcl_intersect(benchmark::State& state, const std::string& scene) {
  const Sample& s = sample(scene);
  for (auto _ : state) {
    for (const TrianglePair& p : s.pairs) {
      Vec3 a[3] = {p.a[0], p.a[1], p.a[2]}, b[3] = {p.b[0], p.b[1], p.b[2]};
      benchmark::DoNotOptimize(fcl::detail::Intersect<double>::intersect_Triangle(a[0], a[1], a[2], b[0], b[1], b[2]));
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.pairs.size()));
}

void leaf_test(benchmark::State& state, const std::string& scene) {
  const Sample& s = sample(scene);
  std::vector<caliber::narrow::Candidate> out;
  out.reserve(s.pairs.size());
  for (auto _ : state) {
    out.clear();
    for (const TrianglePair& p : s.pairs) s.contexts[p.context]->leaf_test(p.ta, p.tb, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.pairs.size()));
  state.counters["kept"] = static_cast<double>(out.size()) / static_cast<double>(std::max<std::size_t>(s.pairs.size(), 1));
}

void leaf_test_buffered(benchmark::State& state, const std::string& scene) {
  const Sample& s = sample(scene);
  std::vector<caliber::narrow::Candidate> out;
  out.reserve(s.pairs.size());
  caliber::narrow::LeafBuffer buffer;
  for (auto _ : state) {
    out.clear();
    for (std::size_t i = 0; i < s.pairs.size(); ++i) {
      const TrianglePair& p = s.pairs[i];
      const caliber::narrow::PairContext& ctx = *s.contexts[p.context];
      ctx.leaf_test(p.ta, p.tb, out, buffer);
      // A buffer holds one object pair's leaf pairs: flushed where the next pair's context differs.
      if (i + 1 == s.pairs.size() || s.pairs[i + 1].context != p.context) ctx.flush_leaves(buffer, out);
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.pairs.size()));
  state.counters["kept"] = static_cast<double>(out.size()) / static_cast<double>(std::max<std::size_t>(s.pairs.size(), 1));
}

/// The share of the kernel's feature pairs that a cheap lower bound shows cannot win, on each scene's
/// pairs: a vertex-face feature pair (a corner of one triangle against the other) is at least the
/// corner's distance to the other's plane; an edge pair is at least the distance to a plane that
/// has both ends of one of the edges on one side. A feature pair whose bound exceeds the pair's final
/// distance (by a relative 1e-9) cannot change the kernel's answer, so this counts what an ideal
/// skip, knowing the answer beforehand and with no rounding margin, could leave out: an upper
/// bound on the saving. "all 8" counts the feature pairs that every pair of a batch of eight could
/// leave out together (what the eight-lane kernel can skip without moving pairs between lanes).
void census() {
  for (const std::string scene : {"two_small", "funnel", "front_car", "two_large"}) {
    const Sample& s = sample(scene);
    std::vector<std::uint16_t> skip(s.pairs.size());  // bit c: feature pair c (9 edge pairs, then 6 corners)
    for (std::size_t k = 0; k < s.pairs.size(); ++k) {
      const TrianglePair& p = s.pairs[k];
      const double d = caliber::geometry::closest_points_triangles(p.a, p.b).distance;
      const double best2 = d * d * (1.0 + 1e-9);
      const Vec3 na = (p.a[1] - p.a[0]).cross(p.a[2] - p.a[0]), nb = (p.b[1] - p.b[0]).cross(p.b[2] - p.b[0]);
      double sa[3], sb[3];  // corners along the other's normal (unnormalized)
      for (int i = 0; i < 3; ++i) {
        sa[i] = nb.dot(p.a[i] - p.b[0]);
        sb[i] = na.dot(p.b[i] - p.a[0]);
      }
      const double na2 = na.squaredNorm(), nb2 = nb.squaredNorm();
      // The squared distance to the plane of normal n (n2 = |n|^2) of an edge whose ends lie s0 and s1.
      const auto side = [](double s0, double s1, double n2) {
        return n2 > 0.0 && s0 * s1 > 0.0 ? std::min(s0 * s0, s1 * s1) / n2 : 0.0;
      };
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          const double bound = std::max(side(sa[i], sa[(i + 1) % 3], nb2), side(sb[j], sb[(j + 1) % 3], na2));
          if (bound > best2) skip[k] |= static_cast<std::uint16_t>(1u << (3 * i + j));
        }
        if (nb2 > 0.0 && sa[i] * sa[i] / nb2 > best2) skip[k] |= static_cast<std::uint16_t>(1u << (9 + 2 * i));
        if (na2 > 0.0 && sb[i] * sb[i] / na2 > best2) skip[k] |= static_cast<std::uint16_t>(1u << (10 + 2 * i));
      }
    }
    std::size_t edges = 0, corners = 0, edges8 = 0, corners8 = 0;
    for (const std::uint16_t m : skip) {
      edges += static_cast<std::size_t>(std::popcount(static_cast<unsigned>(m & 0x1FFu)));
      corners += static_cast<std::size_t>(std::popcount(static_cast<unsigned>(m >> 9)));
    }
    const std::size_t batches = s.pairs.size() / 8;
    for (std::size_t b = 0; b < batches; ++b) {
      unsigned all = 0x7FFF;
      for (std::size_t l = 0; l < 8; ++l) all &= skip[8 * b + l];
      edges8 += static_cast<std::size_t>(std::popcount(all & 0x1FFu));
      corners8 += static_cast<std::size_t>(std::popcount(all >> 9));
    }
    const double n = static_cast<double>(std::max<std::size_t>(s.pairs.size(), 1));
    const double nb = static_cast<double>(std::max<std::size_t>(batches, 1));
    std::printf(
        "%-10s %7zu pairs: edge pairs beaten %5.1f %% (all 8 of a batch %4.1f %%), corners beaten %5.1f %% (all 8 %4.1f %%)\n",
        scene.c_str(), s.pairs.size(), 100.0 * static_cast<double>(edges) / (9.0 * n),
        100.0 * static_cast<double>(edges8) / (9.0 * nb), 100.0 * static_cast<double>(corners) / (6.0 * n),
        100.0 * static_cast<double>(corners8) / (6.0 * nb));
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Our own option first; the rest goes to Google Benchmark.
  std::vector<char*> rest{argv[0]};
  bool counting = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--scenes") == 0 && i + 1 < argc) {
      g_scenes = argv[++i];
    } else if (std::strcmp(argv[i], "--census") == 0) {
      counting = true;
    } else {
      rest.push_back(argv[i]);
    }
  }
  if (!std::filesystem::is_directory(g_scenes)) {
    std::fprintf(stderr, "bench_leaf_kernels: scene folder '%s' not found (--scenes DIR)\n", g_scenes.c_str());
    return 2;
  }
  if (counting) {
    census();
    return 0;
  }
  for (const std::string scene : {"two_small", "funnel", "front_car", "two_large"}) {
    benchmark::RegisterBenchmark(("closest_points/" + scene).c_str(), closest_points<caliber::geometry::closest_points_triangles>,
                                 scene)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("closest_points_portable/" + scene).c_str(),
                                 closest_points<caliber::geometry::detail::closest_points_triangles_portable>, scene)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("closest_points_batch/" + scene).c_str(), closest_points_batch, scene)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("fcl_tri_distance/" + scene).c_str(), fcl_tri_distance, scene)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("intersect/" + scene).c_str(), intersect, scene)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("fcl_intersect/" + scene).c_str(), fcl_intersect, scene)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("leaf_test/" + scene).c_str(), leaf_test, scene)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("leaf_test_buffered/" + scene).c_str(), leaf_test_buffered, scene)
        ->Unit(benchmark::kMillisecond);
  }
  int count = static_cast<int>(rest.size());
  benchmark::Initialize(&count, rest.data());
  if (benchmark::ReportUnrecognizedArguments(count, rest.data())) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
