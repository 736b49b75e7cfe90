// Peer comparison: caliber's interference query (every intersecting triangle pair), sequential and
// with the stealing engine on 2 threads, against Embree 3's rtcCollide on user geometry (a
// triangle's float box) on 1 and 2 threads, its candidates through caliber's exact test, on five
// posed pairs of CGAL meshes in interleaved rounds (medians); both pair sets and Embree's build of B.
//
//   bench_embree_compare [--meshes DIR] [--rounds R] [--calls N] [--out FILE.md] [--commit HASH]
//
// --calls N: each contender's time in a round is the median of N calls in a row after its warm-up
// call (1, the default: one call, with the caches as the other contenders left them).

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <embree3/rtcore.h>

#include "caliber/engine.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
#include "geometry/rigid_move.h"
#include "geometry/triangle_distance.h"
#include "geometry/triangle_intersect.h"
#include "bench_support.h"
#include "machine.h"

namespace {

using caliber::bench::git_commit;
using caliber::bench::median;
using caliber::bench::median_ms;
using TriPair = std::pair<std::uint32_t, std::uint32_t>;  // (triangle of A, triangle of B)
using Vertices = std::vector<Eigen::Vector3d>;

/// B's pose: a rotation about its own box center, and where that center goes, as a fraction of A's
/// box diagonal away from A's box center (bench_fcl_compare's place()). A stays at the identity.
struct Case {
  std::string name, mesh_a, mesh_b;
  double angle_deg;
  Eigen::Vector3d axis, offset;
};

caliber::Pose place(const Case& c, const caliber::Mesh& a, const caliber::Mesh& b) {
  Eigen::Vector3d ca, cb;
  double da, db;
  caliber::bench::box_center(a, ca, da);
  caliber::bench::box_center(b, cb, db);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(c.angle_deg * std::numbers::pi / 180.0, c.axis.normalized()));
  const Eigen::Vector3d t = ca + c.offset * da - q * cb;
  return caliber::Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
}

/// B's vertices in A's frame (A at the identity) as the leaf test moves them (b_vertex): the same bits.
Vertices posed(const caliber::Mesh& m, const caliber::Pose& pose) {
  const caliber::geometry::RigidMove move(pose.rotation_matrix(), pose.translation);
  Vertices out(m.vertices.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = move(m.vertices[i]);
  return out;
}

/// One side's triangles as Embree sees them: the mesh's triangles over (posed) double vertices.
struct Geometry {
  const std::vector<std::array<std::uint32_t, 3>>* triangles;
  const Vertices* vertices;
  void corners(std::uint32_t t, Eigen::Vector3d out[3]) const {
    for (int k = 0; k < 3; ++k) out[k] = (*vertices)[(*triangles)[t][k]];
  }
};

/// x rounded to a float toward `way` (-1: down, +1: up): the nearest, one step out if on the wrong side.
float outward(double x, float way) {
  const float f = static_cast<float>(x);
  return (static_cast<double>(f) - x) * way < 0.0 ? std::nextafter(f, way * std::numeric_limits<float>::infinity()) : f;
}

/// Embree's bounds callback: the triangle's double box, rounded outward to floats (conservative).
void triangle_bounds(const RTCBoundsFunctionArguments* args) {
  Eigen::Vector3d c[3];
  static_cast<const Geometry*>(args->geometryUserPtr)->corners(args->primID, c);
  const Eigen::Vector3d lo = c[0].cwiseMin(c[1]).cwiseMin(c[2]), hi = c[0].cwiseMax(c[1]).cwiseMax(c[2]);
  RTCBounds* b = args->bounds_o;
  b->lower_x = outward(lo.x(), -1), b->lower_y = outward(lo.y(), -1), b->lower_z = outward(lo.z(), -1);
  b->upper_x = outward(hi.x(), 1), b->upper_y = outward(hi.y(), 1), b->upper_z = outward(hi.z(), 1);
}

/// One line on stderr, then exit with `code` (2: a bad option).
[[noreturn]] void fail(const std::string& message, int code) {
  std::fprintf(stderr, "bench_embree_compare: %s\n", message.c_str());
  std::exit(code);
}

/// A scene of one user geometry, one primitive per triangle, committed (built).
RTCScene build_scene(RTCDevice device, const Geometry& g) {
  RTCScene scene = rtcNewScene(device);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(g.triangles->size()));
  rtcSetGeometryUserData(geometry, const_cast<Geometry*>(&g));
  rtcSetGeometryBoundsFunction(geometry, triangle_bounds, nullptr);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  return scene;
}

