// The executor seam (src/parallel/executor.h), whichever backend this build has: every index once,
// nested job groups, exceptions reaching wait(), never more threads at once than asked for, and
// (oneTBB) never more than the process allows, in the host's arena, with no thread of its own.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <numeric>
#include <tuple>
#include <utility>
#include <stdexcept>
#include <thread>
#include <vector>
#include <filesystem>

#include <gtest/gtest.h>

#include "caliber/error.h"
#include "parallel/executor.h"

#ifndef CALIBER_EXECUTOR_STD
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#endif

namespace caliber::parallel {
namespace {

/// Counts how many threads are inside a region at once, and the most seen.
struct Occupancy {
  std::atomic<int> now{0}, peak{0};
  void enter() {
    const int n = ++now;
    int p = peak.load();
    while (n > p && !peak.compare_exchange_weak(p, n)) {}
  }
  void leave() { --now; }
};

TEST(Executor, ParallelForCoversEveryIndexOnce) {
  for (const int threads : {1, 2, 4}) {
    Executor executor(threads);
    for (const std::size_t grain : {std::size_t{1}, std::size_t{3}, std::size_t{64}, std::size_t{5000}}) {
      std::vector<std::atomic<int>> hits(1000);
      executor.execute([&] {
        parallel_for(0, hits.size(), grain, [&](std::size_t lo, std::size_t hi) {
          EXPECT_LT(lo, hi);
          EXPECT_LE(hi - lo, grain);
          for (std::size_t i = lo; i != hi; ++i) ++hits[i];
        });
      });
      for (std::size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i].load(), 1) << "index " << i << " grain " << grain;
    }
    std::vector<std::atomic<int>> each(777);
    executor.execute([&] { parallel_for_each(0, each.size(), [&](std::size_t i) { ++each[i]; }); });
    for (const auto& h : each) ASSERT_EQ(h.load(), 1);
    parallel_for(5, 5, 1, [](std::size_t, std::size_t) { FAIL() << "an empty range runs nothing"; });
  }
}

long fib(int n) {
  if (n < 2) return n;
  long a = 0, b = 0;
  JobGroup group;
  group.run([&] { a = fib(n - 1); });
  b = fib(n - 2);
  group.wait();
  return a + b;
}

TEST(Executor, NestedJobGroupsAndAtMostNThreads) {
  for (const int threads : {1, 2, 3, 8}) {
    Executor executor(threads);
#ifdef CALIBER_EXECUTOR_STD
    EXPECT_EQ(executor.threads(), threads);
#else
    EXPECT_LE(executor.threads(), threads) << "at most the process's limit";
    EXPECT_GE(executor.threads(), 1);
#endif
    long result = 0;
    executor.execute([&] { result = fib(18); });
    EXPECT_EQ(result, 2584);
    Occupancy occupancy;
    executor.execute([&] {
      parallel_for(0, 64, 1, [&](std::size_t, std::size_t) {
        occupancy.enter();
        volatile double x = 0;
        for (int i = 0; i < 20000; ++i) x = x + 1.0;
        occupancy.leave();
      });
    });
    EXPECT_LE(occupancy.peak.load(), threads);
    EXPECT_GE(occupancy.peak.load(), 1);
  }
  EXPECT_EQ(fib(12), 144) << "job groups work outside any executor too";
}

#ifdef CALIBER_EXECUTOR_STD
TEST(Executor, AllNThreadsRunEvenBeyondTheHardwareThreads) {
  // N jobs that each wait (up to 20 s) until all N are running: they can only all finish early if
  // N distinct threads run them at once, hardware threads or not (the std backend's pool has N).
  const int threads = static_cast<int>(std::max(2u, std::thread::hardware_concurrency())) + 2;
  Executor executor(threads);
  std::atomic<int> arrived{0};
  std::atomic<bool> all_met{true};
  std::vector<std::atomic<int>> seen(static_cast<std::size_t>(threads));
  executor.execute([&] {
    parallel_for(0, static_cast<std::size_t>(threads), 1, [&](std::size_t, std::size_t) {
      ++arrived;
      const int index = current_thread_index();
      if (index >= 0 && index < threads) ++seen[static_cast<std::size_t>(index)];
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
      while (arrived.load() < threads) {
        if (std::chrono::steady_clock::now() > deadline) {
          all_met = false;
          return;
        }
        std::this_thread::yield();
      }
    });
  });
  EXPECT_TRUE(all_met.load()) << "the " << threads << " jobs never ran on " << threads << " threads at once (waited 20 s)";
  for (int t = 0; t < threads; ++t) EXPECT_EQ(seen[static_cast<std::size_t>(t)].load(), 1) << "thread index " << t;
}
#else
/// Counts the threads of this process (Linux: /proc/self/task).
std::size_t os_threads() {
  std::size_t n = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) n += entry.is_directory() ? 1 : 0;
  return n;
}

