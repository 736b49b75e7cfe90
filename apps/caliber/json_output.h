#pragma once
// JSON forms of the library's results, for the CLI's --json output.

#include <nlohmann/json.hpp>

#include "caliber/query.h"

namespace caliber::cli {

/// {"kind":…, "pairs":[[ia,ib],…], "contacts":[…], "stats":{"node_tests":…, "leaf_tests":…}}
nlohmann::json to_json(const QueryResult& result);

}  // namespace caliber::cli
