#include "json_output.h"

#include "util/printable.h"

namespace caliber::cli {
namespace {
nlohmann::json vec(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }
}  // namespace

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
                        {"point_a", vec(c.point_a)},
                        {"point_b", vec(c.point_b)},
                        {"normal", vec(c.normal)},
                        {"distance", c.distance},
                        {"depth", c.depth}});
  }
  out["limit_reached"] = result.limit_reached;
  out["stats"] = {{"node_tests", result.stats.node_tests}, {"leaf_tests", result.stats.leaf_tests}};
  return out;
}

std::string json_text(std::string_view text) { return utf8_or_escaped(text); }

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
