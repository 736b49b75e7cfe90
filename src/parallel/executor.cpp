// The executor seam (executor.h): what every backend shares. Where a host lends its threads the
// work goes to a borrowed pool (borrowed_pool.h); otherwise to the backend (tbb_backend.h or
// std_backend.h).

#include "parallel/executor.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <string>

#include "caliber/error.h"
#include "parallel/chunks.h"

namespace caliber::parallel {

Executor::Executor(int threads, HostExecutor* host) : mRequested(threads), mHost(host) {
  if (threads < 0) throw Error(ErrorCode::bad_value, "threads", "must be >= 0 (" + std::string(native::kZeroThreads) + ")");
  if (host == nullptr) mWorkers = std::make_unique<native::Workers>(threads);
}

Executor::~Executor() = default;

int Executor::threads() const { return mHost != nullptr ? host_threads() : mWorkers->threads(); }

void Executor::execute(const std::function<void()>& f) {
  if (mHost != nullptr) {
    // The count read for this call (threads() at its start), or read now.
    const int read = mHostThreads.exchange(0);
    detail::run_on_host(*mHost, read > 0 ? read : offered_threads(), f);
    return;
  }
  const detail::BorrowedScope outside(nullptr, -1);  // its constructs go to the backend, not a borrowed pool
  mWorkers->execute(f);
}

int Executor::offered_threads() const {
  // At most 1024, as EngineOptions::threads; at most the threads asked for, when asked.
  const int offered = std::clamp(mHost->thread_count(), 1, 1024);
  return mRequested > 0 ? std::min(mRequested, offered) : offered;
}

int Executor::host_threads() const {
  const int n = offered_threads();
  mHostThreads.store(n);
  return n;
}

JobGroup::~JobGroup() {
  try {
    wait();
  } catch (...) {  // NOLINT(bugprone-empty-catch): an unwaited group's error has nowhere to go
  }
}

void JobGroup::wait() {
  if (mBorrowed != nullptr) {
    mBorrowed->wait(mBorrowedJobs);
    return;
  }
  mGroup.wait();
  if (mError) std::rethrow_exception(std::exchange(mError, nullptr));
}

int current_thread_index() { return detail::t_borrowed != nullptr ? detail::t_borrowed_index : native::thread_index(); }

bool in_executor() { return detail::t_borrowed != nullptr || native::in_executor(); }

int concurrency() { return detail::t_borrowed != nullptr ? detail::t_borrowed->threads() : native::concurrency(); }

void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body) {
  if (begin >= end) return;
  grain = std::max<std::size_t>(grain, 1);
  if (end - begin <= grain) {
    body(begin, end);
  } else if (detail::t_borrowed != nullptr) {  // on the host's threads: chunks as jobs of the borrowed pool
    JobGroup group;
    detail::for_each_chunk(begin, end, grain,
                           [&](std::size_t lo, std::size_t hi) { group.run([&body, lo, hi] { body(lo, hi); }); });
    group.wait();
  } else if (native::parallel_here()) {
    native::parallel_for(begin, end, grain, body);
  } else {  // outside an executor, or a one-thread one: chunk by chunk, here
    detail::for_each_chunk(begin, end, grain, body);
  }
}

void for_each_in_order(std::size_t n, const std::function<void(std::size_t)>& body) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  const auto drain = [&] {
    for (std::size_t i = next.fetch_add(1, std::memory_order_relaxed); i < n && !failed.load(std::memory_order_relaxed);
         i = next.fetch_add(1, std::memory_order_relaxed)) {
      try {
        body(i);
      } catch (...) {
        failed.store(true, std::memory_order_relaxed);  // nobody takes another item
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  const std::size_t helpers = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(concurrency(), 1))) - (n > 0 ? 1 : 0);
  JobGroup group;
  for (std::size_t k = 0; k < helpers; ++k) group.run(drain);
  drain();
  group.wait();
  if (error) std::rethrow_exception(error);
}

}  // namespace caliber::parallel
