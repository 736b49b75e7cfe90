// A motion that must not tunnel: a needle flies through a thin plate within one step. Neither end
// pose touches the plate; the swept query finds when the needle first reaches it.
//   swept_needle

#include <cstdio>

#include <caliber/caliber.h>
#include <caliber/procedural.h>

int main() {
  try {
    // [readme]
    const auto plate = caliber::build_model(caliber::make_plate(1.0, 0.002, 4));
    const auto needle = caliber::build_model(caliber::make_box(0.001, 0.001, 0.1, 1));
    const caliber::SweptPose still{caliber::Pose{}, caliber::Pose{}};
    const caliber::SweptPose flight{caliber::Pose::from_values(0.3, 0.2, 1.0, 1, 0, 0, 0),
                                    caliber::Pose::from_values(0.3, 0.2, -1.0, 1, 0, 0, 0)};
    caliber::QueryRequest touch;
    touch.max_pairs = 1;
    const bool at_start = !caliber::query(*plate, still.start, *needle, flight.start, touch).contacts.empty();
    const bool at_end = !caliber::query(*plate, still.end, *needle, flight.end, touch).contacts.empty();
    const caliber::SweepResult s = caliber::sweep(*plate, still, *needle, flight);
    // [/readme]
    std::printf("touching at t = 0: %s, at t = 1: %s\n", at_start ? "yes" : "no", at_end ? "yes" : "no");
    if (s.status != caliber::SweepStatus::contact) {
      std::printf("no contact found\n");
      return 1;
    }
    std::printf("first contact at t = %.6f (triangles %u and %u, %.2g apart; %llu distance queries)\n", s.time, s.closest.tri_a,
                s.closest.tri_b, s.closest.distance, static_cast<unsigned long long>(s.queries));
    return 0;
  } catch (const caliber::Error& e) {
    std::fprintf(stderr, "swept_needle: %s\n", e.what());
    return 2;
  }
}