/// What rtcCollide's callbacks found: one buffer per thread that called back (no lock but the
/// first call of each thread; a cache line each), so there are as many buffers as threads used.
struct Collector {
  struct alignas(64) Hits {
    std::vector<TriPair> pairs;
    std::size_t candidates = 0;
  };
  Collector(const Geometry& a, const Geometry& b) : a(a), b(b) {}
  Geometry a, b;
  std::uint64_t id = next_id.fetch_add(1);
  std::mutex mutex;
  std::deque<Hits> hits;
  static inline std::atomic<std::uint64_t> next_id{1};
  Hits& mine() {
    thread_local std::uint64_t seen = 0;
    thread_local Hits* own = nullptr;
    if (seen != id) {
      const std::lock_guard<std::mutex> lock(mutex);
      own = &hits.emplace_back();
      seen = id;
    }
    return *own;
  }
};

/// rtcCollide's callback: caliber's exact test (the one its interference leaf test calls) on each
/// candidate, a primitive pair of two overlapping leaves of the scenes' BVHs.
void collide_pairs(void* user, RTCCollision* collisions, unsigned int count) {
  auto& c = *static_cast<Collector*>(user);
  Collector::Hits& hits = c.mine();
  hits.candidates += count;
  for (unsigned int i = 0; i < count; ++i) {
    Eigen::Vector3d a[3], b[3];
    c.a.corners(collisions[i].primID0, a);
    c.b.corners(collisions[i].primID1, b);
    if (caliber::geometry::triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2]))
      hits.pairs.emplace_back(collisions[i].primID0, collisions[i].primID1);
  }
}

/// A loaded case: caliber's models, B's pose and B's posed vertices.
struct Prepared {
  Case c;
  std::shared_ptr<const caliber::Model> a, b;
  caliber::Pose pose_b;
  Vertices posed_b;
  Geometry geometry_a() const { return {&a->mesh().triangles, &a->mesh().vertices}; }
  Geometry geometry_b() const { return {&b->mesh().triangles, &posed_b}; }
};

struct EmbreeRun {
  double build_ms = 0.0, collide_ms = 0.0;
  std::vector<TriPair> pairs;
  std::size_t candidates = 0, threads = 0;
  bool same_calls = true;  ///< every timed call found the same pairs
};

/// One Embree turn on a device of its own, the only one alive ("threads=N": Embree 3 on TBB caps all
/// threads at the largest count of the live devices, one tbb::global_control). B's build (posing, then
/// the scene) is timed once, rtcCollide (after an untimed warm-up call) `calls` times; A's build is not.
EmbreeRun run_embree(const Prepared& p, int threads, int calls) {
  const std::string config = "threads=" + std::to_string(threads);
  RTCDevice device = rtcNewDevice(config.c_str());
  if (device == nullptr) fail("rtcNewDevice(\"" + config + "\") failed", 1);
  const Geometry ga = p.geometry_a();
  RTCScene scene_a = build_scene(device, ga);
  Vertices vertices_b;
  const Geometry gb{&p.b->mesh().triangles, &vertices_b};
  RTCScene scene_b = nullptr;
  EmbreeRun run;
  run.build_ms = median_ms(1, [&] {
    vertices_b = posed(p.b->mesh(), p.pose_b);
    scene_b = build_scene(device, gb);
  });
  Collector warm(ga, gb);
  rtcCollide(scene_a, scene_b, collide_pairs, &warm);
  std::deque<Collector> timed;  // one a call, made before the clock starts
  for (int k = 0; k < calls; ++k) timed.emplace_back(ga, gb);
  run.collide_ms =
      median_ms(calls, [&, call = std::size_t{0}]() mutable { rtcCollide(scene_a, scene_b, collide_pairs, &timed[call++]); });
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) fail("Embree reported an error on " + p.c.name, 1);
  for (const Collector& c : timed) {  // each call's pairs compared with the call's before; the last kept
    std::vector<TriPair> pairs;
    run.candidates = 0;
    for (const Collector::Hits& h : c.hits) {
      pairs.insert(pairs.end(), h.pairs.begin(), h.pairs.end());
      run.candidates += h.candidates;
    }
    std::sort(pairs.begin(), pairs.end());
    run.same_calls = run.same_calls && (&c == &timed.front() || pairs == run.pairs);
    run.pairs = std::move(pairs);
    run.threads = std::max(run.threads, c.hits.size());
  }
  rtcReleaseScene(scene_b);
  rtcReleaseScene(scene_a);
  rtcReleaseDevice(device);
  return run;
}

