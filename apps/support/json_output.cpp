#include "json_output.h"

#include "util/printable.h"

namespace caliber::cli {

nlohmann::json json_vector(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

void write_scene_header(JsonObjectWriter& report, const World& world, int version) {
  const Scene& sc = world.scene();
  nlohmann::json objects = nlohmann::json::array();
  for (std::size_t i = 0; i < world.object_count(); ++i) {
    objects.push_back({{"id", i}, {"name", json_text(sc.objects[i].name)}, {"mesh", json_text(sc.objects[i].mesh.string())}});
  }
  report.member("schema_version", version);
  report.member("scene", json_text(sc.name));
  report.member("file", json_text(sc.file.string()));
  report.member("objects", objects);
}

nlohmann::json to_json(const QueryResult& result) {
  nlohmann::json out;
  out["kind"] = std::string(to_string(result.kind));
  auto& pairs = out["pairs"] = nlohmann::json::array();
  for (const Contact& c : result.contacts) pairs.push_back({c.tri_a, c.tri_b});
  auto& contacts = out["contacts"] = nlohmann::json::array();
  // Interference reports triangle ids only: its pairs say it all.
  for (const Contact& c : result.kind == QueryKind::interference ? std::vector<Contact>{} : result.contacts) {
    contacts.push_back({{"tri_a", c.tri_a},
                        {"tri_b", c.tri_b},
                        {"point_a", json_vector(c.point_a)},
                        {"point_b", json_vector(c.point_b)},
                        {"normal", json_vector(c.normal)},
                        {"distance", c.distance},
                        {"depth", c.depth}});
  }
  out["limit_reached"] = result.limit_reached;
  out["stats"] = {{"node_tests", result.stats.node_tests}, {"leaf_tests", result.stats.leaf_tests}};
  return out;
}

std::string json_text(std::string_view text) { return utf8_or_escaped(text); }

std::string line_text(std::string_view text) { return printable(text); }

JsonObjectWriter::JsonObjectWriter(std::ostream& out, std::string (*filter)(const std::string&)) : mOut(out), mFilter(filter) {
  mOut << '{';
}

void JsonObjectWriter::put(const std::string& json) { mOut << (mFilter ? mFilter(json) : json); }

void JsonObjectWriter::key(std::string_view key) {
  mOut << (mFirstMember ? "\n" : ",\n");
  mFirstMember = false;
  put(nlohmann::json(json_text(key)).dump() + ":");
}

void JsonObjectWriter::put_value(const nlohmann::json& value) {
  // Every string put in was made valid UTF-8 (json_text); replacing is the last guard, so that a
  // report is never lost at its end to a byte that slipped through.
  put(value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

void JsonObjectWriter::member(std::string_view key, const nlohmann::json& value) {
  this->key(key);
  put_value(value);
}

void JsonObjectWriter::open_array(std::string_view key) {
  this->key(key);
  mOut << '[';
  mFirstItem = true;
}

void JsonObjectWriter::item(const nlohmann::json& value) {
  mOut << (mFirstItem ? "\n" : ",\n");
  mFirstItem = false;
  put_value(value);
}

void JsonObjectWriter::close_array() { mOut << "\n]"; }

void JsonObjectWriter::close() { mOut << "\n}\n"; }

}  // namespace caliber::cli
