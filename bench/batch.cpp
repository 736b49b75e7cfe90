// Batch queries against FCL 0.7's loop: a link (CGAL's turbine, scaled) swept along a path through
// the bunny, N poses, about half of them colliding. Per query kind (first hit, every intersecting
// pair, minimum distance) and per subset (free poses, colliding poses, and the whole batch in the
// path's order): microseconds per pose of
// FCL's loop (fcl::collide / fcl::distance, OBBRSS), a loop of caliber::query, and
// Engine::query_many on 1 and 2 threads (or those --threads names). Interleaved rounds, medians; the entries of every batch
// are checked against the single queries (same pairs and distances, bit for bit).
//
//   bench_batch [--meshes DIR] [--poses N] [--threads T ...] [--repeat R] [--out FILE.md]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include "caliber/batch.h"
#include "caliber/engine.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/query.h"
#include "fcl_support.h"
#include "machine.h"

namespace {

using namespace caliber;

/// The link's poses: its box center along a line through the bunny's box (from 0.9 of its
/// diagonal on one side to 0.9 on the other), turning about a tilted axis one and a half times.
std::vector<Pose> path(const Mesh& a, const Mesh& b, std::size_t n) {
  Eigen::Vector3d ca, cb;
  double da, db;
  bench::box_center(a, ca, da);
  bench::box_center(b, cb, db);
  const Eigen::Vector3d from = ca + Eigen::Vector3d(-0.45, -0.1, 0.05) * da, to = ca + Eigen::Vector3d(0.45, 0.1, -0.05) * da;
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  std::vector<Pose> out;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = n > 1 ? static_cast<double>(i) / static_cast<double>(n - 1) : 0.0;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(3.0 * std::numbers::pi * s, axis));
    const Eigen::Vector3d t = from + s * (to - from) - q * cb;
    out.push_back(Pose::from_values(t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z()));
  }
  return out;
}

struct Config {
  std::string name;
  std::function<void(const std::vector<Pose>&)> run;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The fixed cost of a call: two tetrahedra, 1e5 calls each, ours (interference apart, distance)
/// against FCL's distance, interleaved rounds; the lines printed, returned.
std::string tiny_calls(int repeat, const BuildOptions& build) {
  const Mesh tetra = mesh_from_buffers(std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1},
                                       std::vector<std::int64_t>{0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3}, "tetrahedron");
  const auto ta = build_model(tetra, build);
  const auto tfa = bench::build_fcl(tetra);
  const Pose apart = Pose::from_values(1.5, 0.2, 0.1, 1, 0.1, 0.2, 0.3);
  fcl::CollisionObjectd ta_obj(tfa, bench::to_fcl(Pose{})), tb_obj(tfa, bench::to_fcl(apart));
  std::vector<double> tiny_ours, tiny_fcl, tiny_interference;
  QueryRequest dist, interference;
  dist.kind = QueryKind::distance;
  dist.tolerance = kUnbounded;
  double sink = 0.0;
  constexpr int calls = 100000;
  const auto per_call = [](auto start) {
    return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() / calls;
  };
  for (int r = 0; r < repeat; ++r) {
    auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) sink += query(*ta, Pose{}, *ta, apart, dist).contacts.front().distance;
    tiny_ours.push_back(per_call(start));
    start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) {
      fcl::DistanceRequestd dreq(true, true, 0.0, 0.0);
      fcl::DistanceResultd dres;
      fcl::distance(&ta_obj, &tb_obj, dreq, dres);
      sink += dres.min_distance;
    }
    tiny_fcl.push_back(per_call(start));
    start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) sink += static_cast<double>(query(*ta, Pose{}, *ta, apart, interference).contacts.size());
    tiny_interference.push_back(per_call(start));
  }
  char line[512];
  std::snprintf(line, sizeof line,
                "\nOne distance call on two tetrahedra: caliber::query %.3f us, fcl::distance %.3f us (%.2f)\n"
                "One interference call on the same (apart): caliber::query %.3f us\n",
                median(tiny_ours), median(tiny_fcl), median(tiny_ours) / median(tiny_fcl), median(tiny_interference));
  std::fputs(line, stdout);
  if (sink < 0.0) std::puts("");
  return line;
}

