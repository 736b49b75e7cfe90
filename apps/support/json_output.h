#pragma once
// JSON forms of the library's results, for the CLI's --json output.

#include <ostream>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "caliber/query.h"
#include "caliber/world.h"

namespace caliber::cli {

/// The version of each JSON output the CLI writes (docs/json.md), raised when a field of that
/// output changes meaning or goes away, not when one is added. kSchemaVersion: run --contacts,
/// run --continuous --json, query --json and the viewer's data; kReportSchemaVersion: run --json.
inline constexpr int kSchemaVersion = 1;
inline constexpr int kReportSchemaVersion = 2;

/// {"kind":…, "pairs":[[ia,ib],…], "contacts":[…], "stats":{"node_tests":…, "leaf_tests":…}}
nlohmann::json to_json(const QueryResult& result);

/// A path or a name as a JSON string: bytes that are not UTF-8 (a file name in Latin-1, say)
/// written as the text \xNN, so that any path reaches the report (JSON holds only Unicode).
[[nodiscard]] std::string json_text(std::string_view text);

/// Text from outside (a scene or object name) for a one-line text format, a PLY header comment:
/// control characters and bytes that are not UTF-8 as \xNN.
[[nodiscard]] std::string line_text(std::string_view text);

/// A JSON object written member by member: an array of many records (a run's steps) goes out one
/// record at a time as the records are made, and is never held whole. `filter` (optional)
/// rewrites each piece of JSON text before it is written (the viewer's script_safe).
class JsonObjectWriter {
 public:
  explicit JsonObjectWriter(std::ostream& out, std::string (*filter)(const std::string&) = nullptr);
  /// "key": value
  void member(std::string_view key, const nlohmann::json& value);
  /// "key": [ ... then item() for each element, then close_array().
  void open_array(std::string_view key);
  void item(const nlohmann::json& value);
  void close_array();
  /// The closing brace.
  void close();

 private:
  void put(const std::string& json);
  void put_value(const nlohmann::json& value);
  void key(std::string_view key);
  std::ostream& mOut;
  std::string (*mFilter)(const std::string&);
  bool mFirstMember = true, mFirstItem = true;
};

/// The members a run's report starts with: schema_version (`version`), scene, file, and objects
/// (one {"id", "name", "mesh"} per scene object).
void write_scene_header(JsonObjectWriter& report, const World& world, int version);

/// [x, y, z]
[[nodiscard]] nlohmann::json json_vector(const Eigen::Vector3d& v);

}  // namespace caliber::cli
