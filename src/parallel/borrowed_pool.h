#pragma once
/// \file
/// The threads a host lends for one Executor::execute (caliber/executor.h): one queue of jobs that
/// the caller and the lent threads take from. A thread waiting on a JobGroup runs queued jobs
/// meanwhile (newest first, so it tends to finish its own children); a lent thread takes the
/// oldest (the biggest pieces of a recursive split). Every hand-off goes through one mutex.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>

namespace caliber {
class HostExecutor;
}

namespace caliber::parallel::detail {

/// A JobGroup's jobs in a borrowed pool; guarded by the pool's mutex.
struct BorrowedGroup {
  std::size_t pending = 0;
  std::exception_ptr error;  ///< the first error a job threw
};

class BorrowedPool;

/// The borrowed pools the calling thread works for, innermost first, as a chain through the
/// thread's stack: a thread lent to a pool it already works for (a host that runs a queued range
/// while the thread waits inside that pool's call) must not take its jobs again.
struct Membership {
  explicit Membership(BorrowedPool* pool, int index = 0);
  ~Membership();
  Membership(const Membership&) = delete;
  Membership& operator=(const Membership&) = delete;

  BorrowedPool* pool;
  Membership* outer;
  int index;  ///< the thread's index in `pool`
};

class BorrowedPool {
 public:
  /// A pool of `threads` (the caller included).
  explicit BorrowedPool(int threads, const HostExecutor* host = nullptr) : mThreads(threads), mHost(host) {}
  BorrowedPool(const BorrowedPool&) = delete;
  BorrowedPool& operator=(const BorrowedPool&) = delete;

  [[nodiscard]] int threads() const { return mThreads; }
  /// The host whose threads it borrows (null: none named).
  [[nodiscard]] const HostExecutor* host() const { return mHost; }
  /// Queues `fn` for `group`.
  void submit(std::function<void()> fn, BorrowedGroup& group);
  /// Waits until every job of `group` has run, running queued jobs meanwhile; rethrows the first
  /// error one of them threw.
  void wait(BorrowedGroup& group);
  /// What a lent thread does (`index` >= 1, its index in the pool): take jobs until the pool
  /// closes. Returns at once on a thread that already works for this pool (its caller, when the
  /// host runs the ranges inline or inside finish()), and once the pool has closed.
  void lend(int index);
  /// The caller's work is over (every group waited for): lent threads return.
  void close();

 private:
  struct Job {
    std::function<void()> fn;
    BorrowedGroup* group;
  };
  /// Runs a job taken off the queue (lock not held) and signs it off in its group.
  void run_job(Job& job);

  const int mThreads;
  std::mutex mMutex;
  std::condition_variable mChanged;  ///< a job was queued, a group finished, or the pool closed
  std::deque<Job> mQueue;
  bool mClosed = false;
  const HostExecutor* const mHost;  ///< the host whose threads it borrows
};

/// The borrowed pool whose constructs the calling thread's work goes to, and its index there; null
/// and -1 where its work goes elsewhere (oneTBB, the std::thread pool, or the calling thread).
inline thread_local BorrowedPool* t_borrowed = nullptr;
inline thread_local int t_borrowed_index = -1;
inline thread_local Membership* t_membership = nullptr;

/// Sends the calling thread's parallel constructs to `pool` (as thread `index`) for a scope; a null
/// pool sends them back to the executor they would use outside any borrowed pool.
class BorrowedScope {
 public:
  BorrowedScope(BorrowedPool* pool, int index) : mPool(t_borrowed), mIndex(t_borrowed_index) {
    t_borrowed = pool;
    t_borrowed_index = index;
  }
  ~BorrowedScope() {
    t_borrowed = mPool;
    t_borrowed_index = mIndex;
  }
  BorrowedScope(const BorrowedScope&) = delete;
  BorrowedScope& operator=(const BorrowedScope&) = delete;

 private:
  BorrowedPool* mPool;
  int mIndex;
};

/// Runs `f` on the calling thread, joined by the threads `host` lends until it returns: a pool of
/// `threads` (>= 1, the caller included), one range of one item enqueued per lent thread.
/// Exceptions thrown by `f` (or by jobs it waits for) propagate to the caller.
void run_on_host(HostExecutor& host, int threads, const std::function<void()>& f);

}  // namespace caliber::parallel::detail
