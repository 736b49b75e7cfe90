#include "json_output.h"

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

}  // namespace caliber::cli
