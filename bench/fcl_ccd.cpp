// Peer comparison of the swept query (continuous collision detection): caliber::sweep against FCL
// 0.7's continuousCollide with conservative advancement (CCDC_CONSERVATIVE_ADVANCEMENT) on
// BVHModel<OBBRSS>, with FCL's InterpMotion (CCDM_LINEAR: linear translation, constant angular
// velocity about the origin: the same motion as caliber's SweptPose), on the same random motions.
// Model A holds still at the identity; B flies past or through it from a random pose on one side
// to a random pose on the other. The truth is a sampling of each motion at 1,001 times with
// caliber's exact interference test: a library misses when it answers "no contact" for a motion
// with a sampled contact, and is late when its time of contact comes after the first sampled one.
// Times: medians and sums over the motions of interleaved runs (caliber, then FCL, per motion).
//
//   bench_fcl_ccd [--meshes DIR] [--motions N] [--seed S] [--out FILE.md] [--only NAME] [--no-fcl]
//
// --no-fcl runs caliber's sweeps and the sampled truth alone: a long check for misses.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fcl/math/motion/interp_motion.h>
#include <fcl/narrowphase/continuous_collision.h>

#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "caliber/sweep.h"
#include "fcl_support.h"
#include "sweep_cases.h"
#include "machine.h"

namespace {

using namespace caliber;

struct Tally {
  int motions = 0, sampled_contacts = 0, contacts = 0, misses = 0, late = 0;
  std::vector<double> ms;
  double total_ms = 0.0;
};

double ms_of(const std::chrono::steady_clock::time_point& start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The first of 1,001 evenly spaced times at which A (still) and B (moving) intersect, or -1.
double first_sampled_contact(const Model& a, const Model& b, const SweptPose& motion) {
  QueryRequest touch;
  touch.max_pairs = 1;
  for (int k = 0; k <= 1000; ++k) {
    if (!query(a, Pose{}, b, motion.at(k / 1000.0), touch).contacts.empty()) return k / 1000.0;
  }
  return -1.0;
}

void count(Tally& t, bool contact, double time, double sampled) {
  ++t.motions;
  t.contacts += contact ? 1 : 0;
  if (sampled < 0.0) return;
  ++t.sampled_contacts;
  if (!contact) ++t.misses;
  if (contact && time > sampled) ++t.late;
}

std::string row(const std::string& name, const std::string& who, const Tally& t) {
  std::ostringstream s;
  s << "| " << name << " | " << who << " | " << t.motions << " | " << t.sampled_contacts << " | " << t.contacts << " | "
    << t.misses << " | " << t.late << " | " << median(t.ms) << " | " << t.total_ms << " |\n";
  return s.str();
}

/// The options: the meshes' folder, the motions per case, the seed, the report's file, the cases to run and --no-fcl.
struct Options {
  std::filesystem::path dir = bench::default_meshes_dir();
  int motions = 100;
  unsigned seed = 1;
  std::string out, only;
  bool with_fcl = true;
};

/// The options of the command line, or none (the usage said on stderr) for one it does not know.
std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--meshes") && i + 1 < argc)
      o.dir = argv[++i];
    else if (!std::strcmp(argv[i], "--motions") && i + 1 < argc)
      o.motions = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc)
      o.seed = static_cast<unsigned>(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--out") && i + 1 < argc)
      o.out = argv[++i];
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc)
      o.only = argv[++i];
    else if (!std::strcmp(argv[i], "--no-fcl"))
      o.with_fcl = false;
    else {
      std::fprintf(stderr,
                   "usage: bench_fcl_ccd [--meshes DIR] [--motions N] [--seed S] [--out FILE.md] [--only NAME] [--no-fcl]\n");
      return std::nullopt;
    }
  }
  return o;
}

