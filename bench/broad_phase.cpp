// The broad phase against Bullet's dynamic AABB tree and a plain sort along x: N boxes (half-size
// 0.45) on a jittered cubic grid of spacing 0.9, each drifting, S steps. Per step, after a first
// step that builds each structure (not timed): caliber's broad phase on an engine of 1 and 2 threads
// (or those --threads names; Engine::find_pairs, its tree kept from step to step), the same search made afresh each step
// (caliber::broad_phase), a sort and prune along x over the same boxes, and Bullet 3's
// btDbvtBroadphase fed the same boxes (setAabb on every proxy, then calculateOverlappingPairs; the
// boxes are computed outside its timing). Milliseconds per step, medians of interleaved rounds.
// caliber's pairs are checked against the x-sort's every step; Bullet's pair cache is counted apart:
// how many of its pairs overlap, and whether it holds every pair that does.
//
//   bench_broad_phase [--objects N ...] [--threads T ...] [--steps S] [--repeat R] [--out FILE.md]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <btBulletCollisionCommon.h>

#include "support/x_sort_pairs.h"
#include "broad/world_box.h"
#include "caliber/broad_phase.h"
#include "caliber/engine.h"
#include "caliber/procedural.h"
#include "machine.h"

namespace {

using namespace caliber;
using broad::WorldBox;
using test::pairs_by_x_sort;
using Clock = std::chrono::steady_clock;

struct Boxes {
  std::vector<std::shared_ptr<const Model>> models;
  std::vector<Pose> start;
  std::vector<Eigen::Vector3d> velocity;
  std::vector<Pose> at(int step) const {
    std::vector<Pose> poses = start;
    for (std::size_t i = 0; i < poses.size(); ++i) poses[i].translation += velocity[i] * (0.01 * step);
    return poses;
  }
};

Boxes make_boxes(std::size_t n) {
  Boxes s;
  const auto box = build_model(make_box(0.45, 0.45, 0.45, 1));
  const auto side = static_cast<std::size_t>(std::ceil(std::cbrt(static_cast<double>(n)) - 1e-9));
  std::mt19937_64 rng(n);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05), drift(-0.2, 0.2);
  for (std::size_t i = 0; i < n; ++i) {
    s.models.push_back(box);
    Pose p;
    p.translation = Eigen::Vector3d(0.9 * static_cast<double>(i % side) + jitter(rng),
                                    0.9 * static_cast<double>(i / side % side) + jitter(rng),
                                    0.9 * static_cast<double>(i / (side * side)) + jitter(rng));
    s.start.push_back(p);
    s.velocity.emplace_back(drift(rng), drift(rng), drift(rng));
  }
  return s;
}

std::vector<WorldBox> boxes_of(const Boxes& s, const std::vector<Pose>& poses) {
  std::vector<WorldBox> out;
  for (std::size_t i = 0; i < poses.size(); ++i) out.push_back(broad::world_box(*s.models[i], poses[i], 0.0));
  return out;
}

/// Bullet's dynamic AABB tree with its collision world's pair cache.
struct Bullet {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  std::vector<btBroadphaseProxy*> proxies;
  std::vector<std::unique_ptr<btCollisionObject>> objects;

  static btVector3 v(const Eigen::Vector3d& x) { return {btScalar(x.x()), btScalar(x.y()), btScalar(x.z())}; }

  explicit Bullet(const std::vector<WorldBox>& boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      objects.push_back(std::make_unique<btCollisionObject>());
      objects.back()->setUserIndex(static_cast<int>(i));
      proxies.push_back(broadphase.createProxy(v(boxes[i].lo), v(boxes[i].hi), BOX_SHAPE_PROXYTYPE, objects.back().get(),
                                               btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter, &dispatcher));
    }
    broadphase.calculateOverlappingPairs(&dispatcher);
  }
  void update(const std::vector<WorldBox>& boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i) broadphase.setAabb(proxies[i], v(boxes[i].lo), v(boxes[i].hi), &dispatcher);
    broadphase.calculateOverlappingPairs(&dispatcher);
  }
  std::vector<ObjectPair> pairs() {
    btOverlappingPairCache* cache = broadphase.getOverlappingPairCache();
    std::vector<ObjectPair> out;
    for (int i = 0; i < cache->getNumOverlappingPairs(); ++i) {
      const btBroadphasePair& p = cache->getOverlappingPairArray()[i];
      const auto a = static_cast<std::uint32_t>(static_cast<btCollisionObject*>(p.m_pProxy0->m_clientObject)->getUserIndex());
      const auto b = static_cast<std::uint32_t>(static_cast<btCollisionObject*>(p.m_pProxy1->m_clientObject)->getUserIndex());
      out.push_back({std::min(a, b), std::max(a, b)});
    }
    std::sort(out.begin(), out.end());
    return out;
  }
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

