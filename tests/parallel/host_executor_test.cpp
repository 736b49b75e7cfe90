// Executors on a host's threads (caliber/executor.h, parallel/borrowed_pool.h): every construct
// runs its work on the threads the host lends and on no other; a host that runs its ranges inline
// still gets the work done on the caller; errors reach the waiter; the engine's contacts are those
// of the default engine, for every method.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "caliber/engine.h"
#include "caliber/procedural.h"
#include "parallel/executor.h"
#include "support/pool_host.h"

namespace caliber {
namespace {

using test::PoolHost;

/// A host that runs every range itself, on the calling thread, before enqueue returns.
class InlineHost final : public HostExecutor {
 public:
  int thread_count() const override { return 3; }
  void* enqueue(const Job& job, std::size_t count, std::size_t grain) override {
    for (std::size_t b = 0; b < count; b += grain) job(b, std::min(count, b + grain), 0);
    return nullptr;
  }
  void finish(void*) override { ADD_FAILURE() << "finish() of a call that ran inline"; }
};

/// Sums i over [0, n) through nested job groups and parallel_for; records the threads that ran.
long long busy_sum(std::size_t n, std::mutex& m, std::set<std::thread::id>& seen, std::set<int>& indices) {
  std::atomic<long long> sum{0};
  parallel::JobGroup group;
  for (int part = 0; part < 4; ++part) {
    group.run([&, part] {
      parallel::parallel_for(part * n / 4, (part + 1) * n / 4, 64, [&](std::size_t lo, std::size_t hi) {
        long long s = 0;
        for (std::size_t i = lo; i < hi; ++i) s += static_cast<long long>(i);
        sum += s;
        const std::lock_guard<std::mutex> lock(m);
        seen.insert(std::this_thread::get_id());
        indices.insert(parallel::current_thread_index());
      });
    });
  }
  group.wait();
  return sum.load();
}

TEST(HostExecutor, WorkRunsOnTheHostsThreadsAndNoOthers) {
  PoolHost host(4);
  parallel::Executor executor(0, &host);
  EXPECT_EQ(executor.threads(), 4);
  std::mutex m;
  std::set<std::thread::id> seen;
  std::set<int> indices;
  long long sum = 0;
  const std::thread::id caller = std::this_thread::get_id();
  executor.execute([&] {
    EXPECT_EQ(parallel::concurrency(), 4);
    sum = busy_sum(100000, m, seen, indices);
  });
  EXPECT_EQ(sum, 100000LL * 99999 / 2);
  std::set<std::thread::id> allowed = host.workers();
  allowed.insert(caller);
  for (const std::thread::id& id : seen) EXPECT_TRUE(allowed.count(id)) << "a thread the host did not lend";
  for (const int i : indices) EXPECT_TRUE(i >= 0 && i < 4) << i;
  EXPECT_EQ(parallel::current_thread_index(), -1) << "outside execute()";
  parallel::Executor two(2, &host);
  EXPECT_EQ(two.threads(), 2) << "at most the threads asked for";
}

TEST(HostExecutor, RangesRunInlineLeaveTheWorkToTheCaller) {
  InlineHost host;
  parallel::Executor executor(0, &host);
  std::mutex m;
  std::set<std::thread::id> seen;
  std::set<int> indices;
  long long sum = 0;
  executor.execute([&] { sum = busy_sum(10000, m, seen, indices); });
  EXPECT_EQ(sum, 10000LL * 9999 / 2);
  EXPECT_EQ(seen, std::set<std::thread::id>{std::this_thread::get_id()});
}

TEST(HostExecutor, ExceptionsReachTheWaiter) {
  PoolHost host(3);
  parallel::Executor executor(0, &host);
  EXPECT_THROW(executor.execute([] {
    parallel::JobGroup group;
    for (int i = 0; i < 16; ++i)
      group.run([i] {
        if (i == 11) throw std::runtime_error("job 11");
      });
    group.wait();
  }),
               std::runtime_error);
  EXPECT_THROW(executor.execute([] { throw std::logic_error("the caller's own"); }), std::logic_error);
  int after = 0;
  executor.execute([&] { after = parallel::concurrency(); });
  EXPECT_EQ(after, 3) << "the executor still works after an error";
}

/// A host with no thread of its own whose finish() runs whatever range is queued, another call's
/// too (as the example's pool does when its threads are busy).
class HelpAnyHost final : public HostExecutor {
 public:
  int thread_count() const override { return 3; }
  void* enqueue(const Job& job, std::size_t count, std::size_t grain) override {
    auto* call = new Call{&job, 0};
    const std::lock_guard<std::mutex> lock(mMutex);
    for (std::size_t b = 0; b < count; b += grain, ++call->left) mQueue.push_back({call, b, std::min(count, b + grain)});
    return call;
  }
  void finish(void* handle) override {
    auto* call = static_cast<Call*>(handle);
    std::unique_lock<std::mutex> lock(mMutex);
    while (call->left > 0) {
      if (mQueue.empty()) {
        lock.unlock();
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        lock.lock();
        continue;
      }
      const Range r = mQueue.front();
      mQueue.pop_front();
      lock.unlock();
      (*r.call->job)(r.begin, r.end, 0);
      lock.lock();
      --r.call->left;
    }
    delete call;
  }

