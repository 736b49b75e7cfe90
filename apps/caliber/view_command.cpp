// caliber view: runs a scene and writes one self-contained HTML page (three.js bundled in) that
// draws each step: the posed meshes, the contacts and their normals, the pairs coloured by their
// share of the work, and the run-time tasks coloured by the thread that ran them (docs/viewer.md).

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "caliber/engine.h"
#include "caliber/profile.h"
#include "caliber/error.h"
#include "caliber/scene.h"
#include "caliber/world.h"
#include "commands.h"
#include "interrupt.h"
#include "json_output.h"
#include "output_file.h"
#include "progress.h"
#include "step_geometry.h"
#include "view_page.h"

namespace caliber::cli {
namespace {

struct ViewOptions {
  std::string scene;
  std::string out;
  std::string method{caliber::to_string(caliber::kDefaultMethod)};
  int threads = 0;
  int steps = -1;
  int max_boxes = 5000;
};

std::string base64(const void* data, std::size_t size) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const unsigned v = p[i] << 16 | (i + 1 < size ? p[i + 1] << 8 : 0) | (i + 2 < size ? p[i + 2] : 0);
    out += kDigits[v >> 18 & 63];
    out += kDigits[v >> 12 & 63];
    out += i + 1 < size ? kDigits[v >> 6 & 63] : '=';
    out += i + 2 < size ? kDigits[v & 63] : '=';
  }
  return out;
}

/// Vertices as float32 and triangles as uint32, little-endian (every machine caliber builds on).
nlohmann::json mesh_record(const Mesh& mesh) {
  std::vector<float> v;
  v.reserve(mesh.vertices.size() * 3);
  for (const Eigen::Vector3d& p : mesh.vertices) v.insert(v.end(), {float(p.x()), float(p.y()), float(p.z())});
  std::vector<std::uint32_t> t;
  t.reserve(mesh.triangles.size() * 3);
  for (const auto& tri : mesh.triangles) t.insert(t.end(), tri.begin(), tri.end());
  return {{"vertices", base64(v.data(), v.size() * sizeof(float))}, {"triangles", base64(t.data(), t.size() * 4)}};
}

/// Row-major rotation, then translation.
nlohmann::json pose_record(const Pose& pose) {
  const Eigen::Matrix3d r = pose.rotation_matrix();
  return {r(0, 0),
          r(0, 1),
          r(0, 2),
          r(1, 0),
          r(1, 1),
          r(1, 2),
          r(2, 0),
          r(2, 1),
          r(2, 2),
          pose.translation.x(),
          pose.translation.y(),
          pose.translation.z()};
}

/// The run-time tasks with the thread that ran each, their node tests and their roots' boxes (A's
/// node, object frame); at most `budget` boxes over the step, the heaviest tasks first in the list.
nlohmann::json task_records(const World& world, const StepResult& s, int& budget) {
  const ScheduleRecord& r = *s.schedule;
  std::vector<int> thread(r.task_roots.size(), 0);
  for (const TaskSpan& span : r.timeline) {
    if (span.phase == TaskSpan::Phase::traverse && span.unit < thread.size()) thread[span.unit] = span.thread;
  }
  nlohmann::json tasks = nlohmann::json::array();
  for (std::size_t t = 0; t < r.task_roots.size(); ++t) {
    nlohmann::json roots = nlohmann::json::array();
    for (const TaskRoot& root : r.task_roots[t]) {
      if (budget <= 0) break;
      --budget;
      const std::uint32_t object = s.pair_records[root.pair].pair.a;
      const NodeBox box = caliber::node_box(world.model(object), root.node_a);
      roots.push_back({object, box.center[0], box.center[1], box.center[2], box.half[0], box.half[1], box.half[2]});
    }
    tasks.push_back({{"thread", thread[t]}, {"node_tests", r.task_node_tests[t]}, {"roots", roots}});
  }
  return tasks;
}

nlohmann::json step_view(const World& world, const StepResult& s, const std::vector<Pose>& poses, int max_boxes) {
  nlohmann::json pose_list = nlohmann::json::array();
  for (const Pose& p : poses) pose_list.push_back(pose_record(p));
  std::vector<double> points, normals;
  std::vector<std::uint32_t> pairs;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> per_pair;
  for (const ShownContact& c : shown_contacts(world, s, poses)) {
    points.insert(points.end(), {c.point.x(), c.point.y(), c.point.z()});
    normals.insert(normals.end(), {c.normal.x(), c.normal.y(), c.normal.z()});
    pairs.insert(pairs.end(), {c.object_a, c.object_b});
    ++per_pair[{c.object_a, c.object_b}];
  }
  nlohmann::json pair_list = nlohmann::json::array();
  for (const PairRecord& t : s.pair_records) {
    const auto it = per_pair.find({t.pair.a, t.pair.b});
    pair_list.push_back({{"a", t.pair.a},
                         {"b", t.pair.b},
                         {"node_tests", t.stats.node_tests},
                         {"contacts", it == per_pair.end() ? 0 : it->second}});
  }
  nlohmann::json timeline = nlohmann::json::array();
  for (const TaskSpan& span : s.schedule->timeline) {
    timeline.push_back({span.thread, span.start_ms, span.end_ms, static_cast<int>(span.phase), span.unit});
  }
  int budget = max_boxes;
  return {{"step", s.step},      {"step_ms", s.broad_ms + s.narrow_ms + s.reduce_ms},
          {"poses", pose_list},  {"contacts", {{"points", points}, {"normals", normals}, {"pairs", pairs}}},
          {"pairs", pair_list},  {"tasks", task_records(world, s, budget)},
          {"timeline", timeline}};
}

