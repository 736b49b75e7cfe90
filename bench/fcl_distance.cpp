// Peer comparison of the distance query: caliber::query with QueryKind::distance (unbounded)
// against FCL 0.7's fcl::distance on BVHModel<OBBRSS> (exact: rel_err = abs_err = 0, nearest
// points on), on CGAL mesh pairs separated along x by gaps from 1e-6 to 1 of A's box diagonal.
// Reports both distances, their relative difference, whether the closest triangle pair is the same,
// and warm median times of interleaved runs.
//
//   bench_fcl_distance [--meshes DIR] [--repeat R] [--out FILE.md] [--only NAME] [--warm] [--ours-only]
//
// Each round times one caliber query, then one fcl::distance; the medians over R rounds are
// reported. With --warm, each timed query follows an untimed run of itself, so it finds the caches
// and branch history as it left them; without, it follows the other library's query.
// --only runs the cases whose name contains NAME. --ours-only runs caliber's query alone, R times
// per case and gap, and prints its median time (no FCL model, no table): for `perf record`.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fcl/narrowphase/distance.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>
#include <fcl/narrowphase/detail/traversal/distance/mesh_distance_traversal_node.h>

#include "caliber/model.h"
#include "caliber/query.h"
#include "geometry/rigid_move.h"
#include "geometry/triangle_distance.h"
#include "fcl_support.h"
#include "machine.h"

namespace {

using namespace caliber;
using caliber::bench::FclModel;

struct Case {
  std::string name, mesh_a, mesh_b;
  double angle_deg;
  Eigen::Vector3d axis;
};

/// B turned by the case's rotation, then moved along +x so that its box starts `gap` times A's box
/// diagonal beyond A's box (the meshes are then at least that far apart), centered on A in y and z.
Pose place(const Case& c, const Mesh& a, const Mesh& b, double gap) {
  Eigen::Vector3d alo, ahi;
  bench::box(a, alo, ahi);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(c.angle_deg * std::numbers::pi / 180.0, c.axis.normalized()));
  Mesh turned = b;
  for (auto& v : turned.vertices) v = q * v;
  Eigen::Vector3d blo, bhi;
  bench::box(turned, blo, bhi);
  const double diagonal = (ahi - alo).norm();
  Eigen::Vector3d t = 0.5 * (alo + ahi) - 0.5 * (blo + bhi);
  t.x() = ahi.x() + gap * diagonal - blo.x();
  return Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
}

/// The query both sides answer: the exact distance, unbounded.
QueryRequest distance_request() {
  QueryRequest request;
  request.kind = QueryKind::distance;
  request.tolerance = kUnbounded;
  return request;
}

struct Row {
  std::string name;
  double gap;
  double ours, fcl;
  bool same_pair;
  double ours_ms, fcl_ms;
  std::uint64_t node_tests, leaf_tests;
  std::uint64_t fcl_node_tests = 0, fcl_leaf_tests = 0;
};

/// FCL's own bounding-volume and leaf test counts for the same query: the traversal fcl::distance
/// runs for two OBBRSS meshes, with its statistics on.
void fcl_counts(const FclModel& fa, const FclModel& fb, const Pose& pose_b, const fcl::DistanceRequestd& request, Row& row) {
  fcl::detail::MeshDistanceTraversalNodeOBBRSS<double> node;
  fcl::DistanceResultd result;
  fcl::detail::initialize(node, fa, bench::to_fcl(Pose{}), fb, bench::to_fcl(pose_b), request, result);
  node.enable_statistics = true;
  fcl::detail::distance<double>(&node);  // what fcl::distance runs for two meshes (depth first, qsize 2)
  row.fcl_node_tests = static_cast<std::uint64_t>(node.num_bv_tests);
  row.fcl_leaf_tests = static_cast<std::uint64_t>(node.num_leaf_tests);
}

