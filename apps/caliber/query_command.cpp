// caliber query: two meshes, one query.

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>
#include <cstdio>
#include <memory>
#include <new>
#include <iostream>
#include <string>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"
#include "commands.h"
#include "json_output.h"
#include "output_file.h"
#include "timing.h"

namespace caliber::cli {
namespace {

struct QueryOptions {
  std::string mesh_a, mesh_b;
  std::string pose_a = "0 0 0 1 0 0 0", pose_b = "0 0 0 1 0 0 0";
  std::string kind = "interference";
  double tolerance = 0.0;
  bool tolerance_given = false;  ///< distance: without --tolerance, any distance will do
  double angle = 30.0;
  bool json = false;
  int show = 10;
  std::string method = "sequential";
  int threads = 0;
  int repeat = 1;
  std::size_t max_pairs = 0;
  bool max_pairs_given = false;  ///< --max-pairs on the command line (refused with --first)
  bool first = false;
  bool lowest_ids = false;
};

bool same_result(const caliber::QueryResult& x, const caliber::QueryResult& y) {
  if (x.contacts.size() != y.contacts.size()) return false;
  for (std::size_t i = 0; i < x.contacts.size(); ++i) {
    const auto& a = x.contacts[i];
    const auto& b = y.contacts[i];
    if (a.tri_a != b.tri_a || a.tri_b != b.tri_b || a.distance != b.distance || a.point_a != b.point_a ||
        a.point_b != b.point_b || a.normal != b.normal || a.depth != b.depth) {
      return false;
    }
  }
  return true;
}

/// The pair's result from a step of the parallel engine on a two-object frame (the same contacts as
/// caliber::query, whatever the method).
caliber::QueryResult query_with_engine(caliber::Engine& engine, const caliber::Frame& frame) {
  const caliber::StepResult step = engine.step(frame);
  caliber::QueryResult result;
  result.kind = frame.request.kind;
  result.stats = step.stats;
  result.limit_reached = step.limit_reached;
  result.contacts = step.contacts;  // one shape: the frame's objects are 0 and 1, as caliber::query's
  return result;
}

/// The request the options ask for, checked.
caliber::QueryRequest request_of(const QueryOptions& opt) {
  caliber::QueryRequest request;
  request.kind = caliber::parse_query_kind(opt.kind);
  request.tolerance = opt.tolerance;
  if (request.kind == caliber::QueryKind::distance && !opt.tolerance_given) request.tolerance = caliber::kUnbounded;
  request.angle_deg = opt.angle;
  if (opt.first && opt.max_pairs_given) {
    throw caliber::Error(caliber::ErrorCode::bad_argument, "--first", "is --max-pairs 1: give --first or --max-pairs, not both");
  }
  request.max_pairs = opt.first ? 1 : opt.max_pairs;
  request.lowest_ids = opt.lowest_ids;
  caliber::validate_request(request);
  return request;
}

/// The two models, built with what the query kind reads (B is A when both name the same file).
std::pair<std::shared_ptr<const caliber::Model>, std::shared_ptr<const caliber::Model>> models_of(const QueryOptions& opt,
                                                                                                  caliber::QueryKind kind) {
  caliber::BuildOptions build;
  build.adjacency = kind == caliber::QueryKind::contact;        // only the contact reduction reads it
  build.oriented_boxes = kind == caliber::QueryKind::distance;  // only the distance bound reads them
  const auto model_of = [&](const std::string& path) {
    try {
      return caliber::build_model(caliber::load_mesh(path), build);
    } catch (const std::bad_alloc&) {
      throw caliber::Error(caliber::ErrorCode::out_of_memory, path, "out of memory while loading and building its model");
    }
  };
  auto model_a = model_of(opt.mesh_a);
  auto model_b = opt.mesh_b == opt.mesh_a ? model_a : model_of(opt.mesh_b);
  return {std::move(model_a), std::move(model_b)};
}

/// The query's result and its time per repetition (the first one cold), every repetition checked
/// to give the same result. A method other than sequential runs as a one-pair frame of an engine.
std::pair<caliber::QueryResult, std::vector<double>> timed_query(const QueryOptions& opt, const caliber::QueryRequest& request,
                                                                 const caliber::Pose& pose_a, const caliber::Pose& pose_b,
                                                                 const std::shared_ptr<const caliber::Model>& model_a,
                                                                 const std::shared_ptr<const caliber::Model>& model_b) {
  const caliber::Method method = method_option(opt.method);
  std::unique_ptr<caliber::Engine> engine;
  caliber::Frame frame;
  if (method != caliber::Method::sequential) {
    caliber::EngineOptions options;
    options.method = method;
    options.threads = opt.threads;
    engine = engine_from_options([&] { return std::make_unique<caliber::Engine>(options); });
    frame.models = {model_a, model_b};
    frame.poses = {pose_a, pose_b};
    frame.pairs = {caliber::ObjectPair{0, 1}};
    frame.request = request;
  }
  caliber::QueryResult result;
  std::vector<double> query_ms;
  for (int r = 0; r < opt.repeat; ++r) {
    caliber::QueryResult again;
    const auto start = Clock::now();
    try {
      again = engine ? query_with_engine(*engine, frame) : caliber::query(*model_a, pose_a, *model_b, pose_b, request);
    } catch (const std::bad_alloc&) {
      throw caliber::Error(caliber::ErrorCode::out_of_memory, opt.mesh_a + " x " + opt.mesh_b,
                           "out of memory while running the query (a smaller tolerance reports fewer pairs)");
    }
    query_ms.push_back(ms_since(start));
    if (r == 0) {
      result = std::move(again);
    } else if (!same_result(result, again)) {
      throw std::runtime_error("repetition " + std::to_string(r + 1) + " of the query gave a different result");
    }
  }
  return {std::move(result), std::move(query_ms)};
}

/// The summary printed without --json: the closest pair of a distance query, the counts, the
/// models, the times and the first pairs.
void print_result(const QueryOptions& opt, const caliber::QueryRequest& request, const caliber::QueryResult& result,
                  const caliber::Model& shown_a, const caliber::Model& shown_b, double build_ms, double cold_ms, double warm_ms) {
  if (request.kind == caliber::QueryKind::distance) {
    if (result.contacts.empty()) {
      std::printf("distance: none within the tolerance %g\n", request.tolerance);
    } else {
      const caliber::Contact& c = result.contacts.front();
      std::printf("distance: %.17g between triangle %u of A and triangle %u of B\n", c.distance, c.tri_a, c.tri_b);
      std::printf("  nearest points (%.17g %.17g %.17g) on A, (%.17g %.17g %.17g) on B\n", c.point_a.x(), c.point_a.y(),
                  c.point_a.z(), c.point_b.x(), c.point_b.y(), c.point_b.z());
    }
  }
  const char* what = request.kind == caliber::QueryKind::interference ? "intersecting triangle pairs"
                     : request.kind == caliber::QueryKind::proximity  ? "triangle pairs within the tolerance"
                     : request.kind == caliber::QueryKind::distance   ? "closest triangle pair"
                                                                      : "contacts (local minima)";
  std::printf("%s: %zu %s\n", std::string(caliber::to_string(result.kind)).c_str(), result.contacts.size(), what);
  std::printf("  A: %s (%zu triangles, BVH height %d)\n", opt.mesh_a.c_str(), shown_a.mesh().triangles.size(), shown_a.height());
  std::printf("  B: %s (%zu triangles, BVH height %d)\n", opt.mesh_b.c_str(), shown_b.mesh().triangles.size(), shown_b.height());
  std::printf("  node tests %llu, leaf tests %llu; build %.2f ms, query %.3f ms",
              static_cast<unsigned long long>(result.stats.node_tests), static_cast<unsigned long long>(result.stats.leaf_tests),
              build_ms, cold_ms);
  if (opt.repeat > 1) std::printf(" (first; median of the other %d: %.3f ms)", opt.repeat - 1, warm_ms);
  std::printf("\n");
  const std::size_t shown = std::min<std::size_t>(result.contacts.size(), static_cast<std::size_t>(std::max(opt.show, 0)));
  for (std::size_t i = 0; i < shown; ++i) {
    if (result.kind == caliber::QueryKind::interference) {
      std::printf("  pair %u %u\n", result.contacts[i].tri_a, result.contacts[i].tri_b);
    } else {
      const auto& c = result.contacts[i];
      std::printf("  pair %u %u  distance %.6g  normal (%.4f %.4f %.4f)\n", c.tri_a, c.tri_b, c.distance, c.normal.x(),
                  c.normal.y(), c.normal.z());
    }
  }
  if (shown < result.contacts.size()) std::printf("  ... %zu more (use --json for all)\n", result.contacts.size() - shown);
  if (result.limit_reached) {
    std::printf("  limit reached: the query stopped at %zu pairs and reports %zu (there may be more)\n", request.max_pairs,
                result.contacts.size());
  }
}

int run_query(const QueryOptions& opt) {
  const caliber::QueryRequest request = request_of(opt);
  const caliber::Pose pose_a = caliber::parse_pose(opt.pose_a, "--pose-a");
  const caliber::Pose pose_b = caliber::parse_pose(opt.pose_b, "--pose-b");
  (void)method_option(opt.method);  // a bad method is refused before the models are built
  const auto build_start = Clock::now();
  const auto [model_a, model_b] = models_of(opt, request.kind);
  const double build_ms = ms_since(build_start);
  const auto [result, query_ms] = timed_query(opt, request, pose_a, pose_b, model_a, model_b);
  // Warm: the median of the repetitions after the first (the first alone when there is one).
  const double cold_ms = query_ms.front();
  const double warm_ms = query_ms.size() > 1 ? median_of({query_ms.begin() + 1, query_ms.end()}) : cold_ms;
  if (opt.json) {
    nlohmann::json out = caliber::cli::to_json(result);
    out["schema_version"] = caliber::cli::kSchemaVersion;
    out["stats"]["build_ms"] = build_ms;
    out["stats"]["query_ms"] = cold_ms;
    out["stats"]["query_ms_warm"] = warm_ms;
    out["stats"]["repeat"] = opt.repeat;
    std::cout << out.dump() << "\n";
  } else {
    print_result(opt, request, result, *model_a, *model_b, build_ms, cold_ms, warm_ms);
  }
  check_stdout();
  return 0;
}

}  // namespace

Runner add_query_command(CLI::App& app) {
  auto opt = std::make_shared<QueryOptions>();
  CLI::App* cmd = app.add_subcommand("query", "Query two meshes: interference, proximity, contact or distance");
  cmd->add_option("A", opt->mesh_a, "Mesh A (OFF, OBJ, STL or PLY)")->required();
  cmd->add_option("B", opt->mesh_b, "Mesh B (OFF, OBJ, STL or PLY)")->required();
  cmd->add_option("--pose-a", opt->pose_a, "Pose of A: \"tx ty tz qw qx qy qz\"")->capture_default_str();
  cmd->add_option("--pose-b", opt->pose_b, "Pose of B: \"tx ty tz qw qx qy qz\"")->capture_default_str();
  cmd->add_option("--kind", opt->kind, "interference | proximity | contact | distance")->capture_default_str();
  cmd->add_option("--tolerance", opt->tolerance,
                  "Distance d for proximity and contact (>= 0); for distance, the largest distance of interest "
                  "(default: any)")
      ->capture_default_str()
      ->each([opt](const std::string&) { opt->tolerance_given = true; });
  cmd->add_option("--angle", opt->angle, "Contact angle theta in degrees, [0, 180]")->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON object with every pair and contact");
  cmd->add_option("--show", opt->show, "How many pairs the summary lists")->capture_default_str()->check(at_least(0));
  cmd->add_option("--method", opt->method,
                  "sequential (default: caliber::query) or an engine method: exploitation, stealing, aposteriori, "
                  "apriori, hybrid (same pairs; query_ms times the engine's step)")
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads,
                  "Engine threads (0: every hardware thread the process may use; 1: this thread alone)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--max-pairs", opt->max_pairs,
                  "Report at most N triangle pairs: at N the query stops and says so (0: no limit)")
      ->check(at_least(0))
      ->capture_default_str()
      ->each([opt](const std::string&) { opt->max_pairs_given = true; });
  cmd->add_flag("--first", opt->first, "Stop at the first pair found (any pair, or none): --max-pairs 1; not with --max-pairs");
  cmd->add_flag("--lowest-ids", opt->lowest_ids,
                "Distance on intersecting meshes: report the intersecting pair with the lowest triangle ids (every "
                "pair at distance 0 examined) instead of the first hit's (the same on models with at most 16 "
                "triangle pairs, all of which are tested)");
  cmd->add_option("--repeat", opt->repeat,
                  "Run the query R times: stats.query_ms is the first (cold) run, stats.query_ms_warm the median of "
                  "the others (every run must give the same result)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  return [cmd, opt]() { return cmd->parsed() ? run_query(*opt) : -1; };
}

}  // namespace caliber::cli
