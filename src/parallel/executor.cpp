#include "parallel/executor.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>

#include "caliber/error.h"

#ifdef CALIBER_EXECUTOR_STD
#include <condition_variable>
#include <deque>
#endif

namespace caliber::parallel {

#ifdef CALIBER_EXECUTOR_STD

std::string_view backend() { return "std::thread"; }

/// The std backend: threads - 1 workers and one shared queue; a thread waiting on a TaskGroup runs
/// queued tasks meanwhile (newest first, so it tends to finish its own children), idle workers take
/// the oldest (the biggest pieces of a recursive split). Every hand-off goes through `mutex`.
struct Executor::Pool {
  struct Job {
    std::function<void()> fn;
    TaskGroup* group;
  };

  std::mutex mutex;
  std::condition_variable changed;  ///< a job was queued, a group finished, or the pool stops
  std::deque<Job> queue;
  bool stop = false;
  std::vector<std::thread> workers;

  /// Runs a job taken off the queue (lock not held) and signs it off in its group.
  void run_job(Job& job) {
    std::exception_ptr error;
    try {
      job.fn();
    } catch (...) {
      error = std::current_exception();
    }
    job.fn = nullptr;
    const std::lock_guard<std::mutex> lock(mutex);
    if (error && !job.group->mError) job.group->mError = error;
    // The group's owner may destroy it as soon as the lock is released: nothing touches it after.
    if (--job.group->mPending == 0) changed.notify_all();
  }

  void work();
};

namespace {
/// The pool the calling thread works for: set for workers, and for a caller inside execute().
thread_local Executor::Pool* t_pool = nullptr;
/// The calling thread's index in that pool: 0 for the caller of execute(), 1.. for workers.
thread_local int t_index = -1;
}  // namespace

int current_thread_index() {
  if (detail::t_borrowed != nullptr) return detail::t_borrowed_index;
  return t_pool != nullptr ? t_index : -1;
}

int concurrency() {
  if (detail::t_borrowed != nullptr) return detail::t_borrowed->threads();
  return t_pool != nullptr ? static_cast<int>(t_pool->workers.size()) + 1 : 1;
}

void Executor::Pool::work() {
  t_pool = this;
  std::unique_lock<std::mutex> lock(mutex);
  for (;;) {
    changed.wait(lock, [&] { return stop || !queue.empty(); });
    if (queue.empty()) return;  // stopping, nothing left
    Job job = std::move(queue.front());
    queue.pop_front();
    lock.unlock();
    run_job(job);
    lock.lock();
  }
}

Executor::Executor(int threads, HostExecutor* host) : mRequested(threads), mHost(host), mPool(std::make_unique<Pool>()) {
  if (threads < 0) throw Error(ErrorCode::bad_value, "threads", "must be >= 0 (0: the machine's hardware threads)");
  if (host != nullptr) return;  // the host's threads, lent for each execute()
  if (threads == 0) mRequested = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int t = 1; t < mRequested; ++t) {
    mPool->workers.emplace_back([pool = mPool.get(), t] {
      t_index = t;
      pool->work();
    });
  }
}

int Executor::threads() const {
  if (mHost != nullptr) return host_threads();
  return mRequested;
}

Executor::~Executor() {
  {
    const std::lock_guard<std::mutex> lock(mPool->mutex);
    mPool->stop = true;
  }
  mPool->changed.notify_all();
  for (std::thread& t : mPool->workers) t.join();
}

void Executor::execute(const std::function<void()>& f) {
  if (mHost != nullptr) {
    execute_borrowed(f);
    return;
  }
  const detail::BorrowedScope outside(nullptr, -1);  // its constructs go to this pool, not a borrowed one
  Pool* const previous = t_pool;
  const int previous_index = t_index;
  t_pool = mPool.get();
  t_index = 0;
  try {
    f();
  } catch (...) {
    t_pool = previous;
    t_index = previous_index;
    throw;
  }
  t_pool = previous;
  t_index = previous_index;
}

TaskGroup::TaskGroup() : mBorrowed(detail::t_borrowed), mPool(t_pool) {}

TaskGroup::~TaskGroup() {
  try {
    wait();
  } catch (...) {  // NOLINT(bugprone-empty-catch): an unwaited group's error has nowhere to go
  }
}