 private:
  struct Call {
    const Job* job;
    std::size_t left;
  };
  struct Range {
    Call* call;
    std::size_t begin, end;
  };
  std::mutex mMutex;
  std::deque<Range> mQueue;
};

TEST(HostExecutor, TwoCallersNestingCallsOnOneHostFinish) {
  // Each caller's job nests another call; the second caller's finish() meets the first caller's
  // ranges. A thread that already works for one call must not join another, or the two calls
  // would wait on each other for ever.
  HelpAnyHost host;
  parallel::Executor e1(0, &host), e2(0, &host), e3(2, &host), e4(2, &host);  // nested calls of another size: pools of their own
  std::atomic<int> done{0};
  std::thread first([&] {
    e1.execute([&] {
      parallel::JobGroup group;
      group.run([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        e3.execute([&] { ++done; });
      });
      group.wait();
    });
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(30));  // once the first call's ranges wait
  e2.execute([&] {
    parallel::JobGroup group;
    group.run([&] { e4.execute([&] { ++done; }); });
    group.wait();
  });
  first.join();
  EXPECT_EQ(done.load(), 2);
}

TEST(HostExecutor, ParallelSortOnLentThreads) {
  PoolHost host(3);
  parallel::Executor executor(0, &host);
  std::vector<std::uint64_t> v(50000);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = (i * 2654435761u) % 100003u;
  std::vector<std::uint64_t> want = v;
  std::sort(want.begin(), want.end());
  executor.execute([&] { parallel::parallel_sort(v.begin(), v.end(), std::less<>()); });
  EXPECT_EQ(v, want);
}

TEST(HostExecutor, EngineGivesTheDefaultEnginesContactsForEveryMethod) {
  PoolHost host(3);
  BuildOptions build;
  build.host = &host;
  Frame frame;
  frame.models = {build_model(make_torus(1.0, 0.3, 48, 24), build), build_model(make_sphere(0.3, 16, 32), build)};
  frame.poses = {Pose{}, Pose::from_values(1.3, 0.0, 0.05, 0.98, 0.1, 0.1, 0.1)};
  frame.pairs = {ObjectPair{0, 1}};
  frame.request.kind = QueryKind::proximity;
  frame.request.tolerance = 0.02;
  const StepResult reference = Engine(EngineOptions{}).step(frame);
  ASSERT_FALSE(reference.contacts.empty());
  for (const Method method :
       {Method::sequential, Method::exploitation, Method::stealing, Method::aposteriori, Method::apriori, Method::hybrid}) {
    EngineOptions options;
    options.method = method;
    options.host = &host;
    Engine engine(options);
    for (int k = 0; k < 2; ++k) {  // the temporal methods' second step too
      const StepResult s = engine.step(frame);
      ASSERT_EQ(s.contacts.size(), reference.contacts.size()) << to_string(method);
      for (std::size_t i = 0; i < s.contacts.size(); ++i) {
        EXPECT_EQ(s.contacts[i].tri_a, reference.contacts[i].tri_a);
        EXPECT_EQ(s.contacts[i].tri_b, reference.contacts[i].tri_b);
        EXPECT_EQ(s.contacts[i].point_a, reference.contacts[i].point_a);
        EXPECT_EQ(s.contacts[i].distance, reference.contacts[i].distance);
      }
    }
  }
}

}  // namespace
}  // namespace caliber
