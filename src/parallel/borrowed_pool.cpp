// The threads a host lends for one Executor::execute (borrowed_pool.h).

#include "parallel/borrowed_pool.h"

#include <utility>

#include "caliber/executor.h"

namespace caliber::parallel::detail {

Membership::Membership(BorrowedPool* p, int i) : pool(p), outer(t_membership), index(i) { t_membership = this; }
Membership::~Membership() { t_membership = outer; }

void BorrowedPool::run_job(Job& job) {
  std::exception_ptr error;
  try {
    job.fn();
  } catch (...) {
    error = std::current_exception();
  }
  job.fn = nullptr;
  const std::lock_guard<std::mutex> lock(mMutex);
  if (error && !job.group->error) job.group->error = error;
  // The group's owner may destroy it as soon as the lock is released: nothing touches it after.
  if (--job.group->pending == 0) mChanged.notify_all();
}

void BorrowedPool::submit(std::function<void()> fn, BorrowedGroup& group) {
  if (mThreads == 1) {  // nobody else could take it: run it at once, as outside any executor
    Job job{std::move(fn), &group};
    {
      const std::lock_guard<std::mutex> lock(mMutex);
      ++group.pending;
    }
    run_job(job);
    return;
  }
  {
    const std::lock_guard<std::mutex> lock(mMutex);
    mQueue.push_back(Job{std::move(fn), &group});  // first: a failed push leaves no job counted
    ++group.pending;
  }
  mChanged.notify_one();
}

void BorrowedPool::wait(BorrowedGroup& group) {
  std::unique_lock<std::mutex> lock(mMutex);
  while (group.pending > 0) {
    if (mQueue.empty()) {
      mChanged.wait(lock);
      continue;
    }
    Job job = std::move(mQueue.back());
    mQueue.pop_back();
    lock.unlock();
    run_job(job);
    lock.lock();
  }
  if (std::exception_ptr error = std::exchange(group.error, nullptr)) {
    lock.unlock();
    std::rethrow_exception(error);
  }
}

void BorrowedPool::lend(int index) {
  // A thread that already works for a caliber call, further up its stack (this pool's or another's:
  // a range of another call that a host runs inside finish()) does not join: it would stay until
  // that call is over, and the two calls could wait on each other.
  if (t_membership != nullptr) return;
  const Membership member(this, index);
  const BorrowedScope scope(this, index);
  std::unique_lock<std::mutex> lock(mMutex);
  for (;;) {
    mChanged.wait(lock, [&] { return mClosed || !mQueue.empty(); });
    if (mQueue.empty()) return;  // closed, nothing left
    Job job = std::move(mQueue.front());
    mQueue.pop_front();
    lock.unlock();
    run_job(job);
    lock.lock();
  }
}

void BorrowedPool::close() {
  {
    const std::lock_guard<std::mutex> lock(mMutex);
    mClosed = true;
  }
  mChanged.notify_all();
}

void run_on_host(HostExecutor& host, int threads, const std::function<void()>& f) {
  // Already working for a pool of this host's threads, of the same size (an executor used inside
  // its own work): its work goes to that pool, whose threads are all lent already.
  for (const Membership* m = t_membership; m != nullptr; m = m->outer) {
    if (m->pool->host() == &host && m->pool->threads() == threads) {
      const BorrowedScope scope(m->pool, m->index);
      f();
      return;
    }
  }
  BorrowedPool pool(threads, &host);
  // The caller works for the pool from here on: a range the host runs here (inline, or inside
  // finish()) returns at once. Its constructs go to the pool only while `f` runs: the host's own
  // code in enqueue() and finish() runs as it would outside caliber.
  const Membership member(&pool);
  const BorrowedScope outside(nullptr, -1);
  // The host's threads take the pool's jobs until it closes: one item each, after the caller's.
  // The job outlives finish(): the host may keep a reference to it.
  const HostExecutor::Job lent = [&pool](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) pool.lend(static_cast<int>(i) + 1);
  };
  void* handle = threads > 1 ? host.enqueue(lent, static_cast<std::size_t>(threads - 1), 1) : nullptr;
  std::exception_ptr error;
  try {
    const BorrowedScope scope(&pool, 0);
    f();
  } catch (...) {
    error = std::current_exception();
  }
  pool.close();
  if (handle != nullptr) host.finish(handle);
  if (error) std::rethrow_exception(error);
}

}  // namespace caliber::parallel::detail
