#pragma once
/// \file
/// The one seam between "what jobs to run" and "how to run them": every parallel construct in
/// caliber goes through this header. The host owns the threads: caliber's parallel work runs only
/// inside Executor::execute, and outside it every construct below runs on the calling thread (so
/// caliber::query, and any call a host makes from its own threads, creates no thread).
///
/// Where the work of an execute() goes:
///   - a host's job system (caliber/executor.h): the threads it lends for the call take jobs from
///     one pool (borrowed_pool.h), whichever backend the library was built with;
///   - otherwise the backend chosen when the library is built, in a file of its own:
///     tbb_backend.h (default: oneTBB, the arena execute() is called from or one of its own) or
///     std_backend.h (`-DCALIBER_EXECUTOR=std`, forced by `-DCALIBER_SANITIZE=thread`: a host
///     over threads of its own, every hand-off a std::mutex, so ThreadSanitizer sees all of it).
/// Results never depend on the backend or on the schedule (tested in both builds).

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "caliber/executor.h"
#include "parallel/borrowed_pool.h"

#ifdef CALIBER_EXECUTOR_STD
#include "parallel/std_backend.h"
#else
#include "parallel/tbb_backend.h"
#endif

namespace caliber::parallel {

/// "oneTBB" or "std::thread": the backend this library was built with.
[[nodiscard]] constexpr std::string_view backend() { return native::kName; }

/// Where a piece of caliber's work runs: `threads` = 0, the backend's default (oneTBB: the arena
/// execute() is called from; std::thread: the machine's hardware threads); 1, the calling thread
/// alone; N > 1, N threads (oneTBB: an arena of its own, at most the process's limit). Parallel
/// work started inside execute() (parallel_for, JobGroup, ...) runs there and on no other thread.
class Executor {
 public:
  /// `threads` >= 0 (see the class comment). Throws caliber::Error on a negative count. With a
  /// `host`, the work runs on the threads the host lends for each execute() (borrowed_pool.h), at
  /// most `threads` of them (0: all it offers), and caliber creates no thread.
  explicit Executor(int threads, HostExecutor* host = nullptr);
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  /// The threads execute() would run on if called from this thread now (the caller included).
  [[nodiscard]] int threads() const;

  /// Runs `f` on the calling thread, joined by the executor's other threads until it returns.
  /// Exceptions thrown by `f` (or by jobs it waits for) propagate to the caller.
  void execute(const std::function<void()>& f);

 private:
  /// The host's threads for a call: thread_count() in [1, 1024], at most the threads asked for;
  /// kept for the next execute(), so that a call's cut and its pool agree.
  int host_threads() const;
  /// thread_count() in [1, 1024], at most the threads asked for; stores nothing.
  int offered_threads() const;

  int mRequested;
  HostExecutor* mHost;
  mutable std::atomic<int> mHostThreads{0};   ///< read by threads() for the coming execute(), 0 when not
  std::unique_ptr<native::Workers> mWorkers;  ///< without a host only
};

/// A set of jobs run in parallel (on the executor the caller runs in) and waited for together.
/// Outside any executor (or in a one-thread executor), run() calls the job at once.
class JobGroup {
 public:
  JobGroup() = default;
  ~JobGroup();
  JobGroup(const JobGroup&) = delete;
  JobGroup& operator=(const JobGroup&) = delete;

  /// Queues `f` (or runs it now, serially); the first exception a job throws is rethrown by wait().
  template <class F>
  void run(F&& f) {
    if (mBorrowed != nullptr) {
      mBorrowed->submit(std::function<void()>(std::forward<F>(f)), mBorrowedJobs);
    } else if (native::parallel_here()) {
      mGroup.run(std::forward<F>(f));
    } else {
      try {
        f();
      } catch (...) {
        if (!mError) mError = std::current_exception();
      }
    }
  }
  /// Waits for every job run() so far (helping to run them meanwhile).
  void wait();

