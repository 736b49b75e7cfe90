// What the headers promise about sharing between threads, tested: a built Model may be queried by
// many threads at once, and a World may be stepped by many threads and Engines at once; every
// answer equals the one computed alone, to the bit.

#include <atomic>
#include <filesystem>
#include <string>
#include <random>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/engine.h"
#include "caliber/error.h"
#include "caliber/model.h"
#include "caliber/procedural.h"
#include "caliber/query.h"
#include "caliber/world.h"
#include "support/random_poses.h"
#include "support/temp_dir.h"
#include "support/reference_step.h"

namespace caliber {
namespace {

TEST(Concurrency, ManyThreadsQueryTheSameModels) {
  const auto sphere_model = build_model(make_sphere(0.6, 14, 20));
  const auto torus_model = build_model(make_torus(0.8, 0.25, 24, 14));
  const Model& sphere = *sphere_model;
  const Model& torus = *torus_model;
  std::mt19937_64 rng(2026);
  std::vector<Pose> poses;
  for (int i = 0; i < 40; ++i) poses.push_back(test::random_pose(rng, 0.8));
  const QueryKind kinds[] = {QueryKind::interference, QueryKind::proximity, QueryKind::contact};
  std::vector<QueryResult> reference;
  for (const Pose& p : poses) {
    for (const QueryKind kind : kinds) {
      reference.push_back(query(torus, Pose{}, sphere, p, QueryRequest{kind, 0.05, 35.0}));
    }
  }
  std::size_t nonempty = 0;
  for (const QueryResult& r : reference) nonempty += r.contacts.empty() ? 0 : 1;
  ASSERT_GT(nonempty, reference.size() / 4) << "too few touching poses to test anything";

  constexpr int kThreads = 8;
  std::vector<std::vector<QueryResult>> got(kThreads, std::vector<QueryResult>(reference.size()));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      // Each thread walks the queries in its own order, so different queries overlap in time.
      for (std::size_t j = 0; j < reference.size(); ++j) {
        const std::size_t q = (j * 7 + static_cast<std::size_t>(t) * 13) % reference.size();
        const Pose& p = poses[q / 3];
        got[t][q] = query(torus, Pose{}, sphere, p, QueryRequest{kinds[q % 3], 0.05, 35.0});
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) {
    for (std::size_t q = 0; q < reference.size(); ++q) {
      test::expect_identical(got[t][q], reference[q], "thread " + std::to_string(t) + " query " + std::to_string(q));
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
}

TEST(Concurrency, ManyEnginesStepTheSameWorldAtOnce) {
  test::TempDir temp{"concurrency"};
  save_off(make_sphere(0.6, 12, 16), temp.path() / "sphere.off");
  save_off(make_torus(0.8, 0.25, 20, 12), temp.path() / "torus.off");
  const World world(parse_scene(R"({"steps": 4, "dt": 0.1, "query": {"kind": "contact", "tolerance": 0.05, "angle": 30},
    "objects": [
      {"name": "ring", "mesh": "torus.off", "motion": {"type": "velocity", "angular": [0, 0.5, 0]}},
      {"name": "ball", "mesh": "sphere.off", "position": [0.9, 0, 0.3], "motion": {"type": "velocity", "linear": [-0.2, 0, -0.1]}},
      {"name": "ring2", "mesh": "torus.off", "position": [0.2, 0.6, 0], "orientation": [0.9, 0.3, 0.1, 0.2]}]})",
                                temp.path(), "concurrency.json"));
  const int steps = world.scene().steps;
  std::vector<StepResult> reference;
  for (int k = 0; k < steps; ++k) reference.push_back(test::reference_step(world, k));
  std::size_t contacts = 0;
  for (const StepResult& r : reference) contacts += r.contacts.size();
  ASSERT_GT(contacts, 0u);

  const Method methods[] = {Method::sequential,  Method::exploitation, Method::stealing,
                            Method::aposteriori, Method::apriori,      Method::hybrid};
  constexpr int kMethods = 6;
  std::vector<std::vector<StepResult>> got(kMethods + 1);
  std::vector<std::thread> threads;
  for (int m = 0; m < kMethods; ++m) {
    threads.emplace_back([&, m] {
      EngineOptions options;
      options.method = methods[m];
      options.threads = 2;
      options.stealing_depth = 2;
      Engine engine(options);  // each thread its own engine, all over one world
      for (int k = 0; k < steps; ++k) got[m].push_back(step(world, engine, k));
    });
  }
  threads.emplace_back([&] {  // and the pairwise reference from one more thread
    for (int k = 0; k < steps; ++k) got[kMethods].push_back(test::reference_step(world, k));
  });
  for (std::thread& th : threads) th.join();
  for (std::size_t m = 0; m < got.size(); ++m) {
    ASSERT_EQ(got[m].size(), reference.size());
    for (int k = 0; k < steps; ++k) {
      const auto& g = got[m][k].contacts;
      const auto& w = reference[k].contacts;
      ASSERT_EQ(g.size(), w.size()) << "engine " << m << " step " << k;
      for (std::size_t i = 0; i < w.size(); ++i) {
        ASSERT_EQ(g[i].object_a, w[i].object_a);
        ASSERT_EQ(g[i].object_b, w[i].object_b);
        ASSERT_EQ(g[i].tri_a, w[i].tri_a);
        ASSERT_EQ(g[i].tri_b, w[i].tri_b);
        ASSERT_EQ(g[i].distance, w[i].distance);
        ASSERT_EQ(g[i].point_a, w[i].point_a);
        ASSERT_EQ(g[i].point_b, w[i].point_b);
        ASSERT_EQ(g[i].normal, w[i].normal);
      }
    }
  }
}

TEST(Concurrency, ASecondCallOnABusyEngineIsAnErrorNotARace) {
  // A heavy step on one thread; meanwhile the main thread calls step and forget on the same engine
  // until the heavy step ends: every such call is refused with an Error, the heavy step's contacts
  // are those of an engine used alone, and the engine works afterwards.
  const auto fine = build_model(make_torus(1.0, 0.3, 160, 80));
  const auto ball = build_model(make_sphere(0.32, 60, 90));
  Frame heavy;
  heavy.models = {fine, ball};
  heavy.poses = {Pose{}, Pose::from_values(1.0, 0.0, 0.3, 1, 0, 0, 0)};
  heavy.pairs = {ObjectPair{0, 1}};
  heavy.request.kind = QueryKind::proximity;
  heavy.request.tolerance = 0.05;
  Frame light = heavy;
  light.poses[1] = Pose::from_values(9.0, 0.0, 0.0, 1, 0, 0, 0);  // far apart: a trivial step
  for (const Method method : {Method::sequential, Method::stealing, Method::hybrid}) {
    EngineOptions options;
    options.method = method;
    options.threads = 2;
    const StepResult alone = Engine(options).step(heavy);
    ASSERT_FALSE(alone.contacts.empty());
    Engine shared(options);
    std::atomic<bool> started{false}, done{false};
    StepResult got;
    std::thread worker([&] {
      started = true;
      for (;;) {  // the main thread may hold the engine at first: then this call is the refused one
        try {
          got = shared.step(heavy);
          break;
        } catch (const Error&) {
          std::this_thread::yield();
        }
      }
      done = true;
    });
    while (!started) std::this_thread::yield();
    int refused = 0, ran = 0;
    while (!done) {
      try {
        (void)shared.step(light);
        ++ran;  // between the worker's start and its step's, or after it
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("engine: step called while another call on the same engine is running"),
                  std::string::npos)
            << e.what();
        ++refused;
      }
      try {
        shared.forget();
      } catch (const Error&) {
        ++refused;
      }
    }
    worker.join();
    ASSERT_EQ(got.contacts.size(), alone.contacts.size()) << to_string(method);
    for (std::size_t i = 0; i < got.contacts.size(); ++i) {
      ASSERT_EQ(got.contacts[i].tri_a, alone.contacts[i].tri_a);
      ASSERT_EQ(got.contacts[i].tri_b, alone.contacts[i].tri_b);
      ASSERT_EQ(got.contacts[i].point_a, alone.contacts[i].point_a);
    }
    EXPECT_GT(refused, 0) << to_string(method) << ": the heavy step ran alone (" << ran << " light steps got in)";
    EXPECT_EQ(shared.step(heavy).contacts.size(), alone.contacts.size()) << "the engine works after refusing";
  }
}

}  // namespace
}  // namespace caliber
