// The JSON-lines log of `caliber-bench` and results.json rebuilt from it (see bench_records.h).

#include "bench_records.h"

#include <algorithm>
#include <map>
#include <string>
#include <utility>

#include <cerrno>
#include <cstring>

#include "caliber/error.h"
#include "timing.h"

namespace caliber::cli {

using Json = nlohmann::json;

BenchLog::BenchLog(std::filesystem::path file) : mFile(std::move(file)), mOut(mFile, std::ios::trunc) {
  if (!mOut) {
    std::error_code ec;
    const bool folder = std::filesystem::is_directory(mFile, ec);
    throw Error(ErrorCode::unreadable, mFile.string(),
                folder ? "is a folder, not a log file" : std::string("cannot be opened for writing: ") + std::strerror(errno));
  }
}

void BenchLog::add(Json record) {
  mOut << record.dump() << '\n';
  mOut.flush();
  if (!mOut) throw Error(ErrorCode::unreadable, mFile.string(), "write failed (disk full?)");
  mRecords.push_back(std::move(record));
}

namespace {

using Field = std::pair<const char*, bool (Json::*)() const>;

/// The fields a record of `kind` must have, with their types; false for a kind no log holds.
bool fields_of(const std::string& kind, std::vector<Field>& fields) {
  if (kind == "header") {
    fields = {{"machine", &Json::is_string},
              {"cpu", &Json::is_string},
              {"hardware_threads", &Json::is_number_integer},
              {"compiler", &Json::is_string},
              {"repeat", &Json::is_number_integer},
              {"threads", &Json::is_array},
              {"simulate", &Json::is_array},
              {"simulate_steps", &Json::is_number_integer},
              {"methods", &Json::is_array},
              {"scenes", &Json::is_array},
              {"runs_planned", &Json::is_number_integer}};
  } else if (kind == "run") {
    fields = {{"scene", &Json::is_string},         {"method", &Json::is_string},   {"threads", &Json::is_number_integer},
              {"round", &Json::is_number_integer}, {"total_ms", &Json::is_number}, {"phases", &Json::is_object}};
  } else if (kind == "table1") {
    fields = {{"scene", &Json::is_string},
              {"objects", &Json::is_number},
              {"triangles", &Json::is_number},
              {"node_tests_per_step", &Json::is_number},
              {"contacts_per_step", &Json::is_number},
              {"pairs_per_step", &Json::is_number},
              {"distinct_pairs", &Json::is_number},
              {"heaviest_pair_share", &Json::is_number},
              {"second_pair_share", &Json::is_number},
              {"exploitation_bound", &Json::is_number}};
  } else if (kind == "ceiling") {
    fields = {{"scene", &Json::is_string}, {"copies", &Json::is_number_integer}, {"copy_step_ms", &Json::is_array}};
  } else if (kind == "simulation") {
    fields = {{"scene", &Json::is_string},
              {"method", &Json::is_string},
              {"cores", &Json::is_number_integer},
              {"speedup", &Json::is_number}};
  } else if (kind == "mismatch") {
    fields = {{"scene", &Json::is_string},
              {"method", &Json::is_string},
              {"threads", &Json::is_number_integer},
              {"step", &Json::is_number_integer}};
  } else if (kind == "gantt") {
    fields = {{"scene", &Json::is_string},
              {"threads", &Json::is_number_integer},
              {"step", &Json::is_number_integer},
              {"methods", &Json::is_object}};
  } else if (kind == "fcl") {
    fields = {{"report", &Json::is_string}};
  } else if (kind == "stopped") {
    fields = {{"reason", &Json::is_string}, {"after_s", &Json::is_number}};
  } else {
    return false;
  }
  return true;
}

/// Why a header's lists cannot be read (empty when they can).
std::string header_problem(const Json& r) {
  for (const Json& list : {r["threads"], r["simulate"]}) {
    for (const Json& x : list) {
      if (!x.is_number_integer()) return "a thread or core count is not a whole number";
    }
  }
  for (const Json& m : r["methods"]) {
    if (!m.is_string()) return "a method is not a name";
  }
  for (const Json& sc : r["scenes"]) {
    if (!sc.is_object() || !sc.contains("name") || !sc["name"].is_string() || !sc.contains("file") || !sc["file"].is_string() ||
        !sc.contains("steps") || !sc["steps"].is_number_integer() || sc["steps"].get<long long>() < 1) {
      return "a scene needs a name, a file and steps >= 1";
    }
  }
  return {};
}

/// Why a record's scene, method, phases or copies do not agree with the header (empty when they do).
std::string reference_problem(const Json& r, const Json& header, const std::string& kind) {
  if (r.contains("scene")) {
    const auto& scenes = header["scenes"];
    if (std::none_of(scenes.begin(), scenes.end(), [&](const Json& sc) { return sc["name"] == r["scene"]; })) {
      return "names a scene the header does not list";
    }
  }
  if (r.contains("method") && kind != "gantt") {
    const auto& methods = header["methods"];
    if (std::none_of(methods.begin(), methods.end(), [&](const Json& m) { return m == r["method"]; })) {
      return "names a method the header does not list";
    }
  }
  if (kind == "run") {
    for (const auto& [key, value] : r["phases"].items()) {
      if (!value.is_number()) return "phase \"" + key + "\" is not a number";
    }
  }
  if (kind == "ceiling") {
    for (const Json& x : r["copy_step_ms"]) {
      if (!x.is_number()) return "a copy's time is not a number";
    }
  }
  return {};
}

/// Why a record cannot be read (empty when it can): its kind's fields, with their types, and the
/// scenes and methods it names against the header's.
std::string record_problem(const Json& r, const Json* header) {
  const auto need = [&](const char* key, bool (Json::*is)() const) -> std::string {
    if (!r.contains(key)) return std::string("no \"") + key + "\"";
    if (!(r[key].*is)()) return std::string("\"") + key + "\" has the wrong type";
    return {};
  };
  const std::string kind = r["kind"].get<std::string>();
  std::vector<Field> fields;
  if (!fields_of(kind, fields)) return "unknown record kind \"" + kind + "\"";
  for (const auto& [key, is] : fields) {
    if (std::string p = need(key, is); !p.empty()) return p;
  }
  if (kind == "header") return header_problem(r);
  if (header == nullptr) return "comes before the header";
  return reference_problem(r, *header, kind);
}

}  // namespace

std::vector<Json> read_bench_log(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw Error(ErrorCode::file_not_found, file.string(), "no such bench log");
  // Read whole: a FIFO or a device (/dev/zero) would block or never end.
  if (!std::filesystem::is_regular_file(file, ec)) throw Error(ErrorCode::unreadable, file.string(), "is not a regular file");
  std::ifstream in(file);
  if (!in) throw Error(ErrorCode::file_not_found, file.string(), "cannot be opened");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  std::vector<Json> records;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    Json r = Json::parse(lines[i], nullptr, /*allow_exceptions=*/false);
    if (r.is_discarded() && i + 1 == lines.size() && i > 0) break;  // the line being written when the run was cut
    if (!r.is_object() || !r.contains("kind") || !r["kind"].is_string()) {
      throw Error(ErrorCode::unreadable, file.string(), "line " + std::to_string(i + 1) + " is not a bench record");
    }
    // Logs written before the object pairs met over a run were called distinct_pairs.
    if (r["kind"] == "table1" && !r.contains("distinct_pairs") && r.contains("candidate_pairs")) {
      r["distinct_pairs"] = r["candidate_pairs"];
      r.erase("candidate_pairs");
    }
    if (records.empty() && r["kind"] != "header") {
      throw Error(ErrorCode::unreadable, file.string(), "no header record on line 1 (not a caliber-bench log)");
    }
    if (i > 0 && r["kind"] == "header") {
      throw Error(ErrorCode::unreadable, file.string(), "line " + std::to_string(i + 1) + ": a second header");
    }
    if (const std::string problem = record_problem(r, records.empty() ? nullptr : &records.front()); !problem.empty()) {
      throw Error(ErrorCode::unreadable, file.string(), "line " + std::to_string(i + 1) + ": " + problem);
    }
    records.push_back(std::move(r));
  }
  if (records.empty()) throw Error(ErrorCode::unreadable, file.string(), "empty (not a caliber-bench log)");
  return records;
}