/// The options: the object counts, the engines' thread counts (at least one), the steps, the rounds
/// and the report's file.
struct Options {
  std::vector<std::size_t> sizes = {1000, 4096, 32768, 100000};
  std::vector<int> thread_counts = {1, 2};
  int steps = 20, repeat = 5;
  std::string out_path;
};

/// The options of the command line, or none (the usage said on stderr) for one it does not know.
std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool more = i + 1 < argc;
    if (arg == "--objects" && more) {
      o.sizes.clear();
      while (i + 1 < argc && argv[i + 1][0] != '-') o.sizes.push_back(std::stoul(argv[++i]));
    } else if (arg == "--threads" && more) {
      o.thread_counts.clear();
      while (i + 1 < argc && argv[i + 1][0] != '-') o.thread_counts.push_back(std::max(1, std::stoi(argv[++i])));
    } else if (arg == "--steps" && more) {
      o.steps = std::max(2, std::stoi(argv[++i]));
    } else if (arg == "--repeat" && more) {
      o.repeat = std::max(1, std::stoi(argv[++i]));
    } else if (arg == "--out" && more) {
      o.out_path = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_broad_phase [--objects N ...] [--threads T ...] [--steps S] [--repeat R] [--out FILE.md]\n");
      return std::nullopt;
    }
  }
  if (o.thread_counts.empty()) o.thread_counts = {1};
  return o;
}

/// The table's head: its column names and the rule under them.
std::string table_head(const std::vector<int>& thread_counts) {
  std::string table = "| objects | pairs/step |", rule = "|---|---|";
  for (const int threads : thread_counts) {
    table += " caliber " + std::to_string(threads) + (threads == 1 ? " thread ms |" : " threads ms |");
    rule += "---|";
  }
  table += " afresh ms | x-sort ms | Bullet dbvt ms | caliber " + std::to_string(thread_counts[0]) +
           "t / Bullet | Bullet's pairs (overlapping) |\n" + rule + "---|---|---|---|---|\n";
  return table;
}

/// Every step of a scene: the poses, their world boxes, and the pairs the sort along x finds.
struct Steps {
  std::vector<std::vector<Pose>> poses;
  std::vector<std::vector<WorldBox>> boxes;
  std::vector<std::vector<ObjectPair>> want;
};

/// The first `steps` steps of `scene`, each with its boxes and the x-sort's pairs.
Steps steps_of(const Boxes& scene, int steps) {
  Steps s;
  for (int k = 0; k < steps; ++k) {
    s.poses.push_back(scene.at(k));
    s.boxes.push_back(boxes_of(scene, s.poses.back()));
    s.want.push_back(pairs_by_x_sort(s.boxes.back()));
  }
  return s;
}

/// What the rounds measured on one scene: milliseconds per step by contender ("t1", "t2", ...,
/// "fresh", "x_sort", "bullet"), and Bullet's pair cache over the first round's steps.
struct Measured {
  std::map<std::string, std::vector<double>> ms;
  double bullet_pairs = 0.0, bullet_exact = 0.0;
  bool bullet_holds_all = true;
};

/// caliber's engine on `threads` threads, built at step 0 (not timed): ms per step into `m`; false (on stderr) if pairs differ.
bool time_engine(const Boxes& scene, const Steps& s, int steps, int threads, Measured& m) {
  EngineOptions options;
  options.threads = threads;
  Engine engine(options);
  Frame frame;
  frame.models = scene.models;
  frame.poses = s.poses[0];
  engine.find_pairs(frame);
  const auto t = Clock::now();
  for (int k = 1; k < steps; ++k) {
    frame.poses = s.poses[k];
    engine.find_pairs(frame);
    if (frame.pairs != s.want[k]) {
      std::fprintf(stderr, "caliber's pairs differ from the x-sort's at %zu objects, step %d\n", scene.models.size(), k);
      return false;
    }
  }
  m.ms["t" + std::to_string(threads)].push_back(ms_since(t) / (steps - 1));
  return true;
}

