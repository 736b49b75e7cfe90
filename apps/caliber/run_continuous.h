#pragma once
// caliber run --continuous: each step's motion to the next swept, the pairs that touch between
// steps printed with when, and optionally written to a JSON report.

#include <string>

#include "caliber/engine.h"
#include "caliber/scene.h"

namespace caliber::cli {

struct ContinuousOptions {
  std::string scene_file;  ///< the scene's path as given (kept apart from the report)
  double tolerance = 0.0;  ///< SweepRequest::tolerance
  std::string json;        ///< the report's path, or empty
};

/// Runs the scene's step intervals through World::sweep on `engine` (its method says how a heavy
/// sweep's queries are split); returns the exit code (130 when SIGINT stopped it, 143 for
/// SIGTERM; what was swept is written). Throws caliber::Error on a bad tolerance or report path,
/// before any work.
int run_continuous(const ContinuousOptions& opt, Engine& engine, Scene scene);

}  // namespace caliber::cli
