#pragma once
// A host executor of N threads for tests (caliber/executor.h): N - 1 threads of its own and the
// caller, one queue of ranges, whatever the machine's core count.

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "caliber/executor.h"

namespace caliber::test {

/// A host of N threads (N - 1 of its own), one queue of ranges, each handle counting its ranges.
class PoolHost final : public HostExecutor {
 public:
  explicit PoolHost(int threads) {
    for (int t = 1; t < threads; ++t) mThreads.emplace_back([this, t] { work(t); });
  }
  ~PoolHost() override {
    {
      const std::lock_guard<std::mutex> lock(mMutex);
      mStop = true;
    }
    mChanged.notify_all();
    for (std::thread& t : mThreads) t.join();
  }
  int thread_count() const override { return static_cast<int>(mThreads.size()) + 1; }
  void* enqueue(const Job& job, std::size_t count, std::size_t grain) override {
    auto* left = new std::size_t(0);
    {
      const std::lock_guard<std::mutex> lock(mMutex);
      for (std::size_t b = 0; b < count; b += grain, ++*left) mQueue.push_back({&job, left, b, std::min(count, b + grain)});
    }
    mChanged.notify_all();
    return left;
  }
  void finish(void* handle) override {
    auto* left = static_cast<std::size_t*>(handle);
    std::unique_lock<std::mutex> lock(mMutex);
    while (*left > 0) {
      if (mQueue.empty()) {
        mChanged.wait(lock);
      } else {
        run_one(lock, 0);
      }
    }
    delete left;
  }
  /// The OS threads that ran a range.
  std::set<std::thread::id> workers() {
    const std::lock_guard<std::mutex> lock(mMutex);
    return mRan;
  }

 private:
  struct Range {
    const Job* job;
    std::size_t* left;
    std::size_t begin, end;
  };
  void run_one(std::unique_lock<std::mutex>& lock, int worker) {
    const Range r = mQueue.front();
    mQueue.pop_front();
    mRan.insert(std::this_thread::get_id());
    lock.unlock();
    (*r.job)(r.begin, r.end, worker);
    lock.lock();
    if (--*r.left == 0) mChanged.notify_all();
  }
  void work(int worker) {
    std::unique_lock<std::mutex> lock(mMutex);
    for (;;) {
      mChanged.wait(lock, [&] { return mStop || !mQueue.empty(); });
      if (mQueue.empty()) return;
      run_one(lock, worker);
    }
  }
  std::mutex mMutex;
  std::condition_variable mChanged;
  std::deque<Range> mQueue;
  std::set<std::thread::id> mRan;
  std::vector<std::thread> mThreads;
  bool mStop = false;
};

}  // namespace caliber::test
