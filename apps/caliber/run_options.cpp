// caliber run's option checks (run_options.h).

#include "run_options.h"

#include <algorithm>
#include <string>
#include <string_view>

#include "caliber/error.h"
#include "caliber/scene.h"
#include "commands.h"
#include "caliber/mesh.h"

namespace caliber::cli {
namespace {

/// Whether option `name` was given on the command line.
bool given(const RunOptions& opt, std::string_view name) {
  return std::find(opt.given.begin(), opt.given.end(), name) != opt.given.end();
}

/// Options the mode does not read, refused by name.
void check_mode_options(const RunOptions& opt) {
  static constexpr std::string_view kStepsOnly[] = {"--contacts",     "--export",        "--export-steps", "--bvh-depth",
                                                    "--max-pairs",    "--beta",          "--epsilon",      "--stealing-depth",
                                                    "--node-history", "--simulate-cores"};
  for (const std::string_view name : kStepsOnly) {
    if (opt.continuous && given(opt, name)) {
      throw Error(ErrorCode::bad_argument, "--continuous",
                  "reports the pairs that touch between steps: it takes none of --contacts, --export, --export-steps, "
                  "--bvh-depth, --max-pairs, --beta, --epsilon, --stealing-depth, --node-history, --simulate-cores (" +
                      std::string(name) + " given)");
    }
  }
  if (!opt.continuous && given(opt, "--sweep-tolerance")) {
    throw Error(ErrorCode::bad_argument, "--sweep-tolerance", "is read only with --continuous");
  }
  for (const std::string_view name : {std::string_view("--export-steps"), std::string_view("--bvh-depth")}) {
    if (opt.exports.dir.empty() && given(opt, name)) {
      throw Error(ErrorCode::bad_argument, std::string(name), "is read only with --export DIR");
    }
  }
  // The methods' own options: the calibration's, the hybrid's history, stealing's depth.
  const Method method = method_option(opt.method);
  const bool calibrated = method == Method::aposteriori || method == Method::apriori || method == Method::hybrid;
  const std::string by = " (--method " + opt.method + ")";
  for (const std::string_view name : {std::string_view("--beta"), std::string_view("--epsilon")}) {
    if (!calibrated && given(opt, name)) {
      throw Error(ErrorCode::bad_argument, std::string(name),
                  "is read only by the calibrated methods: aposteriori, apriori, hybrid" + by);
    }
  }
  if (method != Method::hybrid && given(opt, "--node-history")) {
    throw Error(ErrorCode::bad_argument, "--node-history", "is read only by --method hybrid" + by);
  }
  if (method != Method::stealing && given(opt, "--stealing-depth")) {
    throw Error(ErrorCode::bad_argument, "--stealing-depth", "is read only by --method stealing" + by);
  }
}

/// The export steps: none negative (the last is checked against the scene's steps once it is
/// read), each listed once (sorted: a long list is checked in n log n).
void check_export_steps(std::vector<int> listed) {
  std::sort(listed.begin(), listed.end());
  if (!listed.empty() && listed.front() < 0) {
    throw Error(ErrorCode::bad_value, "--export-steps",
                "step " + std::to_string(listed.front()) + " is negative: steps count from 0");
  }
  const auto twice = std::adjacent_find(listed.begin(), listed.end());
  if (twice != listed.end()) {
    throw Error(ErrorCode::bad_value, "--export-steps", "step " + std::to_string(*twice) + " is listed twice");
  }
}

}  // namespace

void check_run_options(const RunOptions& opt) {
  check_mode_options(opt);
  if (!(opt.sweep_tolerance >= 0.0) || opt.sweep_tolerance > kMaxCoordinate ||
      (opt.sweep_tolerance != 0.0 && opt.sweep_tolerance < kMinCoordinate)) {
    throw Error(ErrorCode::bad_value, "--sweep-tolerance", "must be 0 or in [2^-120, 1e15]");
  }
  check_steps_option(opt.steps);
  for (const int p : opt.simulate) {
    if (p < 1 || p > 4096) throw Error(ErrorCode::bad_value, "--simulate-cores", "core counts must be in [1, 4096]");
  }
  if (opt.exports.bvh_depth < -1) throw Error(ErrorCode::bad_value, "--bvh-depth", "must be -1 (no BVH) or a depth >= 0");
  check_export_steps(opt.exports.steps);
}

}  // namespace caliber::cli
