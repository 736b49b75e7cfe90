#pragma once
// JSON forms of the library's results, for the CLI's --json output.

#include <nlohmann/json.hpp>

#include "caliber/query.h"

namespace caliber::cli {

/// The version of the JSON the CLI writes (run --json, run --contacts, query --json, the viewer's
/// data; docs/json.md). Raised when a field changes meaning or goes away, not when one is added.
inline constexpr int kSchemaVersion = 1;

/// {"kind":…, "pairs":[[ia,ib],…], "contacts":[…], "stats":{"node_tests":…, "leaf_tests":…}}
nlohmann::json to_json(const QueryResult& result);

}  // namespace caliber::cli