TEST(Executor, NeverRaisesTheProcessLimitAndReportsWhatItHas) {
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  for (const int threads : {2, 4, 8}) {
    Executor executor(threads);
    EXPECT_EQ(executor.threads(), 2) << threads << " asked for, under a limit of 2";
    Occupancy occupancy;
    executor.execute([&] {
      EXPECT_EQ(concurrency(), 2);
      parallel_for(0, 64, 1, [&](std::size_t, std::size_t) {
        occupancy.enter();
        EXPECT_GE(current_thread_index(), 0);
        EXPECT_LT(current_thread_index(), 2);
        volatile double x = 0;
        for (int i = 0; i < 20000; ++i) x = x + 1.0;
        occupancy.leave();
      });
    });
    EXPECT_LE(occupancy.peak.load(), 2);
    EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), 2u) << "the host's limit stands";
  }
}

TEST(Executor, ZeroRunsInTheArenaItIsCalledFrom) {
  tbb::task_arena host(2);
  host.execute([] { tbb::parallel_for(0, 1000, [](int) {}); });  // the host's worker exists
  const std::size_t before = os_threads();
  Executor executor(0);
  host.execute([&] {
    EXPECT_EQ(executor.threads(),
              std::min(2, static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism))));
    executor.execute([&] {
      std::atomic<int> outside{0};
      parallel_for(0, 256, 1, [&](std::size_t, std::size_t) {
        if (tbb::this_task_arena::max_concurrency() != 2) ++outside;  // a job run in another arena
      });
      EXPECT_EQ(outside.load(), 0);
      EXPECT_EQ(fib(16), 987);
    });
  });
  EXPECT_EQ(os_threads(), before) << "caliber ran on the host's arena and started no thread";
}

TEST(Executor, OneThreadAndNoExecutorRunOnTheCallingThread) {
  const auto caller = std::this_thread::get_id();
  std::atomic<int> elsewhere{0};
  const auto work = [&] {
    parallel_for(0, 100, 1, [&](std::size_t, std::size_t) { elsewhere += std::this_thread::get_id() != caller; });
    parallel_for_each(0, 100, [&](std::size_t) { elsewhere += std::this_thread::get_id() != caller; });
    JobGroup group;
    for (int i = 0; i < 10; ++i) group.run([&] { elsewhere += std::this_thread::get_id() != caller; });
    group.wait();
    for_each_in_order(10, [&](std::size_t) { elsewhere += std::this_thread::get_id() != caller; });
  };
  work();
  EXPECT_EQ(concurrency(), 1);
  EXPECT_EQ(current_thread_index(), -1);
  Executor(1).execute(work);
  EXPECT_EQ(elsewhere.load(), 0);
}
#endif

TEST(Executor, ExceptionsReachTheWaiter) {
  Executor executor(3);
  EXPECT_THROW(executor.execute([] {
    JobGroup group;
    for (int i = 0; i < 20; ++i)
      group.run([i] {
        if (i == 7) throw std::runtime_error("job 7");
      });
    group.wait();
  }),
               std::runtime_error);
  EXPECT_THROW(executor.execute([] {
    parallel_for(0, 100, 1, [](std::size_t lo, std::size_t) {
      if (lo == 42) throw std::runtime_error("chunk 42");
    });
  }),
               std::runtime_error);
  // The executor is still usable afterwards.
  std::atomic<int> sum{0};
  executor.execute([&] { parallel_for_each(0, 100, [&](std::size_t i) { sum += static_cast<int>(i); }); });
  EXPECT_EQ(sum.load(), 4950);
  EXPECT_THROW(Executor(-1), Error);
}

TEST(Executor, ForEachInOrderRunsEveryItemOnceAndRethrows) {
  for (const int threads : {1, 2, 3, 8}) {
    Executor executor(threads);
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{500}}) {
      std::vector<std::atomic<int>> hits(n);
      Occupancy occupancy;
      executor.execute([&] {
        for_each_in_order(n, [&](std::size_t i) {
          occupancy.enter();
          ++hits[i];
          occupancy.leave();
        });
      });
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << "item " << i << ", " << threads << " threads";
      EXPECT_LE(occupancy.peak.load(), threads);
    }
    int inside = 0;
    executor.execute([&] { inside = concurrency(); });
    EXPECT_EQ(inside, executor.threads());
    EXPECT_THROW(executor.execute([] {
      for_each_in_order(100, [](std::size_t i) {
        if (i == 42) throw std::runtime_error("item 42");
      });
    }),
                 std::runtime_error);
  }
  std::vector<std::size_t> order;  // on one thread: in order
  Executor(1).execute([&] { for_each_in_order(5, [&](std::size_t i) { order.push_back(i); }); });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
}