Row run(const Case& c, double gap, const Model& a, const Model& b, const std::shared_ptr<FclModel>& fa,
        const std::shared_ptr<FclModel>& fb, int repeat, bool warm) {
  const Pose pose_b = place(c, a.mesh(), b.mesh(), gap);
  const QueryRequest request = distance_request();
  fcl::CollisionObjectd oa(fa, bench::to_fcl(Pose{}));
  fcl::CollisionObjectd ob(fb, bench::to_fcl(pose_b));
  fcl::DistanceRequestd freq(true, true, 0.0, 0.0);
  QueryResult ours = query(a, Pose{}, b, pose_b, request);
  fcl::DistanceResultd fres;
  fcl::distance(&oa, &ob, freq, fres);
  // Interleaved, one of each per round; medians. Warm: each timed run right after an untimed run of
  // the same query (its caches and branch history its own, not the other library's).
  const auto ours_once = [&] { ours = query(a, Pose{}, b, pose_b, request); };
  const auto fcl_once = [&] {
    fres.clear();
    fcl::distance(&oa, &ob, freq, fres);
  };
  std::vector<double> t_ours, t_fcl;
  for (int r = 0; r < repeat; ++r) {
    if (warm) ours_once();
    t_ours.push_back(bench::median_ms(1, ours_once));
    if (warm) fcl_once();
    t_fcl.push_back(bench::median_ms(1, fcl_once));
  }
  std::sort(t_ours.begin(), t_ours.end());
  std::sort(t_fcl.begin(), t_fcl.end());
  Row row{c.name,
          gap,
          ours.contacts.front().distance,
          fres.min_distance,
          false,
          t_ours[repeat / 2],
          t_fcl[repeat / 2],
          ours.stats.node_tests,
          ours.stats.leaf_tests};
  // FCL keeps the first of several pairs at the same distance (a shared vertex closest, say), we the
  // lowest ids: FCL's pair agrees when our kernel gives it our distance.
  const auto& ta = a.mesh().triangles[static_cast<std::size_t>(fres.b1)];
  const auto& tb = b.mesh().triangles[static_cast<std::size_t>(fres.b2)];
  // B's corners in A's frame (A at the identity) as the query moves them (PairContext::b_vertex).
  const geometry::RigidMove move(pose_b.rotation_matrix(), pose_b.translation);
  const Eigen::Vector3d va[3] = {a.mesh().vertices[ta[0]], a.mesh().vertices[ta[1]], a.mesh().vertices[ta[2]]};
  const Eigen::Vector3d vb[3] = {move(b.mesh().vertices[tb[0]]), move(b.mesh().vertices[tb[1]]), move(b.mesh().vertices[tb[2]])};
  row.same_pair = geometry::closest_points_triangles(va, vb).distance == row.ours;
  fcl_counts(*fa, *fb, pose_b, freq, row);
  return row;
}

/// The options: the meshes' folder, the rounds, the report's file, the cases to run (by name), and --warm and --ours-only.
struct Options {
  std::filesystem::path dir = bench::default_meshes_dir();
  int repeat = 7;
  std::string out, only;
  bool ours_only = false, warm = false;
};

/// The options of the command line, or none (the usage said on stderr) for one it does not know.
std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--meshes") && i + 1 < argc)
      o.dir = argv[++i];
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc)
      o.repeat = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--out") && i + 1 < argc)
      o.out = argv[++i];
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc)
      o.only = argv[++i];
    else if (!std::strcmp(argv[i], "--ours-only"))
      o.ours_only = true;
    else if (!std::strcmp(argv[i], "--warm"))
      o.warm = true;
    else {
      std::fprintf(
          stderr, "usage: bench_fcl_distance [--meshes DIR] [--repeat R] [--out FILE.md] [--only NAME] [--warm] [--ours-only]\n");
      return std::nullopt;
    }
  }
  return o;
}

/// --ours-only on one case: caliber's query alone at each gap, its median time and work printed.
void run_ours_only(const Case& c, const Model& a, const Model& b, int repeat) {
  for (const double gap : {1e-6, 1e-3, 1e-2, 0.1, 1.0}) {
    const Pose pose_b = place(c, a.mesh(), b.mesh(), gap);
    const QueryRequest request = distance_request();
    QueryResult ours;
    const double ms = bench::median_ms(repeat, [&] { ours = query(a, Pose{}, b, pose_b, request); });
    std::printf("%s gap %g: %.12g in %.4f ms (median of %d), %llu node tests, %llu leaf tests\n", c.name.c_str(), gap,
                ours.contacts.front().distance, ms, repeat, static_cast<unsigned long long>(ours.stats.node_tests),
                static_cast<unsigned long long>(ours.stats.leaf_tests));
  }
}

