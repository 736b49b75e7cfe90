// Peer comparison: caliber's sequential interference query against FCL 0.7's BVHModel<OBBRSS>
// collide with every contact, on CGAL meshes (rotated, overlapping copies). Reports the BVH build
// and query times (medians), their ratios, and whether the triangle-pair sets are identical; then
// the first pair only (ours with max_pairs = 1, FCL with num_max_contacts = 1).
//
//   bench_fcl_compare [--meshes DIR] [--repeat R] [--out FILE.md] [--scenes A.json,B.json] [--steps 0,50,100]
//                     [--no-mesh-pairs]
// With --scenes, also every pair of each scene's broad phase at the given steps.

#include <numbers>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/traversal/collision/mesh_collision_traversal_node.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>

#include "caliber/mesh.h"
#include "geometry/triangle_distance.h"
#include "geometry/triangle_intersect.h"
#include "narrow/candidate.h"
#include "caliber/model.h"
#include "caliber/query.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "fcl_support.h"
#include "machine.h"

namespace {

using caliber::bench::box_center;
using caliber::bench::build_fcl;
using caliber::bench::FclModel;
using caliber::bench::median_ms;
using caliber::bench::to_fcl;

/// Rotation of B about its own box center, and where that center goes, as a fraction of A's box
/// diagonal away from A's box center. A stays at the identity.
struct Case {
  std::string name;
  std::string mesh_a, mesh_b;
  double angle_deg;
  Eigen::Vector3d axis;
  Eigen::Vector3d offset;
};

caliber::Pose place(const Case& c, const caliber::Mesh& a, const caliber::Mesh& b) {
  Eigen::Vector3d ca, cb;
  double da, db;
  box_center(a, ca, da);
  box_center(b, cb, db);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(c.angle_deg * std::numbers::pi / 180.0, c.axis.normalized()));
  const Eigen::Vector3d t = ca + c.offset * da - q * cb;
  return caliber::Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
}

struct Row {
  std::string name;
  std::size_t tris_a, tris_b;
  double build_ours, build_fcl, query_ours, query_fcl;
  std::size_t pairs_ours, pairs_fcl, only_ours, only_fcl;
  /// Pairs only FCL reports, checked in world coordinates: how many our exact test says intersect
  /// (a miss of ours), and the largest closest-point distance among them (> 0: FCL's false positive).
  std::size_t only_fcl_exact_hits;
  double only_fcl_max_distance;
  std::uint64_t node_tests, leaf_tests;
  long fcl_bv_tests, fcl_leaf_tests;
  /// Any intersecting pair: ours with max_pairs = 1 (--first), FCL's with num_max_contacts = 1.
  double first_ours, first_fcl;
  bool first_agrees = true;  ///< both found a pair exactly when the full queries did
};

