// The swept query (caliber/sweep.h) on motions that tunnel between their end poses, grazing and
// already-touching cases, and random motions checked against a dense sampling of time with the
// exact interference test.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "caliber/error.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "caliber/sweep.h"

namespace caliber {
namespace {

Pose at(double x, double y, double z, const Eigen::Quaterniond& q = Eigen::Quaterniond::Identity()) {
  Pose p;
  p.translation = Eigen::Vector3d(x, y, z);
  p.rotation = q;
  return p;
}

Eigen::Quaterniond about_z(double degrees) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
}

bool intersect(const Model& a, const Pose& pa, const Model& b, const Pose& pb) {
  QueryRequest r;
  r.max_pairs = 1;
  return !query(a, pa, b, pb, r).contacts.empty();
}

double distance(const Model& a, const Pose& pa, const Model& b, const Pose& pb) {
  QueryRequest r;
  r.kind = QueryKind::distance;
  r.tolerance = kUnbounded;
  return query(a, pa, b, pb, r).contacts.front().distance;
}

TEST(Sweep, NeedleThroughAPlateIsCaughtThoughNeitherEndPoseTouches) {
  // A plate 0.002 thick in the xy plane; a needle 0.2 long along z flies from z = 1 to z = -1 in
  // one step. Its tip reaches the plate's top (z = 0.001) when its centre is at 0.101: t = 0.4495.
  const auto plate = build_model(make_plate(1.0, 0.002, 4));
  const auto needle = build_model(make_box(0.001, 0.001, 0.1, 1));
  const SweptPose still{Pose{}, Pose{}};
  const SweptPose flight{at(0.3, 0.2, 1.0), at(0.3, 0.2, -1.0)};
  ASSERT_FALSE(intersect(*plate, Pose{}, *needle, flight.start));
  ASSERT_FALSE(intersect(*plate, Pose{}, *needle, flight.end));
  SweepRequest request;
  request.tolerance = 1e-6;
  const SweepResult s = sweep(*plate, still, *needle, flight, request);
  ASSERT_EQ(s.status, SweepStatus::contact);
  const double first = (1.0 - 0.101) / 2.0;
  EXPECT_LE(s.time, first) << "never later than the first contact";
  EXPECT_GE(s.time, first - 1e-6 / 2.0 - 1e-12) << "within the tolerance of it (the needle moves 2 per unit t)";
  EXPECT_LE(s.closest.distance, 1e-6);
  EXPECT_LE(distance(*plate, Pose{}, *needle, flight.at(s.time)), 1e-6);
}

TEST(Sweep, ATurningRodSweepsOverABoxBetweenItsEndPoses) {
  // A rod of half-length 1 along x turns by 170 degrees about z; a small box sits at (0, 0.6):
  // the rod is far from it at both ends (0 and 170 degrees) and passes over it near 90.
  const auto rod = build_model(make_box(1.0, 0.02, 0.02, 2));
  const auto box = build_model(make_box(0.05, 0.05, 0.05, 1));
  const SweptPose turn{Pose{}, at(0, 0, 0, about_z(170.0))};
  const SweptPose still{at(0.0, 0.6, 0.0), at(0.0, 0.6, 0.0)};
  ASSERT_FALSE(intersect(*rod, turn.start, *box, still.start));
  ASSERT_FALSE(intersect(*rod, turn.end, *box, still.start));
  const SweepResult s = sweep(*rod, turn, *box, still);
  ASSERT_EQ(s.status, SweepStatus::contact);
  // No contact before t*, checked on a fine grid; and within the tolerance at t*.
  for (int k = 0; k < 2000 && k / 2000.0 < s.time; ++k) {
    EXPECT_FALSE(intersect(*rod, turn.at(k / 2000.0), *box, still.start)) << "t = " << k / 2000.0;
  }
  EXPECT_LE(distance(*rod, turn.at(s.time), *box, still.start), 1e-6 * std::sqrt(1.0 + 2 * 0.02 * 0.02) + 1e-12);
  EXPECT_LT(s.time, 0.5);
  EXPECT_GT(s.time, 0.3);
}

TEST(Sweep, TouchingAtTheStartIsContactAtZeroAndMovingApartIsFree) {
  const auto a = build_model(make_sphere(1.0, 12, 16));
  const auto b = build_model(make_box(0.3, 0.3, 0.3, 2));
  const SweepResult touching = sweep(*a, {Pose{}, Pose{}}, *b, {at(0.9, 0, 0), at(3.0, 0, 0)});
  EXPECT_EQ(touching.status, SweepStatus::contact);
  EXPECT_EQ(touching.time, 0.0);
  const SweepResult apart = sweep(*a, {Pose{}, Pose{}}, *b, {at(1.5, 0, 0), at(3.0, 0, 0)});
  EXPECT_EQ(apart.status, SweepStatus::free);
  EXPECT_EQ(apart.time, 1.0);
  const SweepResult still = sweep(*a, {Pose{}, Pose{}}, *b, {at(1.5, 0, 0), at(1.5, 0, 0)});
  EXPECT_EQ(still.status, SweepStatus::free);
  EXPECT_EQ(still.queries, 1u);
}

TEST(Sweep, GrazingPassesAreDecidedByTheTolerance) {
  // A box passes beside another at a gap of exactly g (faces parallel): contact iff g <= tolerance.
  const auto a = build_model(make_box(0.5, 0.5, 0.5, 1));
  const auto b = build_model(make_box(0.5, 0.5, 0.5, 1));
  for (const double gap : {1e-3, 1e-5}) {
    const SweptPose pass{at(-3.0, 1.0 + gap, 0.0), at(3.0, 1.0 + gap, 0.0)};
    SweepRequest request;
    request.tolerance = 1e-4;
    const SweepResult s = sweep(*a, {Pose{}, Pose{}}, *b, pass, request);
    if (gap > request.tolerance) {
      EXPECT_EQ(s.status, SweepStatus::free) << "gap " << gap;
    } else {
      ASSERT_EQ(s.status, SweepStatus::contact) << "gap " << gap;
      EXPECT_LE(s.time, 2.0 / 6.0) << "the faces start to overlap in x at t = 1/3";
      EXPECT_LE(s.closest.distance, request.tolerance);
    }
  }
}

TEST(Sweep, RandomMotionsNeverMissASampledContact) {
  // Random motions of a torus and a sphere (each turning up to 180 degrees and moving up to 4
  // radii); time sampled at 1/1000: every sampled contact comes at or after t*, none before it,
  // a "free" sweep has none, and the models are within the tolerance at t*.
  const auto torus = build_model(make_torus(1.0, 0.3, 16, 10));
  const auto sphere = build_model(make_sphere(0.4, 8, 12));
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto random_pose = [&](double spread) {
    Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
    if (q.norm() < 1e-3) q = Eigen::Quaterniond::Identity();
    return at(spread * u(rng), spread * u(rng), spread * u(rng), q.normalized());
  };
  int contacts = 0, frees = 0;
  for (int m = 0; m < 300; ++m) {
    const SweptPose ma{random_pose(0.5), random_pose(0.5)};
    const SweptPose mb{random_pose(2.0), random_pose(2.0)};
    SweepRequest request;
    request.tolerance = 1e-4;
    const SweepResult s = sweep(*torus, ma, *sphere, mb, request);
    ASSERT_NE(s.status, SweepStatus::undecided) << "motion " << m;
    for (int k = 0; k <= 1000; ++k) {
      const double t = k / 1000.0;
      if (!intersect(*torus, ma.at(t), *sphere, mb.at(t))) continue;
      ASSERT_EQ(s.status, SweepStatus::contact) << "motion " << m << ": a sampled contact at t = " << t << " was missed";
      ASSERT_LE(s.time, t) << "motion " << m << ": reported after a sampled contact";
      break;
    }
    if (s.status == SweepStatus::contact) {
      ++contacts;
      EXPECT_LE(distance(*torus, ma.at(s.time), *sphere, mb.at(s.time)), request.tolerance) << "motion " << m;
    } else {
      ++frees;
    }
  }
  EXPECT_GT(contacts, 50);
  EXPECT_GT(frees, 25);
}

TEST(Sweep, BadInputIsAnError) {
  const auto a = build_model(make_sphere(1.0, 8, 8));
  SweepRequest negative;
  negative.tolerance = -1.0;
  EXPECT_THROW(static_cast<void>(sweep(*a, {Pose{}, Pose{}}, *a, {at(3, 0, 0), Pose{}}, negative)), Error);
  SweepRequest none;
  none.max_queries = 0;
  EXPECT_THROW(static_cast<void>(sweep(*a, {Pose{}, Pose{}}, *a, {at(3, 0, 0), Pose{}}, none)), Error);
  Pose bad = at(std::nan(""), 0, 0);
  EXPECT_THROW(static_cast<void>(sweep(*a, {Pose{}, bad}, *a, {at(3, 0, 0), Pose{}})), Error);
}

TEST(Sweep, AnInterpolatedTranslationBelowTheSmallestCoordinateIsZeroNotAnError) {
  // B's y goes from 0 to 1e-35 (a valid coordinate): near the start, t * 1e-35 is below 2^-120,
  // which a pose may not hold. The sweep takes 0 there, within its margin.
  const auto a = build_model(make_box(0.5, 0.5, 0.5, 1)), b = build_model(make_box(0.5, 0.5, 0.5, 1));
  const SweptPose still{Pose{}, Pose{}},
      coming{Pose::from_values(1.01, 0, 0, 1, 0, 0, 0), Pose::from_values(0, 1e-35, 0, 1, 0, 0, 0)};
  EXPECT_EQ(coming.at(0.01).translation.y(), 0.0);
  EXPECT_EQ(coming.at(0.5).translation.y(), 0.5e-35);
  const SweepResult r = sweep(*a, still, *b, coming);
  ASSERT_EQ(r.status, SweepStatus::contact);
  EXPECT_LE(r.time, 0.01 / 1.01) << "never later than the first true contact";
  EXPECT_GT(r.time, 0.0);
}

TEST(Sweep, UndecidedWhenTheQueriesRunOut) {
  // A grazing pass just outside a tiny tolerance, turning as it goes (about the axis across the
  // gap, so it never comes closer), takes many small advances: its turn, unlike a slide, can bring
  // any point closer, as far as the bound knows. With a budget of 3 queries the sweep stops
  // undecided, free of contact up to the time it reached.
  const auto a = build_model(make_box(0.5, 0.5, 0.5, 1));
  SweptPose pass{at(-3.0, 1.0 + 1e-5, 0.0), at(3.0, 1.0 + 1e-5, 0.0)};
  pass.end.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()));
  SweepRequest request;
  request.tolerance = 1e-6;
  request.max_queries = 3;
  const SweepResult s = sweep(*a, {Pose{}, Pose{}}, *a, pass, request);
  ASSERT_EQ(s.status, SweepStatus::undecided);
  EXPECT_EQ(s.queries, 3u);
  EXPECT_GT(s.time, 0.0);
  EXPECT_LT(s.time, 1.0);
}