/// The options: the meshes' folder, the poses, the engines' thread counts (at least one), the rounds,
/// the report's file, and whether to time the tiny calls alone.
struct Options {
  std::filesystem::path meshes = bench::default_meshes_dir();
  std::size_t poses_n = 10000;
  int repeat = 5;
  std::string out_path;
  bool tiny_only = false;
  std::vector<int> thread_counts = {1, 2};
};

/// The options of the command line, or none (the usage said on stderr) for one it does not know.
std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--meshes" && has_value) {
      o.meshes = argv[++i];
    } else if (arg == "--poses" && has_value) {
      o.poses_n = std::stoul(argv[++i]);
    } else if (arg == "--threads" && has_value) {
      o.thread_counts.clear();
      while (i + 1 < argc && argv[i + 1][0] != '-') o.thread_counts.push_back(std::max(1, std::stoi(argv[++i])));
    } else if (arg == "--repeat" && has_value) {
      o.repeat = std::max(1, std::stoi(argv[++i]));
    } else if (arg == "--out" && has_value) {
      o.out_path = argv[++i];
    } else if (arg == "--tiny-only") {
      o.tiny_only = true;
    } else {
      std::fprintf(
          stderr, "usage: bench_batch [--meshes DIR] [--poses N] [--threads T ...] [--repeat R] [--out FILE.md] [--tiny-only]\n");
      return std::nullopt;
    }
  }
  if (o.thread_counts.empty()) o.thread_counts = {1};
  return o;
}

/// The bunny (A) and the scaled turbine (the link, B), their models (ours and FCL's), the link's
/// poses (all, and grouped by whether they collide), and an engine per thread count with its column's name.
struct Setup {
  Mesh bunny, link;
  std::shared_ptr<const Model> a, b;
  std::shared_ptr<bench::FclModel> fa, fb;
  std::vector<Pose> all, colliding, free;
  std::vector<std::unique_ptr<Engine>> engines;
  std::vector<std::string> batch_names;
  std::vector<Pose> identity{Pose{}};  ///< A's poses in a batch: the identity alone
};

/// Loads the meshes, builds the models, walks the path and starts the engines.
Setup set_up(const Options& o, const BuildOptions& build) {
  Setup s;
  s.bunny = load_mesh((o.meshes / "bunny00.off").string());
  s.link = load_mesh((o.meshes / "turbine.off").string());
  scale_mesh(s.link, 0.3);
  s.a = build_model(s.bunny, build), s.b = build_model(s.link, build);
  s.fa = bench::build_fcl(s.bunny), s.fb = bench::build_fcl(s.link);
  s.all = path(s.bunny, s.link, o.poses_n);

  // Which poses collide, by the first hit.
  QueryRequest first;
  first.max_pairs = 1;
  for (const Pose& p : s.all) (query(*s.a, Pose{}, *s.b, p, first).contacts.empty() ? s.free : s.colliding).push_back(p);

  for (const int threads : o.thread_counts) {
    EngineOptions options;
    options.threads = threads;
    s.engines.push_back(std::make_unique<Engine>(options));
    s.batch_names.push_back("batch, " + std::to_string(threads) + (threads == 1 ? " thread" : " threads"));
  }
  return s;
}

/// A query kind of the table: its name and its request.
struct Kind {
  std::string name;
  QueryRequest request;
};

/// The query kinds, in the table's order: the first hit, every intersecting pair, the distance.
std::vector<Kind> query_kinds() {
  std::vector<Kind> kinds(3);
  kinds[0].name = "first hit";
  kinds[0].request.max_pairs = 1;
  kinds[1].name = "interference (every pair)";
  kinds[2].name = "distance";
  kinds[2].request.kind = QueryKind::distance;
  kinds[2].request.tolerance = kUnbounded;
  return kinds;
}