/// Adds one pair's query (ours and FCL's, timed, plus FCL's work counters) to `row`.
void compare_pair(const caliber::Model& ours_a, const caliber::Pose& pose_a, const caliber::Model& ours_b,
                  const caliber::Pose& pose_b, const std::shared_ptr<FclModel>& fcl_a, const std::shared_ptr<FclModel>& fcl_b,
                  int repeat, Row& row) {
  caliber::QueryResult ours;
  row.query_ours += median_ms(repeat, [&] { ours = caliber::query(ours_a, pose_a, ours_b, pose_b, {}); });

  fcl::CollisionObjectd obj_a(fcl_a, to_fcl(pose_a));
  fcl::CollisionObjectd obj_b(fcl_b, to_fcl(pose_b));
  fcl::CollisionRequestd request(100000000, false);  // every contact, no contact geometry
  fcl::CollisionResultd fcl_result;
  row.query_fcl += median_ms(repeat, [&] {
    fcl_result.clear();
    fcl::collide(&obj_a, &obj_b, request, fcl_result);
  });

  caliber::QueryRequest first;
  first.max_pairs = 1;
  caliber::QueryResult one;
  row.first_ours += median_ms(repeat, [&] { one = caliber::query(ours_a, pose_a, ours_b, pose_b, first); });
  const fcl::CollisionRequestd one_request(1, false);
  fcl::CollisionResultd one_result;
  row.first_fcl += median_ms(repeat, [&] {
    one_result.clear();
    fcl::collide(&obj_a, &obj_b, one_request, one_result);
  });
  row.first_agrees =
      row.first_agrees && one.contacts.empty() == ours.contacts.empty() && one_result.isCollision() == fcl_result.isCollision();

  std::vector<caliber::TrianglePair> theirs;
  for (std::size_t i = 0; i < fcl_result.numContacts(); ++i) {
    const auto& contact = fcl_result.getContact(i);
    theirs.push_back({static_cast<std::uint32_t>(contact.b1), static_cast<std::uint32_t>(contact.b2)});
  }
  std::sort(theirs.begin(), theirs.end());
  std::vector<caliber::TrianglePair> mine, only_ours, only_fcl;
  for (const caliber::Contact& c : ours.contacts) mine.push_back({c.tri_a, c.tri_b});
  std::set_difference(mine.begin(), mine.end(), theirs.begin(), theirs.end(), std::back_inserter(only_ours));
  std::set_difference(theirs.begin(), theirs.end(), mine.begin(), mine.end(), std::back_inserter(only_fcl));
  for (const caliber::TrianglePair& p : only_fcl) {
    Eigen::Vector3d ta[3], tb[3];
    for (int k = 0; k < 3; ++k) {
      ta[k] = pose_a.apply(ours_a.mesh().vertices[ours_a.mesh().triangles[p.tri_a][k]]);
      tb[k] = pose_b.apply(ours_b.mesh().vertices[ours_b.mesh().triangles[p.tri_b][k]]);
    }
    if (caliber::geometry::triangles_intersect(ta[0], ta[1], ta[2], tb[0], tb[1], tb[2])) ++row.only_fcl_exact_hits;
    row.only_fcl_max_distance = std::max(row.only_fcl_max_distance, caliber::geometry::closest_points_triangles(ta, tb).distance);
  }
  row.pairs_ours += ours.contacts.size();
  row.pairs_fcl += theirs.size();
  row.only_ours += only_ours.size();
  row.only_fcl += only_fcl.size();
  row.node_tests += ours.stats.node_tests;
  row.leaf_tests += ours.stats.leaf_tests;
  // FCL's own work counters, from one untimed run of the same traversal with statistics on.
  fcl::detail::MeshCollisionTraversalNodeOBBRSS<double> node;
  fcl::CollisionResultd counted;
  fcl::detail::initialize(node, *fcl_a, to_fcl(pose_a), *fcl_b, to_fcl(pose_b), request, counted);
  node.enable_statistics = true;
  fcl::detail::collide(&node);
  row.fcl_bv_tests += node.num_bv_tests;
  row.fcl_leaf_tests += node.num_leaf_tests;
}

Row run_case(const Case& c, const std::filesystem::path& dir, int repeat) {
  const caliber::Mesh mesh_a = caliber::load_mesh(dir / c.mesh_a);
  const caliber::Mesh mesh_b = caliber::load_mesh(dir / c.mesh_b);
  const caliber::Pose pose_b = place(c, mesh_a, mesh_b);
  Row row{};
  row.name = c.name;
  row.tris_a = mesh_a.triangles.size();
  row.tris_b = mesh_b.triangles.size();

  caliber::BuildOptions bvh_only;
  bvh_only.adjacency = false;  // FCL builds no adjacency either
  std::shared_ptr<const caliber::Model> ours_a, ours_b;
  row.build_ours = median_ms(repeat, [&] { ours_a = caliber::build_model(mesh_a, bvh_only); });
  ours_b = caliber::build_model(mesh_b, bvh_only);
  std::shared_ptr<FclModel> fcl_a, fcl_b;
  row.build_fcl = median_ms(repeat, [&] { fcl_a = build_fcl(mesh_a); });
  fcl_b = build_fcl(mesh_b);
  compare_pair(*ours_a, caliber::Pose{}, *ours_b, pose_b, fcl_a, fcl_b, repeat, row);
  return row;
}