// The list schedule, not blocks: while one thread holds item 0, the other takes 1, 2, 3, 4, 5 in
// that order (recursive halving would give it 3, 4, 5 first, then steal 1 and 2).
TEST(Executor, ForEachInOrderHandsItemsToTheNextFreeThreadInOrder) {
  Executor executor(2);
  constexpr std::size_t n = 6;
  std::atomic<std::size_t> done{0};
  std::vector<std::size_t> started;  // items 1.. run on one thread while item 0 waits
  bool waited_out = true;
  executor.execute([&] {
    for_each_in_order(n, [&](std::size_t i) {
      if (i == 0) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
        while (done.load() < n - 1) {
          if (std::chrono::steady_clock::now() > deadline) {
            waited_out = false;
            return;
          }
          std::this_thread::yield();
        }
        return;
      }
      started.push_back(i);
      ++done;
    });
  });
  ASSERT_TRUE(waited_out) << "items 1..5 did not run while item 0 was held";
  EXPECT_EQ(started, (std::vector<std::size_t>{1, 2, 3, 4, 5}));
}

TEST(Executor, PerThreadSlotsAreDistinct) {
  Executor executor(4);
  PerThread<std::vector<std::size_t>> slots;
  executor.execute([&] {
    parallel_for(0, 500, 1, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i != hi; ++i) slots.local().push_back(i);
    });
  });
  std::vector<std::size_t> all;
  std::size_t used = 0;
  slots.for_each([&](const std::vector<std::size_t>& s) {
    all.insert(all.end(), s.begin(), s.end());
    ++used;
  });
  EXPECT_GE(used, 1u);
  EXPECT_EQ(slots.all().size(), used);
  std::sort(all.begin(), all.end());
  std::vector<std::size_t> want(500);
  std::iota(want.begin(), want.end(), std::size_t{0});
  EXPECT_EQ(all, want);
  std::vector<int> v(3000);
  std::iota(v.rbegin(), v.rend(), 0);
  parallel_sort(v.begin(), v.end(), std::less<>());
  EXPECT_TRUE(std::is_sorted(v.begin(), v.end()));
  EXPECT_FALSE(backend().empty());
}

TEST(Executor, AnExecutorUsedInsideItsOwnWorkKeepsItsThreads) {
  // Four items that each wait (up to 20 s) until two of them run at once: only parallel work meets.
  Executor executor(2);
  std::atomic<int> running{0};
  std::atomic<bool> met{false};
  const auto body = [&](std::size_t, std::size_t) {
    ++running;
    for (const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
         running.load() < 2 && std::chrono::steady_clock::now() < deadline;) {}
    if (running.load() >= 2) met = true;
  };
  executor.execute([&] { executor.execute([&] { parallel_for(0, 4, 1, body); }); });
  EXPECT_TRUE(met.load()) << "the nested call ran on one thread";
}

TEST(Executor, ChunksOfRangesNearTheLargestSize) {
  const std::size_t top = std::numeric_limits<std::size_t>::max();
  for (const auto& [begin, end, grain] :
       {std::tuple{std::size_t{0}, top, top / 2}, std::tuple{std::size_t{0}, std::size_t{1} << 62, std::size_t{1} << 60},
        std::tuple{top - 10, top, std::size_t{3}}}) {
    std::vector<std::pair<std::size_t, std::size_t>> chunks;
    parallel_for(begin, end, grain, [&](std::size_t lo, std::size_t hi) { chunks.emplace_back(lo, hi); });
    ASSERT_FALSE(chunks.empty()) << "grain " << grain;
    EXPECT_EQ(chunks.front().first, begin);
    EXPECT_EQ(chunks.back().second, end);
    for (std::size_t k = 0; k < chunks.size(); ++k) {
      EXPECT_LT(chunks[k].first, chunks[k].second);
      EXPECT_LE(chunks[k].second - chunks[k].first, grain);
      if (k > 0) EXPECT_EQ(chunks[k].first, chunks[k - 1].second);
    }
  }
}

TEST(Executor, ParallelSortOnAnyExecutorSortsAndKeepsEveryElement) {
  for (const int threads : {1, 2, 4}) {
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{4095}, std::size_t{4097}, std::size_t{100000}}) {
      std::vector<std::uint64_t> v(n);
      for (std::size_t i = 0; i < n; ++i) v[i] = (i * 2654435761u) % 1000003u;
      std::vector<std::uint64_t> want = v;
      std::sort(want.begin(), want.end());
      Executor executor(threads);
      executor.execute([&] { parallel_sort(v.begin(), v.end(), std::less<>()); });
      EXPECT_EQ(v, want) << n << " items, " << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace caliber::parallel
