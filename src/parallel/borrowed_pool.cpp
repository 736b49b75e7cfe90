// The threads a host lends for one Executor::execute (borrowed_pool.h).

#include "parallel/borrowed_pool.h"

#include <utility>

namespace caliber::parallel::detail {

Membership::Membership(BorrowedPool* p) : pool(p), outer(t_membership) { t_membership = this; }
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
  for (const Membership* m = t_membership; m != nullptr; m = m->outer) {
    if (m->pool == this) return;  // already works for this pool, further up its stack
  }
  const Membership member(this);
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

}  // namespace caliber::parallel::detail