/// The queries the sweep would take with the models' fastest point alone against their closest
/// distance (the bound before the local advance), counted by running that advance here, up to
/// 3,000.
std::uint64_t global_bound_queries(const Model& a, const SweptPose& ma, const Model& b, const SweptPose& mb, double tolerance) {
  const auto speed = [](const SweptPose& m, const Model& model) {
    const Eigen::Quaterniond d = m.start.rotation.conjugate() * m.end.rotation;
    const double turn = 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
    return (m.end.translation - m.start.translation).norm() + turn * model.extent();
  };
  const double mu = speed(ma, a) + speed(mb, b);
  std::uint64_t queries = 0;
  for (double t = 0.0; t < 1.0 && queries < 3000; ++queries) {  // (3,000 is enough to say "many")
    const double d = distance(a, ma.at(t), b, mb.at(t));
    if (d <= tolerance) break;
    t += (d - 1e-9 * (a.extent() + b.extent() + 4.0)) / mu;
  }
  return queries;
}

TEST(Sweep, PartsSlidingPastEachOtherTakeAFewQueries) {
  // Two plates sliding past each other face to face 1e-6 apart, a rod grazing a box, each free:
  // the local advance bounds each pair of triangles along the direction between them, across
  // which a slide brings nothing closer.
  const auto plate = build_model(make_plate(0.5, 0.02, 12));
  const auto rod = build_model(make_box(0.6, 0.01, 0.01, 2));
  const auto block = build_model(make_box(0.3, 0.3, 0.3, 3));
  struct Case {
    const char* name;
    const Model& a;
    const Model& b;
    SweptPose motion_b;
  };
  const Case cases[] = {
      {"plates", *plate, *plate, {at(-1.2, 0.3, 0.02 + 1e-6), at(1.2, -0.2, 0.02 + 1e-6)}},
      {"rod over a block", *block, *rod, {at(-1.5, 0.0, 0.31 + 1e-6), at(1.5, 0.2, 0.31 + 1e-6)}},
  };
  for (const Case& c : cases) {
    SweepRequest request;
    request.tolerance = 1e-7;
    const SweptPose still{Pose{}, Pose{}};
    const SweepResult s = sweep(c.a, still, c.b, c.motion_b, request);
    EXPECT_EQ(s.status, SweepStatus::free) << c.name;
    const std::uint64_t before = global_bound_queries(c.a, still, c.b, c.motion_b, request.tolerance);
    EXPECT_LE(s.queries * 10, before) << c.name << ": " << s.queries << " queries against " << before;
    EXPECT_EQ(before, 3000u) << c.name << ": many queries with the global bound alone";
    for (int k = 0; k <= 200; ++k) {
      EXPECT_GT(distance(c.a, still.at(k / 200.0), c.b, c.motion_b.at(k / 200.0)), request.tolerance) << c.name;
    }
  }
}