/// A scene at several steps: every pair of the broad phase, our sequential interference
/// query against FCL's on the same poses. Build times: every distinct model of the scene, summed.
std::vector<Row> run_scene(const std::filesystem::path& file, const std::vector<int>& steps, int repeat) {
  const caliber::World world(caliber::load_scene(file));
  caliber::BuildOptions bvh_only;
  bvh_only.adjacency = false;
  std::map<const caliber::Model*, std::shared_ptr<const caliber::Model>> ours;
  std::map<const caliber::Model*, std::shared_ptr<FclModel>> theirs;
  double build_ours_ms = 0.0, build_fcl_ms = 0.0;
  std::size_t triangles = 0;
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    const caliber::Model* key = &world.model(i);
    if (ours.count(key)) continue;
    build_ours_ms += median_ms(repeat, [&] { ours[key] = caliber::build_model(key->mesh(), bvh_only); });
    build_fcl_ms += median_ms(repeat, [&] { theirs[key] = build_fcl(key->mesh()); });
    triangles += key->mesh().triangles.size();
  }
  std::vector<Row> rows;
  for (const int k : steps) {
    if (k >= world.scene().steps) continue;
    Row row{};
    row.name = world.scene().name + " step " + std::to_string(k);
    row.tris_a = triangles;
    row.build_ours = build_ours_ms;
    row.build_fcl = build_fcl_ms;
    const std::vector<caliber::Pose> poses = world.poses_at(k);
    const std::vector<caliber::ObjectPair> pairs = world.broad_phase(poses);
    row.tris_b = pairs.size();
    for (const caliber::ObjectPair& p : pairs) {
      const caliber::Model* a = &world.model(p.a);
      const caliber::Model* b = &world.model(p.b);
      compare_pair(*ours[a], poses[p.a], *ours[b], poses[p.b], theirs[a], theirs[b], repeat, row);
    }
    rows.push_back(row);
  }
  return rows;
}

std::string short_number(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", x);
  return b;
}

std::string format_row(const Row& r, bool scene) {
  char line[1024];
  const std::string sizes = scene ? std::to_string(r.tris_a) + " (" + std::to_string(r.tris_b) + " pairs)"
                                  : std::to_string(r.tris_a) + " / " + std::to_string(r.tris_b);
  std::snprintf(
      line, sizeof line,
      "| %s | %s | %.2f | %.2f | %.3f | %.3f | %.3f | %.3f | %zu / %zu | %s | %llu / %ld | %llu / %ld | %.4f | %.4f | "
      "%.4f | %s |\n",
      r.name.c_str(), sizes.c_str(), r.build_ours, r.build_fcl, r.build_ours / r.build_fcl, r.query_ours, r.query_fcl,
      r.query_fcl > 0 ? r.query_ours / r.query_fcl : 0.0, r.pairs_ours, r.pairs_fcl,
      (r.only_ours == 0 && r.only_fcl == 0)
          ? "yes"
          : ("no: " + std::to_string(r.only_ours) + " only ours, " + std::to_string(r.only_fcl) + " only FCL" +
             (r.only_fcl > 0 ? " (" + std::to_string(r.only_fcl_exact_hits) + " of them intersect in world coordinates; " +
                                   "largest gap " + short_number(r.only_fcl_max_distance) + ")"
                             : std::string()))
                .c_str(),
      static_cast<unsigned long long>(r.node_tests), r.fcl_bv_tests, static_cast<unsigned long long>(r.leaf_tests),
      r.fcl_leaf_tests, r.first_ours, r.first_fcl, r.query_ours > 0 ? r.first_ours / r.query_ours : 0.0,
      r.first_agrees ? "yes" : "NO");
  return line;
}

}  // namespace

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    if (comma > pos) out.push_back(text.substr(pos, comma - pos));
    pos = comma + 1;
  }
  return out;
}

namespace {

/// The options: the meshes' folder, the report's file, the rounds, the scenes and their steps, and --no-mesh-pairs.
struct Options {
  std::filesystem::path dir = caliber::bench::default_meshes_dir();
  std::string out;
  int repeat = 5;
  std::vector<std::string> scenes;
  std::vector<int> steps = {0, 50, 100};
  bool meshes = true;
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
    else if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc)
      o.scenes = split_list(argv[++i]);
    else if (!std::strcmp(argv[i], "--steps") && i + 1 < argc) {
      o.steps.clear();
      for (const std::string& k : split_list(argv[++i])) o.steps.push_back(std::atoi(k.c_str()));
    } else if (!std::strcmp(argv[i], "--no-mesh-pairs"))
      o.meshes = false;
    else {
      std::fprintf(stderr,
                   "usage: bench_fcl_compare [--meshes DIR] [--repeat R] [--out FILE.md] [--scenes A.json,B.json] "
                   "[--steps 0,50,100] [--no-mesh-pairs]\n");
      return std::nullopt;
    }
  }
  return o;
}