/// A line of the table: both distances, their relative difference, the pair, the times and the work.
std::string format_row(const Row& r) {
  const double rel = std::abs(r.ours - r.fcl) / std::max(std::abs(r.fcl), 1e-300);
  char line[512];
  std::snprintf(line, sizeof line, "| %s | %g | %.12g | %.12g | %.2e | %s | %.3f | %.3f | %.2f | %llu | %llu | %llu | %llu |\n",
                r.name.c_str(), r.gap, r.ours, r.fcl, rel, r.same_pair ? "yes" : "no", r.ours_ms, r.fcl_ms, r.ours_ms / r.fcl_ms,
                static_cast<unsigned long long>(r.node_tests), static_cast<unsigned long long>(r.leaf_tests),
                static_cast<unsigned long long>(r.fcl_node_tests), static_cast<unsigned long long>(r.fcl_leaf_tests));
  return line;
}

/// One case against FCL at each gap: its lines printed and added to `table`.
void run_with_fcl(const Case& c, const std::shared_ptr<const Model>& a, const std::shared_ptr<const Model>& b, const Options& o,
                  std::string& table) {
  const auto fa = bench::build_fcl(a->mesh());
  const auto fb = c.mesh_b == c.mesh_a ? fa : bench::build_fcl(b->mesh());
  for (const double gap : {1e-6, 1e-3, 1e-2, 0.1, 1.0}) {
    const std::string line = format_row(run(c, gap, *a, *b, fa, fb, o.repeat, o.warm));
    table += line;
    std::fputs(line.c_str(), stdout);
    std::fflush(stdout);
  }
}

/// Writes the report to `o.out`: the machine, the method, then the table.
void write_report(const Options& o, const std::string& table) {
  std::ofstream f(o.out);
  f << "# Distance query against FCL\n\n"
    << caliber::bench::machine_description() << "\n\n"
    << "caliber::query (QueryKind::distance, unbounded) against fcl::distance (BVHModel<OBBRSS>, rel_err = abs_err = 0, "
       "nearest points on); B turned, then moved along +x to start `gap` × A's box diagonal beyond A's box. Times: median of "
    << o.repeat << " rounds, each timing one caliber query then one FCL query"
    << (o.warm ? ", each right after an untimed run of itself (--warm)" : ", each right after the other library's (alternating)")
    << ".\n\n"
    << table;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> o = parse(argc, argv);
  if (!o) return 2;
  const std::vector<Case> cases = {
      {"bunny x bunny", "bunny00.off", "bunny00.off", 25, {0, 1, 1}},
      {"armadillo x armadillo", "armadillo.off", "armadillo.off", 30, {1, 2, 0.5}},
      {"dragon x dragon", "ChineseDragon-10kv.off", "ChineseDragon-10kv.off", 20, {1, 0, 1}},
      {"turbine x blade", "turbine.off", "blade.off", 10, {0, 0, 1}},
      {"fandisk x rotor", "fandisk_large.off", "rotor_small.off", 15, {1, 0, 0}},
  };
  std::string table =
      "| case | gap (× diagonal) | caliber distance | FCL distance | relative difference | FCL's pair at our distance | "
      "caliber ms | FCL ms | caliber / FCL | node tests | leaf tests | FCL node tests | FCL leaf tests |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  BuildOptions bvh_only;
  bvh_only.adjacency = false;
  bvh_only.oriented_boxes = true;  // as the CLI and scenes build for distance queries
  int selected = 0;
  for (const Case& c : cases) {
    if (c.name.find(o->only) == std::string::npos) continue;
    ++selected;
    for (const std::string& mesh : {c.mesh_a, c.mesh_b}) {
      if (!std::filesystem::exists(o->dir / mesh)) {
        std::fprintf(stderr, "bench_fcl_distance: %s is missing (run scripts/fetch_meshes.sh, or pass --meshes DIR)\n",
                     (o->dir / mesh).c_str());
        return 2;
      }
    }
    const auto a = build_model(load_mesh(o->dir / c.mesh_a), bvh_only);
    const auto b = c.mesh_b == c.mesh_a ? a : build_model(load_mesh(o->dir / c.mesh_b), bvh_only);
    if (o->ours_only) {
      run_ours_only(c, *a, *b, o->repeat);
      continue;
    }
    run_with_fcl(c, a, b, *o, table);
  }
  if (selected == 0) {
    std::fprintf(stderr, "bench_fcl_distance: no case's name contains \"%s\" (--only)\n", o->only.c_str());
    return 2;
  }
  if (!o->out.empty()) write_report(*o, table);
  return 0;
}
