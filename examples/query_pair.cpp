// Uses the installed caliber: loads two meshes, runs an interference and a contact query of B
// moved by a pose, and prints what they found.
//   query_pair A.off B.off "tx ty tz qw qx qy qz" TOLERANCE

#include <cstdio>
#include <cstdlib>

#include <caliber/caliber.h>

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s A B \"tx ty tz qw qx qy qz\" TOLERANCE\n", argv[0]);
    return 2;
  }
  try {
    // [readme]
    const auto a = caliber::build_model(caliber::load_mesh(argv[1]));
    const auto b = caliber::build_model(caliber::load_mesh(argv[2]));
    const caliber::Pose pose_b = caliber::parse_pose(argv[3], "pose of B");
    caliber::QueryRequest request;
    const caliber::QueryResult hits = caliber::query(*a, caliber::Pose{}, *b, pose_b, request);
    request.kind = caliber::QueryKind::contact;
    request.tolerance = std::atof(argv[4]);
    const caliber::QueryResult contacts = caliber::query(*a, caliber::Pose{}, *b, pose_b, request);
    // [/readme]
    std::printf("caliber %s\n", caliber::kVersion);
    std::printf("interference: %zu pairs\n", hits.contacts.size());
    std::printf("contact: %zu contacts\n", contacts.contacts.size());
    return 0;
  } catch (const caliber::Error& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 2;
  }
}
