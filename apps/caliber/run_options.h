#pragma once
// caliber run's options, and their checks before anything is loaded or written.

#include <string>
#include <vector>

#include "caliber/engine.h"
#include "export_files.h"

namespace caliber::cli {

/// What `caliber run` was given.
struct RunOptions {
  std::string scene;
  std::string method{to_string(kDefaultMethod)};
  int threads = 0;
  int stealing_depth = EngineOptions{}.stealing_depth;
  double beta = EngineOptions{}.beta;
  double epsilon = EngineOptions{}.epsilon;
  bool node_history = false;
  std::vector<int> simulate = {2, 4, 8, 16, 32, 64};
  int steps = -1;
  std::string json;
  std::string contacts;
  ExportOptions exports;
  std::size_t max_pairs = 0;
  bool continuous = false;
  double sweep_tolerance = 0.0;
  std::vector<std::string> given;  ///< the options given on the command line, by their long names
};

/// The options checked before anything is loaded or written (the scene's own checks come later):
/// those the mode does not read refused by name (a value that would be ignored is no setting:
/// --continuous reads none of the steps' outputs, limits and calibration; the steps read no
/// --sweep-tolerance; --export-steps and --bvh-depth are --export's), the others' values checked
/// (the engine's by its constructor).
void check_run_options(const RunOptions& opt);

}  // namespace caliber::cli