namespace {

/// What the records say of one scene.
struct SceneRecords {
  Json info;  ///< name, file, steps (from the header)
  Json table1;
  std::map<std::pair<std::string, int>, std::vector<Json>> runs;  ///< (method, threads) -> run records
  std::map<std::string, Json> simulated, predicted,
      correlation;                             ///< method -> {cores: speedup}, {cores: {ms, speedup}}, correlation
  std::map<int, std::vector<double>> ceiling;  ///< copies -> each copy's ms/step
};

/// A configuration's entry: median step time, its runs in round order, the phases of the median
/// run (the lower middle one for an even count), so the phases add up to the reported time.
Json configuration(const std::vector<Json>& runs, int steps) {
  std::vector<double> totals;
  for (const Json& r : runs) totals.push_back(r["total_ms"].get<double>());
  std::vector<std::size_t> order(totals.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return totals[x] < totals[y]; });
  return {{"step_ms", median_of(totals) / steps},
          {"runs_ms", totals},
          {"phases_per_step", runs[order[(order.size() - 1) / 2]]["phases"]}};
}

Json scene_results(const SceneRecords& s, const std::vector<std::string>& methods) {
  const int steps = s.info["steps"].get<int>();
  Json scene = s.info;
  scene["methods"] = Json::object();
  scene["table1"] = s.table1;
  double sequential = 0.0;
  for (const std::string& m : methods) {
    Json method = {{"threads", Json::object()}};
    for (const auto& [key, runs] : s.runs) {
      if (key.first == m) method["threads"][std::to_string(key.second)] = configuration(runs, steps);
    }
    if (method["threads"].empty()) continue;
    if (m == "sequential") sequential = method["threads"]["1"]["step_ms"].get<double>();
    if (s.simulated.count(m)) method["simulated_speedup"] = s.simulated.at(m);
    if (s.predicted.count(m)) method["predicted"] = s.predicted.at(m);
    if (s.correlation.count(m)) method["correlation"] = s.correlation.at(m);
    scene["methods"][m] = method;
  }
  scene["sequential_step_ms"] = sequential;
  Json ceiling = Json::object();
  for (const auto& [copies, ms] : s.ceiling) {
    const double copy = median_of(ms);
    ceiling[std::to_string(copies)] = {{"copy_step_ms", ms}, {"ceiling_speedup", copy > 0 ? copies * sequential / copy : 0.0}};
  }
  scene["ceiling"] = ceiling;
  return scene;
}

}  // namespace