/// The contenders on one query, in timing order: FCL's loop (B moved in `ob`), caliber::query's, a batch per engine.
std::vector<Config> contenders(const Setup& s, const QueryRequest& request, const fcl::CollisionObjectd& oa,
                               fcl::CollisionObjectd& ob, std::size_t& checksum) {
  const bool distance = request.kind == QueryKind::distance;
  std::vector<Config> configs;
  configs.push_back({"FCL loop", [&, distance](const std::vector<Pose>& poses) {
                       for (const Pose& p : poses) {
                         ob.setTransform(bench::to_fcl(p));
                         ob.computeAABB();
                         if (distance) {
                           fcl::DistanceRequestd dreq(true, true, 0.0, 0.0);
                           fcl::DistanceResultd dres;
                           fcl::distance(&oa, &ob, dreq, dres);
                           checksum += dres.min_distance > 0.0;
                         } else {
                           fcl::CollisionRequestd creq(request.max_pairs == 1 ? 1 : 100000000, false);
                           fcl::CollisionResultd cres;
                           fcl::collide(&oa, &ob, creq, cres);
                           checksum += cres.numContacts();
                         }
                       }
                     }});
  configs.push_back({"query loop", [&](const std::vector<Pose>& poses) {
                       for (const Pose& p : poses) checksum += query(*s.a, Pose{}, *s.b, p, request).contacts.size();
                     }});
  for (std::size_t e = 0; e < s.engines.size(); ++e) {
    configs.push_back({s.batch_names[e], [&, e](const std::vector<Pose>& poses) {
                         checksum += s.engines[e]->query_many(*s.a, s.identity, *s.b, poses, request).contacts.size();
                       }});
  }
  return configs;
}

/// Whether the last engine's batch holds the single queries' entries, bit for bit, at about 50 poses (if not, said on stderr).
bool batch_matches(const Setup& s, const Kind& k, const std::string& subset, const std::vector<Pose>& poses) {
  const QueryRequest& request = k.request;
  const BatchResult check = s.engines.back()->query_many(*s.a, s.identity, *s.b, poses, request);
  for (std::size_t i = 0; i < poses.size(); i += std::max<std::size_t>(1, poses.size() / 50)) {
    const QueryResult q = query(*s.a, Pose{}, *s.b, poses[i], request);
    const auto got = check.contacts_of(i);
    bool same = got.size() == q.contacts.size();
    for (std::size_t c = 0; same && c < got.size(); ++c) {
      same = got[c].tri_a == q.contacts[c].tri_a && got[c].tri_b == q.contacts[c].tri_b &&
             got[c].distance == q.contacts[c].distance && got[c].point_a == q.contacts[c].point_a;
    }
    if (!same) {
      std::fprintf(stderr, "bench_batch: %s, %s pose %zu: the batch differs from the query\n", k.name.c_str(), subset.c_str(), i);
      return false;
    }
  }
  return true;
}

/// The contenders on `poses`, `repeat` interleaved rounds: each one's microseconds per pose, by name.
std::map<std::string, std::vector<double>> time_rounds(const std::vector<Config>& configs, const std::vector<Pose>& poses,
                                                       int repeat) {
  std::map<std::string, std::vector<double>> times;
  for (int r = 0; r < repeat; ++r) {
    for (const Config& c : configs) {
      const auto start = std::chrono::steady_clock::now();
      c.run(poses);
      times[c.name].push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() /
                              static_cast<double>(poses.size()));
    }
  }
  return times;
}