/// Writes the report to `o.out`: the machine, the method, then the table.
void write_report(const Options& o, const std::string& table) {
  std::ofstream file(o.out);
  file << "# caliber vs FCL 0.7 (BVHModel<OBBRSS>), sequential interference, all contacts\n\n"
       << "Machine: " << caliber::bench::machine_description() << "\n\n"
       << "Medians of " << o.repeat << " runs. Ratios are ours / FCL (lower is better for us). "
       << "Build: caliber's sphere tree without adjacency vs FCL's OBBRSS build (scenes: every distinct model, "
       << "summed). Scene rows: every pair of the broad phase at that step, times summed; "
       << "triangles = the scene's distinct models.\n\n"
       << table;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> o = parse(argc, argv);
  if (!o) return 2;
  const std::filesystem::path& dir = o->dir;
  // Rotated, overlapping copies: the meshes' sizes differ, so offsets are in each mesh's units.
  const std::vector<Case> cases = {
      {"armadillo x armadillo", "armadillo.off", "armadillo.off", 30, {1, 2, 0.5}, {0.05, 0.03, -0.02}},
      {"bunny x bunny", "bunny00.off", "bunny00.off", 25, {0, 1, 1}, {0.06, 0.02, 0.0}},
      {"dragon x dragon", "ChineseDragon-10kv.off", "ChineseDragon-10kv.off", 20, {1, 0, 1}, {0.04, 0.03, 0.0}},
      {"elephant x elephant (refined)", "refined_elephant.off", "refined_elephant.off", 35, {1, 1, 0}, {0.05, 0.02, 0.01}},
      {"turbine x blade", "turbine.off", "blade.off", 10, {0, 0, 1}, {0.0, 0.05, 0.0}},
      {"fandisk x rotor", "fandisk_large.off", "rotor_small.off", 15, {1, 0, 0}, {0.02, 0.02, 0.0}},
  };
  std::string table;
  table +=
      "| case | triangles A / B | build ours (ms) | build FCL (ms) | build ratio | query ours (ms) | query FCL (ms) | "
      "query ratio | pairs ours / FCL | identical | node tests ours / FCL | leaf tests ours / FCL | "
      "first pair ours (ms) | first pair FCL (ms) | first / full query, ours | first agrees |\n";
  table += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::printf("machine: %s\n", caliber::bench::machine_description().c_str());
  int skipped = 0;
  for (const Case& c : o->meshes ? cases : std::vector<Case>{}) {
    if (!std::filesystem::exists(dir / c.mesh_a) || !std::filesystem::exists(dir / c.mesh_b)) {
      std::fprintf(stderr, "skipping %s: meshes missing in %s (run scripts/fetch_meshes.sh)\n", c.name.c_str(), dir.c_str());
      ++skipped;
      continue;
    }
    const std::string line = format_row(run_case(c, dir, o->repeat), false);
    std::fputs(line.c_str(), stdout);
    std::fflush(stdout);
    table += line;
  }
  for (const std::string& scene : o->scenes) {
    for (const Row& r : run_scene(scene, o->steps, o->repeat)) {
      const std::string line = format_row(r, true);
      std::fputs(line.c_str(), stdout);
      std::fflush(stdout);
      table += line;
    }
  }
  if (o->meshes && skipped == static_cast<int>(cases.size()) && o->scenes.empty()) {
    std::fprintf(stderr,
                 "bench_fcl_compare: none of the meshes is in %s and no --scenes were given: nothing to compare "
                 "(run scripts/fetch_meshes.sh, or pass --meshes DIR)\n",
                 dir.c_str());
    return 2;
  }
  if (!o->out.empty()) write_report(*o, table);
  return 0;
}
