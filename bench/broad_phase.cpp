// The broad phase against Bullet's dynamic AABB tree and a plain sweep along x: N boxes (half-size
// 0.45) on a jittered cubic grid of spacing 0.9, each drifting, S steps. Per step, after a first
// step that builds each structure (not timed): caliber's broad phase on an engine of 1 and 2 threads
// (or those --threads names; Engine::find_pairs, its tree kept from step to step), the same search made afresh each step
// (caliber::broad_phase), a sweep and prune along x over the same boxes, and Bullet 3's
// btDbvtBroadphase fed the same boxes (setAabb on every proxy, then calculateOverlappingPairs; the
// boxes are computed outside its timing). Milliseconds per step, medians of interleaved rounds.
// caliber's pairs are checked against the sweep's every step; Bullet's pair cache is counted apart:
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
#include <random>
#include <set>
#include <string>
#include <vector>

#include <btBulletCollisionCommon.h>

#include "support/sweep_and_prune.h"
#include "broad/world_box.h"
#include "caliber/broad_phase.h"
#include "caliber/engine.h"
#include "caliber/procedural.h"
#include "machine.h"

namespace {

using namespace caliber;
using broad::WorldBox;
using test::sweep_along_x;
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

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::size_t> sizes = {1000, 4096, 32768, 100000};
  std::vector<int> thread_counts = {1, 2};
  int steps = 20, repeat = 5;
  std::string out_path;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool more = i + 1 < argc;
    if (arg == "--objects" && more) {
      sizes.clear();
      while (i + 1 < argc && argv[i + 1][0] != '-') sizes.push_back(std::stoul(argv[++i]));
    } else if (arg == "--threads" && more) {
      thread_counts.clear();
      while (i + 1 < argc && argv[i + 1][0] != '-') thread_counts.push_back(std::max(1, std::stoi(argv[++i])));
    } else if (arg == "--steps" && more) {
      steps = std::max(2, std::stoi(argv[++i]));
    } else if (arg == "--repeat" && more) {
      repeat = std::max(1, std::stoi(argv[++i]));
    } else if (arg == "--out" && more) {
      out_path = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_broad_phase [--objects N ...] [--threads T ...] [--steps S] [--repeat R] [--out FILE.md]\n");
      return 2;
    }
  }
  if (thread_counts.empty()) thread_counts = {1};
  std::string table = "| objects | pairs/step |", rule = "|---|---|";
  for (const int threads : thread_counts) {
    table += " caliber " + std::to_string(threads) + (threads == 1 ? " thread ms |" : " threads ms |");
    rule += "---|";
  }
  table += " afresh ms | sweep along x ms | Bullet dbvt ms | caliber " + std::to_string(thread_counts[0]) +
           "t / Bullet | Bullet's pairs (overlapping) |\n" + rule + "---|---|---|---|---|\n";
  for (const std::size_t n : sizes) {
    const Boxes scene = make_boxes(n);
    std::vector<std::vector<Pose>> poses;
    std::vector<std::vector<WorldBox>> boxes;
    std::vector<std::vector<ObjectPair>> want;
    for (int k = 0; k < steps; ++k) {
      poses.push_back(scene.at(k));
      boxes.push_back(boxes_of(scene, poses.back()));
      want.push_back(sweep_along_x(boxes.back()));
    }
    std::map<std::string, std::vector<double>> ms;
    double bullet_pairs = 0.0, bullet_exact = 0.0;
    bool bullet_holds_all = true;
    for (int round = 0; round < repeat; ++round) {
      for (const int threads : thread_counts) {
        EngineOptions options;
        options.threads = threads;
        Engine engine(options);
        Frame frame;
        frame.models = scene.models;
        frame.poses = poses[0];
        engine.find_pairs(frame);
        const auto t = Clock::now();
        for (int k = 1; k < steps; ++k) {
          frame.poses = poses[k];
          engine.find_pairs(frame);
          if (frame.pairs != want[k]) {
            std::fprintf(stderr, "caliber's pairs differ from the sweep's at %zu objects, step %d\n", n, k);
            return 1;
          }
        }
        ms["t" + std::to_string(threads)].push_back(ms_since(t) / (steps - 1));
      }
      {
        const auto t = Clock::now();
        for (int k = 1; k < steps; ++k) {
          if (broad_phase(scene.models, poses[k], 0.0).size() != want[k].size()) return 1;
        }
        ms["fresh"].push_back(ms_since(t) / (steps - 1));
      }
      {
        const auto t = Clock::now();
        for (int k = 1; k < steps; ++k) {
          if (sweep_along_x(boxes_of(scene, poses[k])).size() != want[k].size()) return 1;
        }
        ms["sweep"].push_back(ms_since(t) / (steps - 1));
      }
      {
        Bullet bullet(boxes[0]);
        double total = 0.0;
        for (int k = 1; k < steps; ++k) {
          const auto t = Clock::now();
          bullet.update(boxes[k]);
          total += ms_since(t);
          if (round == 0) {
            const std::vector<ObjectPair> got = bullet.pairs();
            std::size_t exact = 0;
            for (const ObjectPair& p : got) exact += std::binary_search(want[k].begin(), want[k].end(), p) ? 1 : 0;
            bullet_pairs += static_cast<double>(got.size()) / (steps - 1);
            bullet_exact += static_cast<double>(exact) / (steps - 1);
            bullet_holds_all = bullet_holds_all && exact == want[k].size();
          }
        }
        ms["bullet"].push_back(total / (steps - 1));
      }
    }
    double pairs = 0.0;
    for (int k = 1; k < steps; ++k) pairs += static_cast<double>(want[k].size()) / (steps - 1);
    char cell[512];
    std::snprintf(cell, sizeof cell, "| %zu | %.0f |", n, pairs);
    std::string row = cell;
    for (const int threads : thread_counts) {
      std::snprintf(cell, sizeof cell, " %.2f |", median(ms["t" + std::to_string(threads)]));
      row += cell;
    }
    const double first = median(ms["t" + std::to_string(thread_counts[0])]);
    std::snprintf(cell, sizeof cell, " %.2f | %.2f | %.2f | %.2f | %.0f (%.0f)%s |\n", median(ms["fresh"]), median(ms["sweep"]),
                  median(ms["bullet"]), first / median(ms["bullet"]), bullet_pairs, bullet_exact,
                  bullet_holds_all ? "" : " MISSES PAIRS");
    row += cell;
    table += row;
    std::fputs(row.c_str(), stdout);
    std::fflush(stdout);
  }
  const std::string head =
      "Machine: " + bench::machine_description() + ". " + std::to_string(steps) +
      " steps, milliseconds per step after the first (which builds each structure), medians of " + std::to_string(repeat) +
      " interleaved rounds. Boxes of half-size 0.45 on a jittered cubic grid of spacing 0.9, drifting; caliber's "
      "pairs equal the sweep's at every step (checked); Bullet is given the same boxes (their computation not timed).\n\n";
  if (!out_path.empty()) std::ofstream(out_path) << head << table;
  std::printf("\n%s", head.c_str());
  return 0;
}
