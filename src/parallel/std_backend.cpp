// The std::thread backend of executor.h (std_backend.h): a host over threads of its own.

#include "parallel/std_backend.h"

#include <condition_variable>
#include <deque>
#include <vector>

#include "caliber/executor.h"
#include "parallel/borrowed_pool.h"
#include "parallel/chunks.h"

namespace caliber::parallel::native {

/// threads - 1 workers taking ranges from one queue. finish() runs the queued ranges of its own
/// call on the calling thread until they are all done: a call made from a worker (an executor used
/// inside another's work) finishes even while every worker is busy.
class ThreadPoolHost final : public HostExecutor {
 public:
  explicit ThreadPoolHost(int threads) : mThreads(threads) {
    try {
      for (int t = 1; t < threads; ++t) mWorkers.emplace_back([this, t] { work(t); });
    } catch (...) {  // a thread that could not be made: stop those that were, then report it
      stop();
      throw;
    }
  }
  ~ThreadPoolHost() override { stop(); }
  ThreadPoolHost(const ThreadPoolHost&) = delete;
  ThreadPoolHost& operator=(const ThreadPoolHost&) = delete;

  [[nodiscard]] int thread_count() const override { return mThreads; }

  void* enqueue(const Job& job, std::size_t count, std::size_t grain) override {
    auto call = std::make_unique<Call>(Call{&job, 0});
    {
      const std::lock_guard<std::mutex> lock(mMutex);
      for (std::size_t begin = 0; begin < count; begin += grain, ++call->left) {
        mQueue.push_back({call.get(), begin, std::min(count, begin + grain)});
      }
    }
    mChanged.notify_all();
    return call.release();
  }

  void finish(void* handle) override {
    const std::unique_ptr<Call> call(static_cast<Call*>(handle));
    std::unique_lock<std::mutex> lock(mMutex);
    while (call->left > 0) {
      const auto own = std::find_if(mQueue.begin(), mQueue.end(), [&](const Range& r) { return r.call == call.get(); });
      if (own == mQueue.end()) {
        mChanged.wait(lock);
        continue;
      }
      const Range range = *own;
      mQueue.erase(own);
      run(lock, range, 0);
    }
  }

 private:
  struct Call {
    const Job* job;
    std::size_t left;  ///< ranges not yet done
  };
  struct Range {
    Call* call;
    std::size_t begin, end;
  };

  /// Stops the workers made so far and joins them.
  void stop() {
    {
      const std::lock_guard<std::mutex> lock(mMutex);
      mStop = true;
    }
    mChanged.notify_all();
    for (std::thread& t : mWorkers) t.join();
  }

  /// Runs `range` with the lock released; signs it off in its call.
  void run(std::unique_lock<std::mutex>& lock, const Range& range, int worker) {
    lock.unlock();
    (*range.call->job)(range.begin, range.end, worker);
    lock.lock();
    if (--range.call->left == 0) mChanged.notify_all();
  }

  void work(int worker) {
    std::unique_lock<std::mutex> lock(mMutex);
    for (;;) {
      mChanged.wait(lock, [&] { return mStop || !mQueue.empty(); });
      if (mQueue.empty()) return;  // stopping, nothing left
      const Range range = mQueue.front();
      mQueue.pop_front();
      run(lock, range, worker);
    }
  }

  const int mThreads;
  std::mutex mMutex;
  std::condition_variable mChanged;  ///< a range was queued or done, or the pool stops
  std::deque<Range> mQueue;
  std::vector<std::thread> mWorkers;
  bool mStop = false;
};

Workers::Workers(int threads)
    : mThreads(threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))),
      mHost(std::make_unique<ThreadPoolHost>(mThreads)) {}

Workers::~Workers() = default;

void Workers::execute(const std::function<void()>& f) { detail::run_on_host(*mHost, mThreads, f); }

void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body) {
  detail::for_each_chunk(begin, end, grain, body);
}

}  // namespace caliber::parallel::native
