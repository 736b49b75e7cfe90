#pragma once
/// \file
/// The oneTBB backend of executor.h (the default). An executor runs its work in the oneTBB arena it
/// is called from (threads = 0), in a tbb::task_arena of its own (threads > 1, at most the
/// process's limit), or on the calling thread alone (threads = 1). It never changes process-wide
/// settings (no tbb::global_control). tbb::parallel_for, tbb::task_group and
/// tbb::enumerable_thread_specific underneath; these wrappers add nothing on hot paths but a
/// thread-local flag per job.

#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>
#include <string_view>
#include <utility>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

namespace caliber::parallel::native {

inline constexpr std::string_view kName = "oneTBB";
/// What `threads` = 0 means, for the error on a negative count.
inline constexpr std::string_view kZeroThreads = "0: the arena caliber is called from";

/// The concurrency of the executor whose work the calling thread is doing; 0 outside any. Set by
/// Workers::execute and carried into every job the wrappers below hand to oneTBB, on whatever
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

/// The calling thread's slot in the arena of the executor it works for, or -1 outside any.
int thread_index();

/// Whether the caller works for an executor of this backend.
inline bool in_executor() { return t_concurrency > 0; }

/// The concurrency of the executor the caller works for; 1 outside any.
inline int concurrency() { return std::max(t_concurrency, 1); }

/// The threads of an executor without a host: an arena of its own, or the caller's.
class Workers {
 public:
  /// `threads` >= 0, as Executor's.
  explicit Workers(int threads);
  ~Workers();
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  /// 1 for a one-thread executor; otherwise the arena's concurrency, at most the process's limit
  /// (oneTBB's max_allowed_parallelism, which follows the CPU affinity).
  [[nodiscard]] int threads() const;
  void execute(const std::function<void()>& f);

 private:
  int mRequested;
  std::unique_ptr<tbb::task_arena> mArena;  ///< threads > 1 only
};

/// A JobGroup's jobs on oneTBB (inside an executor of more than one thread).
class Group {
 public:
  template <class F>
  void run(F&& f) {
    mGroup.run([fn = std::forward<F>(f), c = t_concurrency] {
      const ConcurrencyScope scope(c);
      fn();
    });
  }
  void wait() { mGroup.wait(); }

 private:
  tbb::task_group mGroup;
};

/// parallel_for inside an executor of more than one thread: chunks of at most `grain`.
void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body);

template <class F>
void parallel_for_each(std::size_t begin, std::size_t end, F& f) {
  tbb::parallel_for(begin, end, [&f, c = t_concurrency](std::size_t i) {
    const ConcurrencyScope scope(c);
    f(i);
  });
}

template <class It, class Less>
void parallel_sort(It first, It last, Less less) {
  tbb::parallel_sort(first, last, less);
}

template <class T>
class PerThreadSlots {
 public:
  T& local() { return mSlots.local(); }
  template <class F>
  void for_each(F&& f) {
    for (T& t : mSlots) f(t);
  }

 private:
  tbb::enumerable_thread_specific<T> mSlots;
};

}  // namespace caliber::parallel::native
