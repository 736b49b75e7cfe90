// Scene files: strict JSON reading with errors that name the file and the key.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "caliber/error.h"
#include "caliber/scene.h"
#include "world/json_scan.h"

namespace caliber {
namespace {
using Json = nlohmann::json;

/// Reads values out of the JSON tree; every failure names the file and the key path.
class Reader {
 public:
  explicit Reader(std::string source) : mSource(std::move(source)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& problem, ErrorCode code = ErrorCode::bad_value) const {
    throw Error(code, mSource, key.empty() ? problem : "'" + key + "': " + problem);
  }

  void object(const Json& j, const std::string& where) const {
    if (!j.is_object()) fail(where, "must be an object");
  }

  void only_keys(const Json& j, const std::string& where, std::initializer_list<const char*> allowed) const {
    object(j, where);
    for (const auto& [key, value] : j.items()) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || key == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(join(where, key), "unknown key (expected one of: " + list + ")");
      }
    }
  }

  static std::string join(const std::string& where, const std::string& key) { return where.empty() ? key : where + "." + key; }

  double number(const Json& j, const std::string& key) const {
    if (!j.is_number()) fail(key, "must be a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(key, "must be finite");
    return v;
  }

  double number(const Json& obj, const std::string& where, const char* key, double fallback) const {
    return obj.contains(key) ? number(obj.at(key), join(where, key)) : fallback;
  }

  int integer(const Json& j, const std::string& key, long lo, long hi) const {
    if (!j.is_number_integer()) fail(key, "must be an integer");
    const long v = j.get<long>();
    if (v < lo || v > hi) fail(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }

  std::string string(const Json& j, const std::string& key) const {
    if (!j.is_string()) fail(key, "must be a string");
    return j.get<std::string>();
  }

  Eigen::Vector3d vec3(const Json& j, const std::string& key) const {
    if (!j.is_array() || j.size() != 3) fail(key, "must be an array of 3 numbers");
    return {number(j[0], key + "[0]"), number(j[1], key + "[1]"), number(j[2], key + "[2]")};
  }

  Eigen::Quaterniond quat(const Json& j, const std::string& key) const {
    if (!j.is_array() || j.size() != 4) fail(key, "must be an array of 4 numbers [w, x, y, z]");
    double q[4];
    for (int i = 0; i < 4; ++i) q[i] = number(j[i], key + "[" + std::to_string(i) + "]");
    try {
      return unit_quaternion(q[0], q[1], q[2], q[3], "");
    } catch (const Error& e) {
      fail(key, e.what());
    }
  }

  const Json& required(const Json& obj, const std::string& where, const char* key) const {
    if (!obj.contains(key)) fail(join(where, key), "is required", ErrorCode::bad_value);
    return obj.at(key);
  }

 private:
  std::string mSource;
};

Motion read_motion(const Reader& r, const Json& j, const std::string& where) {
  r.object(j, where);
  const std::string type = j.contains("type") ? r.string(j.at("type"), where + ".type") : "static";
  Motion m;
  if (type == "static") {
    r.only_keys(j, where, {"type"});
    m.type = Motion::Type::fixed;
  } else if (type == "velocity") {
    r.only_keys(j, where, {"type", "linear", "angular"});
    m.type = Motion::Type::velocity;
    if (j.contains("linear")) m.linear = r.vec3(j.at("linear"), where + ".linear");
    if (j.contains("angular")) m.angular = r.vec3(j.at("angular"), where + ".angular");
  } else if (type == "keyframes") {
    r.only_keys(j, where, {"type", "keys"});
    m.type = Motion::Type::keyframes;
    const Json& keys = r.required(j, where, "keys");
    if (!keys.is_array() || keys.empty()) r.fail(where + ".keys", "must be a non-empty array");
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const std::string at = where + ".keys[" + std::to_string(i) + "]";
      r.only_keys(keys[i], at, {"time", "position", "orientation"});
      Keyframe k;
      k.time = r.number(r.required(keys[i], at, "time"), at + ".time");
      if (keys[i].contains("position")) k.position = r.vec3(keys[i].at("position"), at + ".position");
      if (keys[i].contains("orientation")) k.orientation = r.quat(keys[i].at("orientation"), at + ".orientation");
      const bool after = m.keys.empty() || (k.time > m.keys.back().time && std::isfinite(k.time - m.keys.back().time));
      if (!after)
        r.fail(at + ".time", k.time > m.keys.back().time ? "is too far from the key before it" : "key times must increase");
      m.keys.push_back(k);
    }
  } else {
    r.fail(where + ".type", "unknown motion '" + type + "' (expected static, velocity or keyframes)");
  }
  return m;
}

SceneObject read_object(const Reader& r, const Json& j, const std::string& where, const std::filesystem::path& base,
                        std::size_t index) {
  r.only_keys(j, where, {"name", "mesh", "scale", "refine", "position", "orientation", "motion", "group", "groups"});
  SceneObject o;
  o.name = j.contains("name") ? r.string(j.at("name"), where + ".name") : "object" + std::to_string(index);
  const std::string mesh = r.string(r.required(j, where, "mesh"), where + ".mesh");
  o.mesh = std::filesystem::path(mesh).is_absolute() ? std::filesystem::path(mesh) : base / mesh;
  o.mesh = o.mesh.lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.mesh, ec)) {
    // A path that cannot be followed (a loop of links, a folder without access) is no missing file.
    const bool unreachable = ec && ec != std::errc::no_such_file_or_directory;
    const bool there = unreachable || std::filesystem::exists(o.mesh, ec);
    r.fail(where + ".mesh",
           (unreachable ? "cannot be read (" + ec.message() + "): "
            : there     ? "not a regular mesh file: "
                        : "no such mesh file: ") +
               o.mesh.string() + (std::filesystem::is_directory(o.mesh, ec) ? " (a directory)" : ""),
           there ? ErrorCode::unreadable : ErrorCode::file_not_found);
  }
  o.scale = r.number(j, where, "scale", 1.0);
  if (!(o.scale > 0.0)) r.fail(where + ".scale", "must be > 0");
  if (j.contains("refine")) o.refine = r.integer(j.at("refine"), where + ".refine", 0, 6);
  if (j.contains("position")) o.pose.translation = r.vec3(j.at("position"), where + ".position");
  if (j.contains("orientation")) o.pose.rotation = r.quat(j.at("orientation"), where + ".orientation");
  if (j.contains("motion")) o.motion = read_motion(r, j.at("motion"), where + ".motion");
  if (j.contains("group")) o.group = static_cast<std::uint8_t>(r.integer(j.at("group"), where + ".group", 0, kMaxGroups - 1));
  if (j.contains("groups")) {
    const Json& g = j.at("groups");
    if (!g.is_array()) r.fail(where + ".groups", "must be an array of {first, count, group}");
    for (std::size_t i = 0; i < g.size(); ++i) {
      const std::string at = where + ".groups[" + std::to_string(i) + "]";
      r.only_keys(g[i], at, {"first", "count", "group"});
      GroupRange range;
      range.first = static_cast<std::uint32_t>(r.integer(r.required(g[i], at, "first"), at + ".first", 0, 0x7fffffff));
      range.count = static_cast<std::uint32_t>(r.integer(r.required(g[i], at, "count"), at + ".count", 0, 0x7fffffff));
      range.group = static_cast<std::uint8_t>(r.integer(r.required(g[i], at, "group"), at + ".group", 0, kMaxGroups - 1));
      o.groups.push_back(range);
    }
  }
  return o;
}