/// Bullet's tree, built at step 0 (not timed), fed each step's boxes: ms per step into `m`; in round 0, what its pairs hold.
void time_bullet(const Steps& s, int steps, int round, Measured& m) {
  Bullet bullet(s.boxes[0]);
  double total = 0.0;
  for (int k = 1; k < steps; ++k) {
    const auto t = Clock::now();
    bullet.update(s.boxes[k]);
    total += ms_since(t);
    if (round == 0) {
      const std::vector<ObjectPair> got = bullet.pairs();
      std::size_t exact = 0;
      for (const ObjectPair& p : got) exact += std::binary_search(s.want[k].begin(), s.want[k].end(), p) ? 1 : 0;
      m.bullet_pairs += static_cast<double>(got.size()) / (steps - 1);
      m.bullet_exact += static_cast<double>(exact) / (steps - 1);
      m.bullet_holds_all = m.bullet_holds_all && exact == s.want[k].size();
    }
  }
  m.ms["bullet"].push_back(total / (steps - 1));
}

/// The interleaved rounds: caliber per thread count, the search afresh, the x-sort, then Bullet. False if any pairs differ.
bool time_rounds(const Boxes& scene, const Steps& s, const Options& o, Measured& m) {
  const int steps = o.steps;
  for (int round = 0; round < o.repeat; ++round) {
    for (const int threads : o.thread_counts) {
      if (!time_engine(scene, s, steps, threads, m)) return false;
    }
    {
      const auto t = Clock::now();
      for (int k = 1; k < steps; ++k) {
        if (broad_phase(scene.models, s.poses[k], 0.0).size() != s.want[k].size()) return false;
      }
      m.ms["fresh"].push_back(ms_since(t) / (steps - 1));
    }
    {
      const auto t = Clock::now();
      for (int k = 1; k < steps; ++k) {
        if (pairs_by_x_sort(boxes_of(scene, s.poses[k])).size() != s.want[k].size()) return false;
      }
      m.ms["x_sort"].push_back(ms_since(t) / (steps - 1));
    }
    time_bullet(s, steps, round, m);
  }
  return true;
}

/// A row of the table: the objects, the pairs per step, each contender's median and Bullet's pairs.
std::string table_row(std::size_t n, const Steps& s, const Options& o, const Measured& m) {
  const int steps = o.steps;
  double pairs = 0.0;
  for (int k = 1; k < steps; ++k) pairs += static_cast<double>(s.want[k].size()) / (steps - 1);
  char cell[512];
  std::snprintf(cell, sizeof cell, "| %zu | %.0f |", n, pairs);
  std::string row = cell;
  for (const int threads : o.thread_counts) {
    std::snprintf(cell, sizeof cell, " %.2f |", median(m.ms.at("t" + std::to_string(threads))));
    row += cell;
  }
  const double first = median(m.ms.at("t" + std::to_string(o.thread_counts[0])));
  std::snprintf(cell, sizeof cell, " %.2f | %.2f | %.2f | %.2f | %.0f (%.0f)%s |\n", median(m.ms.at("fresh")),
                median(m.ms.at("x_sort")), median(m.ms.at("bullet")), first / median(m.ms.at("bullet")), m.bullet_pairs,
                m.bullet_exact, m.bullet_holds_all ? "" : " MISSES PAIRS");
  row += cell;
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Options> o = parse(argc, argv);
  if (!o) return 2;
  std::string table = table_head(o->thread_counts);
  for (const std::size_t n : o->sizes) {
    const Boxes scene = make_boxes(n);
    const Steps s = steps_of(scene, o->steps);
    Measured m;
    if (!time_rounds(scene, s, *o, m)) return 1;
    const std::string row = table_row(n, s, *o, m);
    table += row;
    std::fputs(row.c_str(), stdout);
    std::fflush(stdout);
  }
  const std::string head =
      "Machine: " + bench::machine_description() + ". " + std::to_string(o->steps) +
      " steps, milliseconds per step after the first (which builds each structure), medians of " + std::to_string(o->repeat) +
      " interleaved rounds. Boxes of half-size 0.45 on a jittered cubic grid of spacing 0.9, drifting; caliber's "
      "pairs equal the x-sort's at every step (checked); Bullet is given the same boxes (their computation not timed).\n\n";
  if (!o->out_path.empty()) std::ofstream(o->out_path) << head << table;
  std::printf("\n%s", head.c_str());
  return 0;
}