TEST(Sweep, RandomSlidesNeverMissASampledContact) {
  // Plates and boxes sliding near each other, tilted a little and turning a little: the local
  // advance takes long strides where it can; time sampled at 1/2000, every sampled contact comes
  // at or after t*, and the models are within the tolerance at t*.
  const auto plate = build_model(make_plate(0.5, 0.02, 6));
  const auto box = build_model(make_box(0.2, 0.1, 0.05, 2));
  std::mt19937_64 rng(58);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto tilt = [&](double degrees) {
    return Eigen::Quaterniond(
        Eigen::AngleAxisd(degrees * u(rng) * 3.14159265358979 / 180.0, Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
  };
  int contacts = 0, frees = 0;
  for (int m = 0; m < 120; ++m) {
    const Model& b = m % 2 == 0 ? *plate : *box;
    const double height = 0.01 + (m % 2 == 0 ? 0.01 : 0.05) + 0.02 * (u(rng) + 0.6);
    const SweptPose mb{at(-1.3, 0.5 * u(rng), height, tilt(2.0)), at(1.3, 0.5 * u(rng), height + 0.02 * u(rng), tilt(2.0))};
    const SweptPose still{Pose{}, Pose{}};
    SweepRequest request;
    request.tolerance = 1e-5;
    const SweepResult s = sweep(*plate, still, b, mb, request);
    ASSERT_NE(s.status, SweepStatus::undecided) << "motion " << m;
    for (int k = 0; k <= 2000; ++k) {
      const double t = k / 2000.0;
      if (!intersect(*plate, still.at(t), b, mb.at(t))) continue;
      ASSERT_EQ(s.status, SweepStatus::contact) << "motion " << m << ": a sampled contact at t = " << t << " was missed";
      ASSERT_LE(s.time, t) << "motion " << m << ": reported after a sampled contact";
      break;
    }
    if (s.status == SweepStatus::contact) {
      ++contacts;
      EXPECT_LE(distance(*plate, still.at(s.time), b, mb.at(s.time)), request.tolerance) << "motion " << m;
    } else {
      ++frees;
    }
  }
  EXPECT_GT(contacts, 15);
  EXPECT_GT(frees, 15);
}

}  // namespace
}  // namespace caliber
