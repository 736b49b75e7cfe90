// Grazing motions in the swept query: parts that slide past each other a hair apart, free all the
// way, whose closest distance over their fastest point gives tiny steps. Prints the status, the
// distance queries and the time of each (one run; a budget of 100,000 queries).
//   bench_sweep_grazing

#include <chrono>
#include <cstdio>

#include "caliber/caliber.h"
#include "caliber/procedural.h"

namespace {

caliber::Pose at(double x, double y, double z) {
  caliber::Pose p;
  p.translation = Eigen::Vector3d(x, y, z);
  return p;
}

const char* status_name(caliber::SweepStatus s) {
  return s == caliber::SweepStatus::free ? "free" : s == caliber::SweepStatus::contact ? "contact" : "undecided";
}

}  // namespace

int main() {
  using caliber::build_model;
  const auto plate = build_model(caliber::make_plate(0.5, 0.02, 24));
  const auto rod = build_model(caliber::make_box(0.6, 0.01, 0.01, 2));
  const auto block = build_model(caliber::make_box(0.3, 0.3, 0.3, 3));
  const auto wire = build_model(caliber::make_box(1.0, 0.0005, 0.0005, 1));
  struct Case {
    const char* name;
    const caliber::Model& a;
    const caliber::Model& b;
    caliber::SweptPose motion_b;
  };
  const Case cases[] = {
      {"plates sliding 1e-6 apart", *plate, *plate, {at(-1.2, 0.3, 0.02 + 1e-6), at(1.2, -0.2, 0.02 + 1e-6)}},
      {"rod grazing a block 1e-6 above", *block, *rod, {at(-1.5, 0.0, 0.31 + 1e-6), at(1.5, 0.2, 0.31 + 1e-6)}},
      {"wire grazing a plate 1e-6 above", *plate, *wire, {at(-0.2, -2.0, 0.0105 + 1e-6), at(0.2, 2.0, 0.0105 + 1e-6)}},
  };
  std::printf("| motion | status | distance queries | ms |\n|---|---|---|---|\n");
  for (const Case& c : cases) {
    caliber::SweepRequest request;
    request.tolerance = 1e-7;
    request.max_queries = 100000;
    const auto start = std::chrono::steady_clock::now();
    const caliber::SweepResult s = caliber::sweep(c.a, {caliber::Pose{}, caliber::Pose{}}, c.b, c.motion_b, request);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::printf("| %s | %s | %llu | %.2f |\n", c.name, status_name(s.status), static_cast<unsigned long long>(s.queries), ms);
  }
  return 0;
}
