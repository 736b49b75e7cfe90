// The swept query on many motions: Engine::sweep_many on 1 and 2 threads (or those --threads
// names) against a loop of caliber::sweep over the same motions, and one motion at a time through
// the engine (the heavy sweep alone, its queries split across threads by the engine's method).
// The motions are bench_fcl_ccd's, and a case of heavy queries: two plates of 2 x 24 x 24
// triangles coming together face to face (every distance query visits tens of thousands of node
// pairs at nearly equal distances). Interleaved rounds, medians of each round's total; every
// answer is checked against the loop's (status, time, closest pair), bit for bit.
//
//   bench_sweep_many [--meshes DIR] [--motions N] [--seed S] [--threads T ...] [--rounds R]
//                    [--method M] [--only NAME] [--out FILE.md]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "caliber/engine.h"
#include "caliber/sweep.h"
#include "machine.h"
#include "sweep_cases.h"

namespace {

using namespace caliber;

double ms_since(const std::chrono::steady_clock::time_point& start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

bool same(const SweepResult& x, const SweepResult& y) {
  return x.status == y.status && x.time == y.time && x.queries == y.queries && x.closest.tri_a == y.closest.tri_a &&
         x.closest.tri_b == y.closest.tri_b && x.closest.distance == y.closest.distance;
}

/// The options: the meshes' folder, the motions per case, the seed, the engines' thread counts, the
/// rounds, the engines' method, the cases to run (by name) and the report's file.
struct Options {
  std::filesystem::path dir = bench::default_meshes_dir();
  int motions = 100, rounds = 5;
  unsigned seed = 1;
  std::vector<int> thread_counts;
  Method method = kDefaultMethod;
  std::string out, only;
};

/// The options of the command line (1 and 2 threads by default), or none (the usage said on stderr) for one it does not know.
std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const auto value = [&] { return i + 1 < argc ? argv[++i] : nullptr; };
    const char* arg = argv[i];
    const char* v = nullptr;
    if (!std::strcmp(arg, "--threads")) {
      while (i + 1 < argc && argv[i + 1][0] != '-') o.thread_counts.push_back(std::max(1, std::atoi(argv[++i])));
      continue;
    }
    if (!std::strcmp(arg, "--meshes") && (v = value()))
      o.dir = v;
    else if (!std::strcmp(arg, "--motions") && (v = value()))
      o.motions = std::max(1, std::atoi(v));
    else if (!std::strcmp(arg, "--seed") && (v = value()))
      o.seed = static_cast<unsigned>(std::atoi(v));
    else if (!std::strcmp(arg, "--rounds") && (v = value()))
      o.rounds = std::max(1, std::atoi(v));
    else if (!std::strcmp(arg, "--method") && (v = value()))
      o.method = parse_method(v);
    else if (!std::strcmp(arg, "--only") && (v = value()))
      o.only = v;
    else if (!std::strcmp(arg, "--out") && (v = value()))
      o.out = v;
    else {
      std::fprintf(stderr,
                   "usage: bench_sweep_many [--meshes DIR] [--motions N] [--seed S] [--threads T ...] [--rounds R] "
                   "[--method M] [--only NAME] [--out FILE.md]\n");
      return std::nullopt;
    }
  }
  if (o.thread_counts.empty()) o.thread_counts = {1, 2};
  return o;
}

/// Writes the table's head to `table`: its column names and the rule under them.
void table_head(std::ostream& table, const std::vector<int>& thread_counts) {
  table << "| case | motions | contacts | queries | loop of sweep ms |";
  for (const int t : thread_counts) table << " sweep_many " << t << "t ms |";
  for (const int t : thread_counts) table << " one at a time " << t << "t ms |";
  table << "\n|---|---|---|---|---|";
  for (std::size_t k = 0; k < 2 * thread_counts.size(); ++k) table << "---|";
  table << "\n";
}

/// B's motions in a case: bench_fcl_ccd's, or for the plates face to face, the one plate going down through the other.
std::vector<SweptPose> motions_of(const bench::SweepCase& c, bool face_to_face, const Options& o) {
  bench::SweepMotions next(c, o.seed);
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<SweptPose> moving;
  for (int m = 0; m < o.motions; ++m) {
    if (!face_to_face) {
      moving.push_back(next.next());
      continue;
    }
    // Down from 0.3 to 0.1 through the other plate, sliding and turning a little.
    SweptPose s;
    s.start.translation = Eigen::Vector3d(0.05 * u(rng), 0.05 * u(rng), 0.3);
    s.end.translation = Eigen::Vector3d(0.05 * u(rng), 0.05 * u(rng), -0.1);
    s.end.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * u(rng), Eigen::Vector3d::UnitZ()));
    moving.push_back(s);
  }
  return moving;
}

/// Each round's total in milliseconds: the loop of caliber::sweep's, and per engine, sweep_many's on
/// all the motions at once and on one motion at a time.
struct Times {
  std::vector<double> loop_ms;
  std::vector<std::vector<double>> many_ms, single_ms;
};

