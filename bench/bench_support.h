#pragma once
// What the mesh benches share without any peer library: where the meshes are, median timing, the
// checkout's commit and a mesh's box. fcl_support.h adds FCL's side.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliber/mesh.h"

namespace caliber::bench {

/// Where the benches look for the CGAL meshes without --meshes: data/meshes under the working
/// directory where there is one (a device pack, a checkout's root), else the source tree's
/// (CALIBER_BENCH_MESHES: the benches run from build/ too).
inline std::filesystem::path default_meshes_dir() {
  const std::filesystem::path here = "data/meshes";
#ifdef CALIBER_BENCH_MESHES
  if (!std::filesystem::is_directory(here)) return CALIBER_BENCH_MESHES;
#endif
  return here;
}

/// Median wall time of `repeat` runs of f, in milliseconds.
inline double median_ms(int repeat, const std::function<void()>& f) {
  std::vector<double> times;
  for (int i = 0; i < repeat; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

/// The median of v (the upper one of an even count); NaN for no value.
inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The short hash of the checkout's HEAD ("unknown" outside one): a bench's commit when it is not given.
inline std::string git_commit() {
  char buffer[64] = "";
  if (FILE* pipe = popen("git rev-parse --short HEAD 2>/dev/null", "r")) {
    if (std::fgets(buffer, sizeof buffer, pipe) == nullptr) buffer[0] = '\0';
    pclose(pipe);
  }
  const std::string out(buffer, std::strcspn(buffer, "\r\n"));
  return out.empty() ? "unknown" : out;
}

/// The axis-aligned box of a mesh's vertices: its low and high corners.
inline void box(const Mesh& m, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = m.vertices[0];
  hi = lo;
  for (const auto& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

/// The center and diagonal of a mesh's box.
inline void box_center(const Mesh& m, Eigen::Vector3d& center, double& diagonal) {
  Eigen::Vector3d lo, hi;
  box(m, lo, hi);
  center = 0.5 * (lo + hi);
  diagonal = (hi - lo).norm();
}

}  // namespace caliber::bench