 private:
  detail::BorrowedPool* mBorrowed = detail::t_borrowed;  ///< the host's threads' pool it was made in, or null
  detail::BorrowedGroup mBorrowedJobs;
  native::Group mGroup;
  std::exception_ptr mError;  ///< of a job run serially
};

/// The calling thread's index in the executor it works for (0 .. threads-1 for threads of its own;
/// the slot in the host's arena otherwise), or -1 outside any.
[[nodiscard]] int current_thread_index();

/// Whether the caller is doing an executor's work (inside Executor::execute, or a task it started).
[[nodiscard]] bool in_executor();

/// The number of threads of the executor the caller runs in; 1 outside any executor.
[[nodiscard]] int concurrency();

/// Calls body(lo, hi) on disjoint chunks covering [begin, end), each at most `grain` long (and at
/// least grain / 2 where the range allows), in parallel on the current executor (one after the
/// other outside any). A range no longer than `grain` runs at once on the calling thread.
void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body);

/// Greedy list scheduling: calls body(i) for i = 0, 1, ..., n-1, each i taken by whichever of the
/// executor's threads is free next, in that order. Given items sorted heaviest first this is the
/// LPT schedule that the load-balance simulation replays. parallel_for is not: its recursive halving
/// hands each thread a contiguous block (on 2 threads, items {0, 1} to one and {2, 3} to the other).
/// The first exception a body throws is rethrown once every thread has stopped; items not yet
/// taken are then skipped.
void for_each_in_order(std::size_t n, const std::function<void(std::size_t)>& body);

/// Calls f(i) for every i in [begin, end), in parallel; the backend picks the chunk sizes.
template <class F>
void parallel_for_each(std::size_t begin, std::size_t end, F&& f) {
  if (begin >= end) return;
  if (detail::t_borrowed != nullptr) {  // chunks of about an eighth of a thread's share
    const std::size_t share = (end - begin) / (8 * static_cast<std::size_t>(detail::t_borrowed->threads()));
    parallel_for(begin, end, std::max<std::size_t>(share, 1), [&](std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i != hi; ++i) f(i);
    });
  } else if (native::parallel_here()) {
    native::parallel_for_each(begin, end, f);
  } else {
    for (std::size_t i = begin; i != end; ++i) f(i);
  }
}

namespace detail {
/// Sorts [first, last): halves sorted as jobs of a JobGroup, `depth` levels deep, then merged.
template <class It, class Less>
void sort_in_halves(It first, It last, Less less, int depth) {
  constexpr std::ptrdiff_t kSmall = 4096;  // below this a job costs more than it saves
  if (depth <= 0 || last - first < kSmall) {
    std::sort(first, last, less);
    return;
  }
  const It middle = first + (last - first) / 2;
  JobGroup group;
  group.run([&] { sort_in_halves(first, middle, less, depth - 1); });
  sort_in_halves(middle, last, less, depth - 1);
  group.wait();
  std::inplace_merge(first, middle, last, less);
}
}  // namespace detail

/// Sorts [first, last) by `less`, in parallel on the current executor (on the calling thread
/// outside any). Only for orders where no two elements compare equal, or where equal elements
/// cannot be told apart (plain numbers), so that the result is unique.
template <class It, class Less>
void parallel_sort(It first, It last, Less less) {
  if (detail::t_borrowed != nullptr) {
    int depth = 1;  // about two halves per thread
    while ((1 << (depth - 1)) < detail::t_borrowed->threads() && depth < 10) ++depth;
    detail::sort_in_halves(first, last, less, detail::t_borrowed->threads() > 1 ? depth : 0);
  } else if (native::parallel_here()) {
    native::parallel_sort(first, last, less);
  } else {
    std::sort(first, last, less);
  }
}

/// One T per thread that asked for it: local() is the calling thread's (default-constructed on
/// first use), for_each() visits all of them. local() may be called concurrently; for_each() only
/// while no thread calls local().
template <class T>
class PerThread {
 public:
  T& local() { return mSlots.local(); }

  template <class F>
  void for_each(F&& f) {
    mSlots.for_each(std::forward<F>(f));
  }

  /// Pointers to every thread's T, for reading them from several threads at once.
  std::vector<T*> all() {
    std::vector<T*> out;
    for_each([&](T& t) { out.push_back(&t); });
    return out;
  }

 private:
  native::PerThreadSlots<T> mSlots;
};

}  // namespace caliber::parallel