/// A row of the table: the medians of FCL's loop, caliber's loop and each batch, then the ratios.
std::string table_row(const Kind& k, const std::string& subset, std::size_t count,
                      const std::map<std::string, std::vector<double>>& times, const std::vector<std::string>& batch_names) {
  char line[512];
  const double fcl_us = median(times.at("FCL loop")), loop_us = median(times.at("query loop"));
  std::snprintf(line, sizeof line, "| %s | %s | %zu | %.2f | %.2f |", k.name.c_str(), subset.c_str(), count, fcl_us, loop_us);
  std::string row = line;
  for (const std::string& name : batch_names) {
    std::snprintf(line, sizeof line, " %.2f |", median(times.at(name)));
    row += line;
  }
  const double b1 = median(times.at(batch_names.front())), bn = median(times.at(batch_names.back()));
  std::snprintf(line, sizeof line, " %.3f | %.3f | %.2f |\n", loop_us / fcl_us, b1 / fcl_us, b1 / bn);
  row += line;
  return row;
}

/// One query kind on each subset of poses: checked, then timed; its rows printed and added to `table`. False if a batch differs.
bool measure_kind(const Setup& s, const Kind& k, int repeat, const fcl::CollisionObjectd& oa, fcl::CollisionObjectd& ob,
                  std::size_t& checksum, std::string& table) {
  const std::vector<Config> configs = contenders(s, k.request, oa, ob, checksum);
  for (const auto& [subset, poses] :
       {std::pair<std::string, const std::vector<Pose>*>{"free", &s.free}, {"colliding", &s.colliding}, {"all", &s.all}}) {
    if (poses->empty()) continue;
    // Every batch's entries are the single queries', bit for bit.
    if (!batch_matches(s, k, subset, *poses)) return false;
    const std::string row = table_row(k, subset, poses->size(), time_rounds(configs, *poses, repeat), s.batch_names);
    std::fputs(row.c_str(), stdout);
    std::fflush(stdout);
    table += row;
  }
  return true;
}

/// Writes the report to `path`: the setup, the table, then the tiny calls' lines.
void write_report(const std::string& path, const Options& o, const Setup& s, const std::string& table, const std::string& tiny) {
  std::ofstream out(path);
  out << "# Batch queries against FCL 0.7's loop\n\n"
      << "Machine: " << bench::machine_description() << "\n\n"
      << "CGAL's turbine (" << s.link.triangles.size() << " triangles, scaled 0.3) swept along a path through the bunny ("
      << s.bunny.triangles.size() << " triangles): " << s.all.size() << " poses, " << s.colliding.size()
      << " colliding. Microseconds per pose, medians of " << o.repeat
      << " interleaved rounds; each batch's entries checked against the single queries.\n\n"
      << "| query | poses | count | FCL loop | query loop |";
  for (const std::string& name : s.batch_names) out << " " << name << " |";
  out << " loop / FCL | batch " << o.thread_counts.front() << "t / FCL | " << o.thread_counts.back() << "t / "
      << o.thread_counts.front() << "t |\n|---|---|---|---|---|";
  for (std::size_t e = 0; e < s.batch_names.size(); ++e) out << "---|";
  out << "---|---|---|\n" << table << tiny;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> o = parse(argc, argv);
  if (!o) return 2;
  // Oriented boxes kept: the distance query reads them instead of computing them (what the CLI and
  // scenes do for distance queries; the other kinds do not read them).
  BuildOptions build;
  build.oriented_boxes = true;
  if (o->tiny_only) {
    (void)tiny_calls(o->repeat, build);
    return 0;
  }
  const Setup s = set_up(*o, build);
  fcl::CollisionObjectd oa(s.fa, bench::to_fcl(Pose{}));
  fcl::CollisionObjectd ob(s.fb, bench::to_fcl(Pose{}));

  std::string table;
  std::size_t checksum = 0;  // what every timed run found, kept so that no run is optimized away
  for (const Kind& k : query_kinds()) {
    if (!measure_kind(s, k, o->repeat, oa, ob, checksum, table)) return 1;
  }

  const std::string tiny = tiny_calls(o->repeat, build);

  if (!o->out_path.empty()) write_report(o->out_path, *o, s, table, tiny);
  return checksum == SIZE_MAX ? 1 : 0;  // (kept, so that no timed run is optimized away)
}