/// Per case, over the rounds: the times of each contender and what the pair sets looked like.
struct Row {
  std::size_t pairs_caliber = 0, pairs_embree = 0, only_caliber = 0, only_embree = 0;
  std::size_t only_touching = 0;  ///< mismatched pairs at distance 0 by the closest points (touching)
  std::size_t candidates = 0, threads_1 = 0, threads_2 = 0;
  std::uint64_t leaf_tests = 0;  ///< caliber's exact tests (the sequential query's)
  bool stealing_same = true, embree_stable = true;
  std::vector<double> seq_ms, stealing_ms, embree1_ms, embree2_ms, build_ms;
};

std::vector<TriPair> pairs_of(const std::vector<caliber::Contact>& contacts) {
  std::vector<TriPair> out;
  for (const caliber::Contact& c : contacts) out.emplace_back(c.tri_a, c.tri_b);
  std::sort(out.begin(), out.end());
  return out;
}

/// Compares Embree's pairs with caliber's (the first round's): the differences, and how many of
/// them touch (closest-point distance 0).
void compare_sets(const Prepared& p, const std::vector<TriPair>& ours, const EmbreeRun& theirs, Row& row) {
  std::vector<TriPair> only_ours, only_theirs;
  std::set_difference(ours.begin(), ours.end(), theirs.pairs.begin(), theirs.pairs.end(), std::back_inserter(only_ours));
  std::set_difference(theirs.pairs.begin(), theirs.pairs.end(), ours.begin(), ours.end(), std::back_inserter(only_theirs));
  row.pairs_caliber = ours.size(), row.pairs_embree = theirs.pairs.size(), row.candidates = theirs.candidates;
  row.only_caliber = only_ours.size(), row.only_embree = only_theirs.size();
  for (const auto* list : {&only_ours, &only_theirs}) {
    for (const TriPair& t : *list) {
      Eigen::Vector3d a[3], b[3];
      p.geometry_a().corners(t.first, a);
      p.geometry_b().corners(t.second, b);
      if (caliber::geometry::closest_points_triangles(a, b).distance == 0.0) ++row.only_touching;
    }
  }
}