/// JSON placed inside <script>: every '<' written "\\u003c" (the same string to JSON; in JSON text a
/// '<' can only be inside a string) so that no text in it (an object's name, say: "</script>",
/// "<!--") can end or change the script element.
std::string script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (const char c : json) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

int view_scene(const ViewOptions& opt) {
  if (!kViewerBuilt) {
    throw Error(ErrorCode::bad_value, "caliber view",
                "this build has no viewer: viewer/node_modules (three.js and esbuild from npm) was missing when it was "
                "configured; run scripts/setup.sh, then rebuild");
  }
  // The options checked (the engine's by its constructor) before the scene is read.
  check_steps_option(opt.steps);
  if (opt.max_boxes < 0) throw Error(ErrorCode::bad_value, "--max-boxes", "must be 0 or more");
  EngineOptions options;
  options.method = method_option(opt.method);
  options.threads = opt.threads;
  options.timeline = true;
  Engine engine = engine_from_options([&] { return Engine(options); });
  Scene scene = load_scene(opt.scene);
  if (opt.steps > 0) scene.steps = opt.steps;
  // SIGINT and SIGTERM handled from before the page is opened until it is in place (or removed).
  const InterruptGuard interrupt;
  check_distinct_files({{"--out", opt.out}}, scene_inputs(opt.scene, scene));
  OutputFile out(opt.out, "--out");

  const World world(std::move(scene));
  const Scene& sc = world.scene();
  // The page is streamed: its head, the data (meshes and objects, then each step as it ends), its
  // tail; so its memory does not grow with the steps.
  out.stream() << kPageHead;
  JsonObjectWriter data(out.stream(), &script_safe);
  data.member("schema_version", kSchemaVersion);
  data.member("scene", json_text(sc.name));
  data.member("query", std::string(to_string(sc.query.kind)));
  data.member("method", std::string(to_string(engine.options().method)));
  data.member("threads", engine.threads());
  nlohmann::json objects = nlohmann::json::array();
  std::map<const Model*, std::size_t> mesh_index;
  data.open_array("meshes");
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    const Model* model = &world.model(i);
    const auto [it, added] = mesh_index.emplace(model, mesh_index.size());
    if (added) data.item(mesh_record(model->mesh()));
    objects.push_back({{"name", json_text(sc.objects[i].name)}, {"mesh", it->second}});
  }
  data.close_array();
  data.member("objects", objects);
  data.open_array("steps");
  const Progress progress(static_cast<std::size_t>(sc.steps));
  int done = 0;
  for (int k = 0; k < sc.steps && !interrupted(); ++k, ++done) {
    const StepResult s = step(world, engine, k);
    data.item(step_view(world, s, world.poses_at(k), opt.max_boxes));
    progress.update(static_cast<std::size_t>(k + 1), "step " + std::to_string(k) + ": " + std::to_string(s.contacts.size()) +
                                                         " contacts, " + std::to_string(s.schedule->task_node_tests.size()) +
                                                         " run-time tasks");
  }
  progress.end();
  const bool stopped = interrupted();  // a signal during the writing below stops nothing: the page is whole
  if (stopped) {
    std::printf("interrupted (%s) after %d of %d steps: %s\n", interrupt_name(), done, sc.steps,
                done > 0 ? "writing the page of the steps done" : "no page written");
    if (done == 0) return interrupted_exit_code();  // the temporary file removed, as after a failure
  }
  data.close_array();
  if (stopped) data.member("interrupted", true);
  data.close();
  out.stream() << kPageMiddle << kViewerScript << kPageTail;
  out.commit();
  std::printf("wrote %s: %s, %d steps, %zu objects, %s on %d thread(s)\n", opt.out.c_str(), sc.name.c_str(), done,
              world.object_count(), std::string(to_string(engine.options().method)).c_str(), engine.threads());
  check_stdout();
  return stopped ? interrupted_exit_code() : 0;
}

}  // namespace

Runner add_view_command(CLI::App& app) {
  auto opt = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand("view", "Run a scene and write an HTML page that shows its steps (three.js, offline)");
  cmd->add_option("SCENE", opt->scene, "Scene file (JSON, see docs/scenes.md)")->required();
  cmd->add_option("--out", opt->out, "The HTML file to write")->required();
  cmd->add_option("--steps", opt->steps, "Run and show this many steps instead of the scene's")
      ->check(at_least(1));  // -1, the default, stands for the scene's steps: not a value to give
  cmd->add_option("--method", opt->method, "sequential | exploitation | stealing | aposteriori | apriori | hybrid")
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Threads (0: every hardware thread the process may use; 1: this thread alone)")
      ->capture_default_str();
  cmd->add_option("--max-boxes", opt->max_boxes, "Most task-root boxes drawn per step")->capture_default_str();
  return [cmd, opt]() { return cmd->parsed() ? view_scene(*opt) : -1; };
}

}  // namespace caliber::cli
