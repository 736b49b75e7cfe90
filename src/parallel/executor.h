#pragma once
/// \file
/// The one seam between "what tasks to run" and "how to run them": every parallel construct in
/// caliber goes through this header. The host owns the threads: caliber's parallel work runs only
/// inside Executor::execute, and outside it every construct below runs on the calling thread (so
/// caliber::query, and any call a host makes from its own threads, creates no thread). Two
/// backends, chosen when the library is built:
///   - oneTBB (default): an executor runs its work in the oneTBB arena it is called from
///     (threads = 0), in a tbb::task_arena of its own (threads > 1, at most the process's limit),
///     or on the calling thread alone (threads = 1). It never changes process-wide settings (no
///     tbb::global_control). tbb::parallel_for, tbb::task_group, tbb::enumerable_thread_specific
///     underneath; these wrappers add nothing on hot paths but a thread-local flag per task.
///   - std::thread (`-DCALIBER_EXECUTOR=std`, forced by `-DCALIBER_SANITIZE=thread`): a small pool
///     whose every synchronization is a std::mutex / std::condition_variable, so ThreadSanitizer
///     sees all of it. Debian's libtbb is not instrumented: under TSan its own hand-offs look like
///     races, which would hide the real ones in caliber. Slower, and not work stealing in the
///     strict sense (waiting threads help from one shared queue), but it runs the same code paths.
///     threads = 0 there means the machine's hardware threads.
/// Results never depend on the backend or on the schedule (tested in both builds).

#include <cstddef>
#include <functional>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>
#include <algorithm>
#include <exception>

#include "caliber/executor.h"
#include "parallel/borrowed_pool.h"

#ifdef CALIBER_EXECUTOR_STD
#include <algorithm>
#include <exception>
#include <list>
#include <map>
#include <mutex>
#include <thread>
#else
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>
#endif

namespace caliber::parallel {

/// "oneTBB" or "std::thread": the backend this library was built with.
[[nodiscard]] std::string_view backend();

/// Where a piece of caliber's work runs: `threads` = 0, the oneTBB arena execute() is called from
/// (the host's: its arena, or oneTBB's default one); 1, the calling thread alone; N > 1, an arena
/// of its own with N slots, run on at most the process's limit of threads. Parallel work started
/// inside execute() (parallel_for, TaskGroup, ...) runs there and on no other thread.
class Executor {
 public:
  /// `threads` >= 0 (see the class comment). Throws caliber::Error on a negative count. With a
  /// `host`, the work runs on the threads the host lends for each execute() (borrowed_pool.h), at
  /// most `threads` of them (0: all it offers), and caliber creates no thread.
  explicit Executor(int threads, HostExecutor* host = nullptr);
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  /// The threads execute() would run on if called from this thread now (the caller included):
  /// 1 for a one-thread executor; otherwise the arena's concurrency, at most the process's limit
  /// (oneTBB's max_allowed_parallelism, which follows the CPU affinity).
  [[nodiscard]] int threads() const;

  /// Runs `f` on the calling thread, joined by the executor's other threads until it returns.
  /// Exceptions thrown by `f` (or by tasks it waits for) propagate to the caller.
  void execute(const std::function<void()>& f);

 private:
  /// execute() on the host's threads.
  void execute_borrowed(const std::function<void()>& f);
  /// The host's threads for a call: thread_count() in [1, 1024], at most the threads asked for;
  /// kept for the next execute(), so that a call's cut and its pool agree.
  int host_threads() const;

  int mRequested;
  HostExecutor* mHost;
  mutable int mHostThreads = 0;  ///< read by threads() for the coming execute(), 0 when not
#ifdef CALIBER_EXECUTOR_STD
 public:
  struct Pool;

 private:
  std::unique_ptr<Pool> mPool;
#else
  std::unique_ptr<tbb::task_arena> mArena;  ///< threads > 1 only
#endif
};

#ifndef CALIBER_EXECUTOR_STD
namespace detail {
/// The concurrency of the executor whose work the calling thread is doing; 0 outside any. Set by
/// Executor::execute and carried into every task the wrappers below hand to oneTBB, on whatever
/// thread runs it (a worker of the host's arena knows nothing of caliber otherwise).
inline thread_local int t_concurrency = 0;

/// Sets t_concurrency for a scope.
class ConcurrencyScope {
 public:
  explicit ConcurrencyScope(int concurrency) : mSaved(t_concurrency) { t_concurrency = concurrency; }
  ~ConcurrencyScope() { t_concurrency = mSaved; }
  ConcurrencyScope(const ConcurrencyScope&) = delete;
  ConcurrencyScope& operator=(const ConcurrencyScope&) = delete;

 private:
  int mSaved;
};

/// Whether parallel constructs should go to oneTBB: inside an executor of more than one thread.
inline bool parallel_here() { return t_concurrency > 1; }
}  // namespace detail
#endif

/// A set of tasks run in parallel (on the executor the caller runs in) and waited for together.
/// Outside any executor (or in a one-thread executor), run() calls the task at once.
class TaskGroup {
 public:
  TaskGroup();
  ~TaskGroup();
  TaskGroup(const TaskGroup&) = delete;
  TaskGroup& operator=(const TaskGroup&) = delete;

#ifdef CALIBER_EXECUTOR_STD
  /// Queues `f`; the first exception a task throws is rethrown by wait().
  void run(std::function<void()> f);
  /// Waits for every task run() so far, helping to run queued tasks meanwhile.
  void wait();