/// The interleaved rounds on one case (A still): the loop's answers into `want`; the count of the engines' answers that differ.
int time_rounds(const Model& a, const Model& b, const std::vector<SweptPose>& moving,
                const std::vector<std::unique_ptr<Engine>>& engines, int rounds, Times& times, std::vector<SweepResult>& want) {
  int mismatches = 0;
  const SweptPose still{Pose{}, Pose{}};
  for (int r = 0; r < rounds; ++r) {
    auto start = std::chrono::steady_clock::now();
    for (std::size_t m = 0; m < moving.size(); ++m) want[m] = sweep(a, still, b, moving[m]);
    times.loop_ms.push_back(ms_since(start));
    for (std::size_t k = 0; k < engines.size(); ++k) {
      start = std::chrono::steady_clock::now();
      const std::vector<SweepResult> got = engines[k]->sweep_many(a, {&still, 1}, b, moving);
      times.many_ms[k].push_back(ms_since(start));
      for (std::size_t m = 0; m < moving.size(); ++m) mismatches += same(got[m], want[m]) ? 0 : 1;
      double total = 0.0;
      for (std::size_t m = 0; m < moving.size(); ++m) {
        start = std::chrono::steady_clock::now();
        const std::vector<SweepResult> one = engines[k]->sweep_many(a, {&still, 1}, b, {&moving[m], 1});
        total += ms_since(start);
        mismatches += same(one[0], want[m]) ? 0 : 1;
      }
      times.single_ms[k].push_back(total);
    }
  }
  return mismatches;
}

/// One case: every contender over the rounds on its motions, its row added to `table`; the count of answers unlike the loop's.
int run_case(const bench::SweepCase& c, bool face_to_face, const Options& o, std::ostream& table) {
  const auto a = build_model(c.a);
  const auto b = face_to_face ? a : build_model(c.b);
  const std::vector<SweptPose> moving = motions_of(c, face_to_face, o);
  std::vector<std::unique_ptr<Engine>> engines;
  for (const int t : o.thread_counts) {
    EngineOptions options;
    options.method = o.method;
    options.threads = t;
    engines.push_back(std::make_unique<Engine>(options));
  }
  Times times;
  times.many_ms.resize(o.thread_counts.size());
  times.single_ms.resize(o.thread_counts.size());
  std::vector<SweepResult> want(moving.size());
  const int mismatches = time_rounds(*a, *b, moving, engines, o.rounds, times, want);
  std::uint64_t queries = 0;
  int contacts = 0;
  for (const SweepResult& s : want) {
    queries += s.queries;
    contacts += s.status == SweepStatus::contact ? 1 : 0;
  }
  table << "| " << c.name << " (" << a->triangle_count() << " x " << b->triangle_count() << ") | " << o.motions << " | "
        << contacts << " | " << queries << " | " << median(times.loop_ms) << " |";
  for (const auto& ms : times.many_ms) table << " " << median(ms) << " |";
  for (const auto& ms : times.single_ms) table << " " << median(ms) << " |";
  table << "\n";
  std::fprintf(stderr, "%s done\n", c.name.c_str());
  return mismatches;
}

/// The report: the machine, the command line, what is measured and the mismatches, then the table.
std::string report_of(const Options& o, int mismatches, const std::string& table) {
  std::ostringstream report;
  report << "Machine: " << bench::machine_description() << ". `bench_sweep_many --motions " << o.motions << " --seed " << o.seed
         << " --rounds " << o.rounds << " --method " << to_string(o.method) << " --threads";
  for (const int t : o.thread_counts) report << " " << t;
  report << (o.only.empty() ? "" : " --only '" + o.only + "'")
         << "`: bench_fcl_ccd's motions (A still, B through or past A), default tolerance. Medians over interleaved rounds "
            "of each round's total: a loop of caliber::sweep on one thread; Engine::sweep_many on all the motions at "
            "once; Engine::sweep_many on one motion at a time (a heavy sweep's queries split by the method). Answers "
            "differing from the loop's: "
         << mismatches << ".\n\n"
         << table;
  return report.str();
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> o = parse(argc, argv);
  if (!o) return 2;
  std::ostringstream table;
  table_head(table, o->thread_counts);
  int mismatches = 0;
  std::vector<bench::SweepCase> cases = bench::sweep_cases(o->dir, o->only);
  const std::string plates = "plate x plate, face to face";
  if (o->only.empty() || plates.find(o->only) != std::string::npos) cases.push_back({plates, make_plate(1.0, 0.01, 24), {}});
  for (const bench::SweepCase& c : cases) mismatches += run_case(c, c.name == plates, *o, table);
  const std::string report = report_of(*o, mismatches, table.str());
  std::printf("%s", report.c_str());
  if (!o->out.empty()) std::ofstream(o->out) << report;
  return mismatches == 0 ? 0 : 1;
}