/// FCL's continuousCollide on one motion of B (A still), timed and counted into `theirs`.
void fcl_motion(const std::shared_ptr<bench::FclModel>& fa, const std::shared_ptr<bench::FclModel>& fb, const SweptPose& motion,
                double sampled, Tally& theirs) {
  fcl::ContinuousCollisionRequestd request;
  request.ccd_motion_type = fcl::CCDM_LINEAR;
  request.ccd_solver_type = fcl::CCDC_CONSERVATIVE_ADVANCEMENT;
  fcl::ContinuousCollisionResultd result;
  // The motions built with their reference point at the origin: FCL 0.7's InterpMotion(tf1, tf2),
  // which continuousCollide(geometry, tf_begin, tf_end, ...) builds, leaves that point
  // uninitialized (and missed every contact here).
  const fcl::Matrix3d identity = fcl::Matrix3d::Identity();
  const fcl::Vector3d origin = fcl::Vector3d::Zero();
  const auto start = std::chrono::steady_clock::now();
  const fcl::InterpMotion<double> still(identity, origin, identity, origin, origin);
  const fcl::InterpMotion<double> flight(motion.start.rotation_matrix(), motion.start.translation, motion.end.rotation_matrix(),
                                         motion.end.translation, origin);
  fcl::continuousCollide<double>(fa.get(), &still, fb.get(), &flight, request, result);
  const double fcl_ms = ms_of(start);
  theirs.ms.push_back(fcl_ms);
  theirs.total_ms += fcl_ms;
  count(theirs, result.is_collide, result.time_of_contact, sampled);
}

/// One case: each motion sampled, then swept by caliber, then (unless --no-fcl) by FCL; its rows added to `table`.
void run_case(const bench::SweepCase& c, const Options& o, std::string& table) {
  const auto a = build_model(c.a);
  const auto b = build_model(c.b);
  const auto fa = bench::build_fcl(c.a);
  const auto fb = bench::build_fcl(c.b);
  bench::SweepMotions next_motion(c, o.seed);
  Tally ours, theirs;
  for (int m = 0; m < o.motions; ++m) {
    const SweptPose motion = next_motion.next();
    const double sampled = first_sampled_contact(*a, *b, motion);

    const auto start = std::chrono::steady_clock::now();
    const SweepResult s = sweep(*a, SweptPose{Pose{}, Pose{}}, *b, motion);
    const double our_ms = ms_of(start);
    ours.ms.push_back(our_ms);
    ours.total_ms += our_ms;
    count(ours, s.status == SweepStatus::contact, s.time, sampled);

    if (!o.with_fcl) continue;
    fcl_motion(fa, fb, motion, sampled, theirs);
  }
  table += row(c.name + " (" + std::to_string(c.a.triangles.size()) + " x " + std::to_string(c.b.triangles.size()) + ")",
               "caliber", ours);
  if (o.with_fcl) table += row("", "FCL 0.7 (CA, OBBRSS)", theirs);
  std::fprintf(stderr, "%s done\n", c.name.c_str());
}

/// The report: the machine, the command line, what is measured, then the table.
std::string report_of(const Options& o, const std::string& table) {
  std::ostringstream report;
  report << "Machine: " << bench::machine_description() << ". `bench_fcl_ccd --motions " << o.motions << " --seed " << o.seed
         << (o.only.empty() ? "" : " --only '" + o.only + "'") << (o.with_fcl ? "" : " --no-fcl")
         << "`: A still, B flying through or past A between two random poses (turned up to 90 degrees), caliber::sweep "
            "(default tolerance) against FCL's continuousCollide (conservative advancement, InterpMotion about the origin, "
            "default toc_err); "
            "truth: 1,001 sampled times with the exact interference test. misses: no contact reported where one was "
            "sampled; late: a time of contact after the first sampled one.\n\n"
         << table;
  return report.str();
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> o = parse(argc, argv);
  if (!o) return 2;
  std::vector<bench::SweepCase> cases = bench::sweep_cases(o->dir, o->only);
  std::string table =
      "| case | library | motions | with a sampled contact | contact reported | misses | late | median ms | total ms |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  for (const bench::SweepCase& c : cases) run_case(c, *o, table);
  const std::string report = report_of(*o, table);
  std::printf("%s", report.c_str());
  if (!o->out.empty()) std::ofstream(o->out) << report;
  return 0;
}