 private:
  detail::BorrowedPool* mBorrowed;  ///< the host's threads' pool it was made in, or null
  detail::BorrowedGroup mBorrowedJobs;
  Executor::Pool* mPool;
  std::size_t mPending = 0;   ///< guarded by the pool's mutex
  std::exception_ptr mError;  ///< guarded by the pool's mutex
  friend struct Executor::Pool;
#else
  /// Hands `f` to oneTBB (or runs it now, serially); the first exception a task throws is
  /// rethrown by wait().
  template <class F>
  void run(F&& f) {
    if (mBorrowed != nullptr) {
      mBorrowed->submit(std::function<void()>(std::forward<F>(f)), mBorrowedJobs);
      return;
    }
    if (!detail::parallel_here()) {
      try {
        f();
      } catch (...) {
        if (!mError) mError = std::current_exception();
      }
      return;
    }
    mGroup.run([fn = std::forward<F>(f), c = detail::t_concurrency] {
      const detail::ConcurrencyScope scope(c);
      fn();
    });
  }
  /// Waits for every task run() so far.
  void wait() {
    if (mBorrowed != nullptr) {
      mBorrowed->wait(mBorrowedJobs);
      return;
    }
    mGroup.wait();
    if (mError) std::rethrow_exception(std::exchange(mError, nullptr));
  }

 private:
  detail::BorrowedPool* mBorrowed = detail::t_borrowed;  ///< the host's threads' pool it was made in, or null
  detail::BorrowedGroup mBorrowedJobs;
  tbb::task_group mGroup;
  std::exception_ptr mError;  ///< of a task run serially
#endif
};

/// The calling thread's index in the executor it works for (0 .. threads-1 for an arena of its own;
/// the slot in the host's arena otherwise), or -1 outside any.
[[nodiscard]] int current_thread_index();

/// Calls body(lo, hi) on disjoint chunks covering [begin, end), each at most `grain` long (and at
/// least grain / 2 where the range allows), in parallel on the current executor (one after the
/// other outside any). A range no longer than `grain` runs at once on the calling thread.
void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body);

/// The number of threads of the executor the caller runs in; 1 outside any executor.
[[nodiscard]] int concurrency();

/// Greedy list scheduling: calls body(i) for i = 0, 1, ..., n-1, each i taken by whichever of the
/// executor's threads is free next, in that order. Given items sorted heaviest first this is the
/// LPT schedule that the load-balance simulation replays. parallel_for is not: its recursive halving
/// hands each thread a contiguous block (on 2 threads, tasks {0, 1} to one and {2, 3} to the other).
/// The first exception a body throws is rethrown once every thread has stopped; items not yet
/// taken are then skipped.
void for_each_in_order(std::size_t n, const std::function<void(std::size_t)>& body);

/// Calls f(i) for every i in [begin, end), in parallel; the backend picks the chunk sizes.
template <class F>
void parallel_for_each(std::size_t begin, std::size_t end, F&& f) {
#ifdef CALIBER_EXECUTOR_STD
  parallel_for(begin, end, 1, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i != hi; ++i) f(i);
  });
#else
  if (begin >= end) return;
  if (detail::t_borrowed != nullptr) {  // chunks of about an eighth of a thread's share
    const std::size_t share = (end - begin) / (8 * static_cast<std::size_t>(detail::t_borrowed->threads()));
    parallel_for(begin, end, std::max<std::size_t>(share, 1), [&](std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i != hi; ++i) f(i);
    });
    return;
  }
  if (!detail::parallel_here()) {
    for (std::size_t i = begin; i != end; ++i) f(i);
    return;
  }
  tbb::parallel_for(begin, end, [&f, c = detail::t_concurrency](std::size_t i) {
    const detail::ConcurrencyScope scope(c);
    f(i);
  });
#endif
}

/// Sorts [first, last) by `less`, in parallel where the backend can (std backend, or outside an
/// executor: one thread). Only for orders where no two elements compare equal, or where equal
/// elements cannot be told apart (plain numbers), so that the result is unique.
template <class It, class Less>
void parallel_sort(It first, It last, Less less) {
#ifdef CALIBER_EXECUTOR_STD
  std::sort(first, last, less);
#else
  if (detail::parallel_here() && detail::t_borrowed == nullptr) {
    tbb::parallel_sort(first, last, less);
  } else {
    std::sort(first, last, less);
  }
#endif
}

/// One T per thread that asked for it: local() is the calling thread's (default-constructed on
/// first use), for_each() visits all of them. local() may be called concurrently; for_each() only
/// while no thread calls local().
template <class T>
class PerThread {
 public:
  T& local() {
#ifdef CALIBER_EXECUTOR_STD
    const std::lock_guard<std::mutex> lock(mMutex);
    auto [it, inserted] = mSlots.try_emplace(std::this_thread::get_id(), nullptr);
    if (inserted) it->second = &mStorage.emplace_back();
    return *it->second;
#else
    return mSlots.local();
#endif
  }

  template <class F>
  void for_each(F&& f) {
#ifdef CALIBER_EXECUTOR_STD
    const std::lock_guard<std::mutex> lock(mMutex);
    for (T& t : mStorage) f(t);
#else
    for (T& t : mSlots) f(t);
#endif
  }

  /// Pointers to every thread's T, for reading them from several threads at once.
  std::vector<T*> all() {
    std::vector<T*> out;
    for_each([&](T& t) { out.push_back(&t); });
    return out;
  }

 private:
#ifdef CALIBER_EXECUTOR_STD
  std::mutex mMutex;
  std::map<std::thread::id, T*> mSlots;
  std::list<T> mStorage;
#else
  tbb::enumerable_thread_specific<T> mSlots;
#endif
};

}  // namespace caliber::parallel