/// One round of one case: every contender once, each after an untimed warm-up call.
void run_round(const Prepared& p, caliber::Engine& stealing, bool first, int calls, Row& row) {
  const caliber::Pose identity;
  caliber::QueryRequest request;  // interference: every intersecting triangle pair
  caliber::QueryResult seq = caliber::query(*p.a, identity, *p.b, p.pose_b, request);
  row.seq_ms.push_back(median_ms(calls, [&] { seq = caliber::query(*p.a, identity, *p.b, p.pose_b, request); }));
  const std::vector<TriPair> ours = pairs_of(seq.contacts);
  row.leaf_tests = seq.stats.leaf_tests;
  const EmbreeRun one = run_embree(p, 1, calls);
  row.embree1_ms.push_back(one.collide_ms);
  row.build_ms.push_back(one.build_ms);
  if (first) compare_sets(p, ours, one, row);
  row.threads_1 = std::max(row.threads_1, one.threads);
  caliber::Frame frame{{p.a, p.b}, {identity, p.pose_b}, {{0, 1}}, request};
  caliber::StepResult step = stealing.step(frame);
  row.stealing_ms.push_back(median_ms(calls, [&] { step = stealing.step(frame); }));
  row.stealing_same = row.stealing_same && pairs_of(step.contacts) == ours;
  const EmbreeRun two = run_embree(p, 2, calls);
  row.embree2_ms.push_back(two.collide_ms);
  row.embree_stable =
      row.embree_stable && one.same_calls && two.same_calls && two.pairs == one.pairs && one.pairs.size() == row.pairs_embree;
  row.threads_2 = std::max(row.threads_2, two.threads);
}

/// Appends a case's line to the main table and to the details table.
void format_row(const Prepared& p, const Row& r, std::string& table, std::string& details) {
  const double seq = median(r.seq_ms), e1 = median(r.embree1_ms), st = median(r.stealing_ms), e2 = median(r.embree2_ms);
  char line[512];
  std::snprintf(line, sizeof line,
                "| %s | %zu × %zu | %zu | %zu | %zu | %zu | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n", p.c.name.c_str(),
                p.a->triangle_count(), p.b->triangle_count(), r.pairs_caliber, r.pairs_embree, r.only_caliber, r.only_embree, seq,
                e1, seq / e1, st, e2, st / e2, median(r.build_ms));
  table += line;
  std::snprintf(line, sizeof line, "| %s | %llu | %zu | %zu | %zu / %zu | %s | %s |\n", p.c.name.c_str(),
                static_cast<unsigned long long>(r.leaf_tests), r.candidates, r.only_touching, r.threads_1, r.threads_2,
                r.stealing_same ? "yes" : "NO", r.embree_stable ? "yes" : "NO");
  details += line;
}

struct Options {
  std::filesystem::path meshes = caliber::bench::default_meshes_dir();
  int rounds = 5, calls = 1;
  std::string out, commit, command;
};

Options parse(int argc, char** argv) {
  Options o;
  o.command = argv[0];
  for (int i = 1; i < argc; ++i) o.command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg != "--meshes" && arg != "--rounds" && arg != "--calls" && arg != "--out" && arg != "--commit")
      fail("unknown option " + arg + " (options: --meshes DIR --rounds R --calls N --out FILE.md --commit HASH)", 2);
    if (i + 1 >= argc) fail(arg + " needs a value", 2);
    const std::string value = argv[++i];
    if (arg == "--meshes") o.meshes = value;
    if (arg == "--out") o.out = value;
    if (arg == "--commit") o.commit = value;
    if (arg == "--rounds" || arg == "--calls") {
      char* end = nullptr;
      const long r = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || *end != '\0' || r < 1 || r > 1000) fail(arg + " needs an integer in 1..1000, got " + value, 2);
      (arg == "--rounds" ? o.rounds : o.calls) = static_cast<int>(r);
    }
  }
  return o;
}

/// Loads each case whose meshes are in `dir` (a note on stderr for the others) and poses B.
std::vector<Prepared> load(const std::vector<Case>& cases, const std::filesystem::path& dir) {
  std::vector<Prepared> out;
  for (const Case& c : cases) {
    if (!std::filesystem::exists(dir / c.mesh_a) || !std::filesystem::exists(dir / c.mesh_b)) {
      std::fprintf(stderr, "skipping %s: meshes missing in %s (run scripts/fetch_meshes.sh)\n", c.name.c_str(), dir.c_str());
      continue;
    }
    Prepared& p = out.emplace_back();
    p.c = c;
    p.a = caliber::build_model(caliber::load_mesh(dir / c.mesh_a));
    p.b = caliber::build_model(caliber::load_mesh(dir / c.mesh_b));
    p.pose_b = place(c, p.a->mesh(), p.b->mesh());
    p.posed_b = posed(p.b->mesh(), p.pose_b);
  }
  return out;
}