void TaskGroup::run(std::function<void()> f) {
  if (mBorrowed != nullptr) {
    mBorrowed->submit(std::move(f), mBorrowedJobs);
    return;
  }
  if (mPool == nullptr) {  // outside any executor: run it now
    try {
      f();
    } catch (...) {
      if (!mError) mError = std::current_exception();
    }
    return;
  }
  {
    const std::lock_guard<std::mutex> lock(mPool->mutex);
    mPool->queue.push_back(Executor::Pool::Job{std::move(f), this});  // first: a failed push leaves no job counted
    ++mPending;
  }
  mPool->changed.notify_one();
}

void TaskGroup::wait() {
  if (mBorrowed != nullptr) {
    mBorrowed->wait(mBorrowedJobs);
    return;
  }
  std::exception_ptr error;
  if (mPool != nullptr) {
    std::unique_lock<std::mutex> lock(mPool->mutex);
    while (mPending > 0) {
      if (mPool->queue.empty()) {
        mPool->changed.wait(lock);
        continue;
      }
      Executor::Pool::Job job = std::move(mPool->queue.back());
      mPool->queue.pop_back();
      lock.unlock();
      mPool->run_job(job);
      lock.lock();
    }
    error = std::exchange(mError, nullptr);
  } else {
    error = std::exchange(mError, nullptr);
  }
  if (error) std::rethrow_exception(error);
}

void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body) {
  if (begin >= end) return;
  grain = std::max<std::size_t>(grain, 1);
  if (end - begin <= grain) {
    body(begin, end);
    return;
  }
  const std::size_t length = end - begin;
  const std::size_t chunks = (length + grain - 1) / grain;
  TaskGroup group;
  for (std::size_t c = 0; c < chunks; ++c) {
    const std::size_t lo = begin + length * c / chunks, hi = begin + length * (c + 1) / chunks;
    group.run([&body, lo, hi] { body(lo, hi); });
  }
  group.wait();
}

#else  // oneTBB

std::string_view backend() { return "oneTBB"; }

namespace {
/// The process's limit on oneTBB's threads (max_allowed_parallelism: the CPU affinity's count
/// unless a host's tbb::global_control lowers it).
int process_limit() {
  const std::size_t limit = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  return static_cast<int>(std::clamp<std::size_t>(limit, 1, 1u << 20));
}
}  // namespace

Executor::Executor(int threads, HostExecutor* host) : mRequested(threads), mHost(host) {
  if (threads < 0) throw Error(ErrorCode::bad_value, "threads", "must be >= 0 (0: the arena caliber is called from)");
  if (host != nullptr) return;  // the host's threads, lent for each execute()
  // An arena no wider than the limit in force, so that its slot indices stay below threads().
  if (threads > 1) mArena = std::make_unique<tbb::task_arena>(std::min(threads, process_limit()));
}

Executor::~Executor() = default;

int Executor::threads() const {
  if (mHost != nullptr) return host_threads();
  if (mRequested == 1) return 1;
  const int arena = mArena ? mArena->max_concurrency() : tbb::this_task_arena::max_concurrency();
  return std::max(1, std::min(arena, process_limit()));
}

void Executor::execute(const std::function<void()>& f) {
  if (mHost != nullptr) {
    execute_borrowed(f);
    return;
  }
  const detail::BorrowedScope outside(nullptr, -1);  // its constructs go to oneTBB, not a borrowed pool
  const int concurrency = threads();
  if (concurrency > 1 && mArena) {
    mArena->execute([&] {
      const detail::ConcurrencyScope scope(concurrency);
      f();
    });
    return;
  }
  // The caller's arena (the tasks oneTBB runs go to it), or the calling thread alone.
  const detail::ConcurrencyScope scope(concurrency);
  f();
}

int current_thread_index() {
  if (detail::t_borrowed != nullptr) return detail::t_borrowed_index;
  if (detail::t_concurrency == 0) return -1;
  if (detail::t_concurrency == 1) return 0;
  const int index = tbb::this_task_arena::current_thread_index();
  return index == tbb::task_arena::not_initialized ? -1 : index;
}