Json results_from_records(const std::vector<Json>& records) {
  if (records.empty() || records.front()["kind"] != "header") {
    throw Error(ErrorCode::unreadable, "bench log", "no header record");
  }
  const Json& h = records.front();
  Json results = {{"machine", h["machine"]},
                  {"cpu", h["cpu"]},
                  {"hardware_threads", h["hardware_threads"]},
                  {"compiler", h["compiler"]},
                  {"repeat", h["repeat"]},
                  {"threads", h["threads"]},
                  {"simulate", h["simulate"]},
                  {"simulate_steps", h["simulate_steps"]}};
  const auto methods = h["methods"].get<std::vector<std::string>>();
  std::vector<SceneRecords> scenes;
  std::map<std::string, std::size_t> index;
  for (const Json& info : h["scenes"]) {
    index[info["name"].get<std::string>()] = scenes.size();
    scenes.push_back(SceneRecords{info, Json(), {}, {}, {}, {}, {}});
  }
  const auto scene_of = [&](const Json& r) -> SceneRecords& {
    const auto it = index.find(r.value("scene", std::string()));
    if (it == index.end()) throw Error(ErrorCode::unreadable, "bench log", "a record names a scene the header does not list");
    return scenes[it->second];
  };
  bool identical = true;
  std::size_t runs_done = 0;
  results["fcl_report"] = "Not run.\n";
  for (const Json& r : records) {
    const std::string kind = r["kind"].get<std::string>();
    if (kind == "run") {
      scene_of(r).runs[{r["method"].get<std::string>(), r["threads"].get<int>()}].push_back(r);
      ++runs_done;
    } else if (kind == "table1") {
      Json t = r;
      t.erase("kind");
      t.erase("scene");
      scene_of(r).table1 = t;
    } else if (kind == "ceiling") {
      scene_of(r).ceiling[r["copies"].get<int>()] = r["copy_step_ms"].get<std::vector<double>>();
    } else if (kind == "simulation") {
      SceneRecords& s = scene_of(r);
      const std::string m = r["method"].get<std::string>();
      s.simulated[m][std::to_string(r["cores"].get<int>())] = r["speedup"];
      if (r.contains("predicted_step_ms") && r["predicted_step_ms"].is_number() && r["predicted_step_ms"].get<double>() > 0 &&
          r.contains("sequential_step_ms") && r["sequential_step_ms"].is_number()) {
        const double predicted = r["predicted_step_ms"].get<double>();
        s.predicted[m][std::to_string(r["cores"].get<int>())] = {{"step_ms", predicted},
                                                                 {"sequential_step_ms", r["sequential_step_ms"]},
                                                                 {"speedup", r["sequential_step_ms"].get<double>() / predicted}};
      }
      if (r.contains("correlation")) s.correlation[m] = r["correlation"];
    } else if (kind == "mismatch") {
      identical = false;
    } else if (kind == "gantt") {
      Json g = r;
      g.erase("kind");
      results["gantt"] = g;
    } else if (kind == "fcl") {
      results["fcl_report"] = r["report"];
    } else if (kind == "stopped") {
      results["stopped"] = {{"reason", r["reason"]}, {"after_s", r["after_s"]}};
      if (r["reason"] == "interrupted") {
        results["stopped"]["signal"] = r.value("signal", "a signal");
        results["interrupted"] = true;
      }
    }
  }
  results["scenes"] = Json::array();
  for (const SceneRecords& s : scenes) {
    if (s.table1.is_null() || !s.runs.count({"sequential", 1})) continue;  // no reference yet
    results["scenes"].push_back(scene_results(s, methods));
  }
  results["contacts_identical"] = identical;
  results["runs_done"] = runs_done;
  results["runs_planned"] = h["runs_planned"];
  return results;
}

}  // namespace caliber::cli