/// The file's title, provenance and method (bench/results/intel-xeon-2c/kernels/README.md says more).
std::string header_of(const Options& o) {
  char today[16];
  const std::time_t now = std::time(nullptr);
  std::strftime(today, sizeof today, "%Y-%m-%d", std::gmtime(&now));
  return "# caliber vs Embree " RTC_VERSION_STRING " rtcCollide: interference, every intersecting triangle pair\n\nMachine: " +
         caliber::bench::machine_description() + "\n\nDate: " + today + ", commit " + o.commit + ", " + std::to_string(o.rounds) +
         " interleaved rounds, medians" +
         (o.calls > 1 ? " of " + std::to_string(o.calls) + " calls in a row in each" : std::string()) + "\n\nCommand: `" +
         o.command + "`\n\n" +
         "A at the identity, B posed. Embree: user geometry (a triangle's double box rounded outward to floats), "
         "every candidate through caliber's exact test; one device alive at a time (`threads=1`, then `threads=2`), "
         "A's and B's scenes built at the start of its turn. B build: posing B's vertices and rtcCommitScene (caliber "
         "builds its models once, for any pose). Ratios: caliber / Embree (below 1: caliber faster).\n\n";
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parse(argc, argv);
  if (o.commit.empty()) o.commit = git_commit();
  // Overlapping, rotated copies; offsets are fractions of A's box diagonal.
  const std::vector<Case> cases = {
      {"bunny × bunny", "bunny00.off", "bunny00.off", 90, {-1, 0, 1}, {0.06, -0.2, -0.1}},
      {"armadillo × armadillo", "armadillo.off", "armadillo.off", 45, {0, 1, 1}, {0.2, 0.04, 0.03}},
      {"elephant × elephant (refined)", "refined_elephant.off", "refined_elephant.off", 120, {-1, 1, 2}, {0.12, 0.02, 0.13}},
      {"turbine × turbine", "turbine.off", "turbine.off", 45, {1, -1, 1}, {0.03, -0.07, -0.15}},
      {"bunny × elephant (refined)", "bunny00.off", "refined_elephant.off", 45, {-1, 1, 2}, {-0.14, 0.16, 0.12}},
  };
  const std::vector<Prepared> prepared = load(cases, o.meshes);
  if (prepared.empty()) {
    std::fprintf(stderr, "bench_embree_compare: none of the meshes is in %s (run scripts/fetch_meshes.sh, or --meshes DIR)\n",
                 o.meshes.c_str());
    return 2;
  }
  caliber::EngineOptions options;
  options.method = caliber::Method::stealing, options.threads = 2;
  caliber::Engine stealing(options);
  std::vector<Row> rows(prepared.size());
  for (int round = 0; round < o.rounds; ++round) {
    for (std::size_t i = 0; i < prepared.size(); ++i) run_round(prepared[i], stealing, round == 0, o.calls, rows[i]);
  }
  std::string table =
      "| pair | triangles A × B | contacts caliber | contacts Embree | only caliber | only Embree | caliber seq (ms) | "
      "Embree 1 thread (ms) | ratio caliber / Embree | caliber stealing 2 threads (ms) | Embree 2 threads (ms) | "
      "ratio caliber / Embree | Embree build of B, 1 thread (ms) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::string details =
      "| pair | caliber exact tests | Embree candidates (exact tests) | mismatched pairs touching | threads that called back, "
      "1 / 2 | stealing pairs = sequential | Embree pairs same in every run |\n|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < prepared.size(); ++i) format_row(prepared[i], rows[i], table, details);
  const std::string header = header_of(o);
  std::printf("%s%s\n%s", header.c_str(), table.c_str(), details.c_str());
  if (!o.out.empty()) {
    std::ofstream file(o.out);
    file << header << table << "\n" << details;
    if (!file) fail("cannot write " + o.out, 1);
  }
  return 0;
}