QueryRequest read_query(const Reader& r, const Json& q) {
  r.only_keys(q, "query", {"kind", "tolerance", "angle", "max_pairs"});
  QueryRequest query;
  if (q.contains("kind")) {
    const std::string kind = r.string(q.at("kind"), "query.kind");  // fails naming the file and key itself
    try {
      query.kind = parse_query_kind(kind);
    } catch (const Error& e) {
      r.fail("query.kind", e.what());
    }
  }
  query.tolerance = r.number(q, "query", "tolerance", 0.0);
  if (query.tolerance < 0.0) r.fail("query.tolerance", "must be >= 0");
  if (query.tolerance > kMaxCoordinate) r.fail("query.tolerance", "must be at most 1e15 (caliber's limit on coordinates)");
  if (query.tolerance > 0.0 && query.tolerance < kMinCoordinate) {
    r.fail("query.tolerance", "must be 0 or at least 2^-120 (about 7.5e-37; caliber's exact predicates need no smaller)");
  }
  query.angle_deg = r.number(q, "query", "angle", query.angle_deg);
  if (query.angle_deg < 0.0 || query.angle_deg > 180.0) r.fail("query.angle", "must be in [0, 180] degrees");
  if (q.contains("max_pairs"))
    query.max_pairs = static_cast<std::size_t>(r.integer(q.at("max_pairs"), "query.max_pairs", 0, 0x7fffffff));
  return query;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::filesystem::path& base_dir, const std::string& source) {
  const Reader r(source);
  // JSON holds no NUL byte; the parser would end the text there and ignore the rest.
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos) {
    throw Error(ErrorCode::unreadable, source, "holds a NUL byte at offset " + std::to_string(nul) + " (not a JSON text)");
  }
  Json root;
  try {
    world::JsonScan check(source);
    Json::sax_parse(text, &check);
    root = Json::parse(text);
  } catch (const Json::exception& e) {  // parse_error, and out_of_range for a number like 1e999
    throw Error(ErrorCode::unreadable, source, std::string("not valid JSON: ") + e.what());
  }
  r.only_keys(root, "", {"name", "steps", "dt", "query", "groups", "ignore", "objects"});
  Scene scene;
  scene.name = root.contains("name") ? r.string(root.at("name"), "name") : std::filesystem::path(source).stem().string();
  if (root.contains("steps")) scene.steps = r.integer(root.at("steps"), "steps", 1, kMaxSceneSteps);
  scene.dt = r.number(root, "", "dt", scene.dt);
  if (!(scene.dt > 0.0)) r.fail("dt", "must be > 0");

  if (root.contains("query")) scene.query = read_query(r, root.at("query"));

  const Json& objects = r.required(root, "", "objects");
  if (!objects.is_array() || objects.empty()) r.fail("objects", "must be a non-empty array");
  std::map<std::string, int> ids;  // name -> object id: `ignore` names are looked up, not scanned for
  for (std::size_t i = 0; i < objects.size(); ++i) {
    SceneObject o = read_object(r, objects[i], "objects[" + std::to_string(i) + "]", base_dir, i);
    if (!ids.emplace(o.name, static_cast<int>(i)).second) {
      r.fail("objects[" + std::to_string(i) + "].name", "duplicate name '" + o.name + "'");
    }
    scene.objects.push_back(std::move(o));
  }
  const auto find = [&](const Json& name, const std::string& key) {
    const std::string n = r.string(name, key);
    const auto it = ids.find(n);
    if (it == ids.end()) r.fail(key, "no object named '" + n + "'");
    return it->second;
  };

  if (root.contains("groups")) {
    const Json& g = root.at("groups");
    r.only_keys(g, "groups", {"compatible"});
    const Json& pairs = r.required(g, "groups", "compatible");
    if (!pairs.is_array()) r.fail("groups.compatible", "must be an array of [g, h] pairs");
    scene.use_groups = true;
    scene.compatibility.compatible.fill(0);
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const std::string at = "groups.compatible[" + std::to_string(i) + "]";
      if (!pairs[i].is_array() || pairs[i].size() != 2) r.fail(at, "must be a pair [g, h]");
      const int a = r.integer(pairs[i][0], at + "[0]", 0, kMaxGroups - 1);
      const int b = r.integer(pairs[i][1], at + "[1]", 0, kMaxGroups - 1);
      scene.compatibility.compatible[a] |= std::uint64_t{1} << b;
      scene.compatibility.compatible[b] |= std::uint64_t{1} << a;
    }
  }
  if (root.contains("ignore")) {
    const Json& ig = root.at("ignore");
    if (!ig.is_array()) r.fail("ignore", "must be an array of [name, name] pairs");
    for (std::size_t i = 0; i < ig.size(); ++i) {
      const std::string at = "ignore[" + std::to_string(i) + "]";
      if (!ig[i].is_array() || ig[i].size() != 2) r.fail(at, "must be a pair of object names");
      const int a = find(ig[i][0], at + "[0]");
      const int b = find(ig[i][1], at + "[1]");
      if (a == b) r.fail(at, "an object cannot be paired with itself");
      scene.ignore.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  return scene;
}

Scene load_scene(const std::filesystem::path& file) {
  if (file.empty()) throw Error(ErrorCode::bad_argument, "scene path", "is empty");
  if (file.native().find('\0') != std::string::npos)
    throw Error(ErrorCode::bad_argument, file.string(), "the path holds a NUL byte");
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw Error(ErrorCode::file_not_found, file.string(), "no such scene file");
  if (std::filesystem::is_directory(file, ec))
    throw Error(ErrorCode::unreadable, file.string(), "is a directory, not a scene file");
  // Read whole: a FIFO or a device (/dev/zero) would block or never end.
  if (!std::filesystem::is_regular_file(file, ec)) throw Error(ErrorCode::unreadable, file.string(), "is not a regular file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(ErrorCode::unreadable, file.string(), "cannot be opened for reading");
  std::stringstream text;
  text << in.rdbuf();
  Scene scene = parse_scene(text.str(), std::filesystem::absolute(file).parent_path(), file.string());
  scene.file = file;
  return scene;
}

Pose pose_at(const Pose& initial, const Motion& motion, double t) {
  switch (motion.type) {
    case Motion::Type::fixed:
      return initial;
    case Motion::Type::velocity: {
      Pose p;
      p.translation = initial.translation + motion.linear * t;
      const Eigen::Vector3d turn = motion.angular * t;
      const double angle = turn.norm();
      // Without a turn the orientation is the initial one, bit for bit (no renormalization), so a
      // velocity object at t = 0, or one that only translates, has exactly the pose it was given.
      p.rotation = angle > 0.0 ? (Eigen::Quaterniond(Eigen::AngleAxisd(angle, turn / angle)) * initial.rotation).normalized()
                               : initial.rotation;
      return p;
    }
    case Motion::Type::keyframes: {
      const auto& keys = motion.keys;
      if (keys.empty()) throw Error(ErrorCode::bad_value, "motion", "a keyframe motion needs at least one key");
      Pose p;
      if (t <= keys.front().time || keys.size() == 1) {
        p.translation = keys.front().position;
        p.rotation = keys.front().orientation;
        return p;
      }
      if (t >= keys.back().time) {
        p.translation = keys.back().position;
        p.rotation = keys.back().orientation;
        return p;
      }
      // The first key at or after t (binary search: a baked animation has one key a frame).
      const std::size_t i = static_cast<std::size_t>(
          std::lower_bound(keys.begin(), keys.end(), t, [](const Keyframe& k, double at) { return k.time < at; }) - keys.begin());
      if (keys[i].time == t) {  // a key's own pose, not the slerp's end (which may be its negation)
        p.translation = keys[i].position;
        p.rotation = keys[i].orientation;
        return p;
      }
      const Keyframe& k0 = keys[i - 1];
      const Keyframe& k1 = keys[i];
      const double s = (t - k0.time) / (k1.time - k0.time);
      p.translation = (1.0 - s) * k0.position + s * k1.position;
      p.rotation = k0.orientation.slerp(s, k1.orientation).normalized();
      return p;
    }
  }
  return initial;
}

}  // namespace caliber