int concurrency() {
  if (detail::t_borrowed != nullptr) return detail::t_borrowed->threads();
  return std::max(detail::t_concurrency, 1);
}

TaskGroup::TaskGroup() = default;
TaskGroup::~TaskGroup() {
  try {
    if (mBorrowed != nullptr) {
      mBorrowed->wait(mBorrowedJobs);
    } else {
      mGroup.wait();
    }
  } catch (...) {  // NOLINT(bugprone-empty-catch): an unwaited group's error has nowhere to go
  }
}

void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body) {
  if (begin >= end) return;
  grain = std::max<std::size_t>(grain, 1);
  if (end - begin <= grain) {
    body(begin, end);
    return;
  }
  if (detail::t_borrowed != nullptr) {  // on the host's threads: chunks as tasks of the borrowed pool
    const std::size_t length = end - begin, chunks = (length + grain - 1) / grain;
    TaskGroup group;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::size_t lo = begin + length * c / chunks, hi = begin + length * (c + 1) / chunks;
      group.run([&body, lo, hi] { body(lo, hi); });
    }
    group.wait();
    return;
  }
  if (!detail::parallel_here()) {  // outside an executor, or a one-thread one: chunk by chunk, here
    const std::size_t length = end - begin, chunks = (length + grain - 1) / grain;
    for (std::size_t c = 0; c < chunks; ++c) body(begin + length * c / chunks, begin + length * (c + 1) / chunks);
    return;
  }
  // simple_partitioner: split down to the grain. The default (auto) partitioner stops splitting
  // early when nobody steals, so a thread would run ~16 consecutive items as one chunk. Even so the
  // halving hands out contiguous blocks: where the order matters, use for_each_in_order.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(begin, end, grain),
      [&body, c = detail::t_concurrency](const tbb::blocked_range<std::size_t>& r) {
        const detail::ConcurrencyScope scope(c);
        body(r.begin(), r.end());
      },
      tbb::simple_partitioner());
}

#endif

void Executor::execute_borrowed(const std::function<void()>& f) {
  // The count read for this call (threads() at its start), or read now.
  detail::BorrowedPool pool(mHostThreads > 0 ? std::exchange(mHostThreads, 0) : threads());
  // The caller works for the pool from here on: a range the host runs here (inline, or inside
  // finish()) returns at once. Its constructs go to the pool only while `f` runs: the host's own
  // code in enqueue() and finish() runs as it would outside caliber.
  const detail::Membership member(&pool);
  const detail::BorrowedScope outside(nullptr, -1);
  // The host's threads take the pool's jobs until it closes: one item each, after the caller's.
  // The task outlives finish(): the host may keep a reference to it.
  const HostExecutor::Task lent = [&pool](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) pool.lend(static_cast<int>(i) + 1);
  };
  void* handle = pool.threads() > 1 ? mHost->enqueue(lent, static_cast<std::size_t>(pool.threads() - 1), 1) : nullptr;
  std::exception_ptr error;
  try {
    const detail::BorrowedScope scope(&pool, 0);
    f();
  } catch (...) {
    error = std::current_exception();
  }
  pool.close();
  if (handle != nullptr) mHost->finish(handle);
  if (error) std::rethrow_exception(error);
}

int Executor::host_threads() const {
  // At most 1024, as EngineOptions::threads; at most the threads asked for, when asked.
  const int offered = std::clamp(mHost->thread_count(), 1, 1024);
  mHostThreads = mRequested > 0 ? std::min(mRequested, offered) : offered;
  return mHostThreads;
}

void for_each_in_order(std::size_t n, const std::function<void(std::size_t)>& body) {
  std::atomic<std::size_t> next{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  const auto drain = [&] {
    for (std::size_t i = next.fetch_add(1, std::memory_order_relaxed); i < n; i = next.fetch_add(1, std::memory_order_relaxed)) {
      try {
        body(i);
      } catch (...) {
        next.store(n, std::memory_order_relaxed);  // nobody takes another item
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  const std::size_t helpers = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(concurrency(), 1))) - (n > 0 ? 1 : 0);
  TaskGroup group;
  for (std::size_t k = 0; k < helpers; ++k) group.run(drain);
  drain();
  group.wait();
  if (error) std::rethrow_exception(error);
}

}  // namespace caliber::parallel
