#pragma once
/// \file
/// The std::thread backend of executor.h (`-DCALIBER_EXECUTOR=std`, forced by
/// `-DCALIBER_SANITIZE=thread`): an executor of N threads is a host (caliber/executor.h) over N - 1
/// threads of its own, lent to each execute() as any host's are (borrowed_pool.h). Every
/// synchronization is a std::mutex / std::condition_variable, so ThreadSanitizer sees all of it:
/// Debian's libtbb is not instrumented, and under TSan its own hand-offs look like races, which
/// would hide the real ones in caliber. Slower, and not work stealing in the strict sense (waiting
/// threads help from one shared queue), but it runs the same code paths. `threads` = 0 means the
/// machine's hardware threads. All of an executor's parallel work goes to its pool: outside one,
/// the constructs below run on the calling thread.

#include <algorithm>
#include <cstddef>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string_view>
#include <thread>
#include <utility>

namespace caliber::parallel::native {

inline constexpr std::string_view kName = "std::thread";
/// What `threads` = 0 means, for the error on a negative count.
inline constexpr std::string_view kZeroThreads = "0: the machine's hardware threads";

/// Never: this backend's parallel work runs in the pools of borrowed_pool.h.
constexpr bool parallel_here() { return false; }
inline int thread_index() { return -1; }
inline int concurrency() { return 1; }
inline bool in_executor() { return false; }

class ThreadPoolHost;

/// The threads of an executor without a host: a host over threads of its own.
class Workers {
 public:
  /// `threads` >= 0, as Executor's (0: the machine's hardware threads).
  explicit Workers(int threads);
  ~Workers();
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  [[nodiscard]] int threads() const { return mThreads; }
  void execute(const std::function<void()>& f);

 private:
  int mThreads;
  std::unique_ptr<ThreadPoolHost> mHost;
};

/// Jobs outside any pool: run at once, on the calling thread.
class Group {
 public:
  template <class F>
  void run(F&& f) {
    std::forward<F>(f)();
  }
  void wait() {}
};

/// Chunks of at most `grain`, one after the other on the calling thread.
void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body);

template <class F>
void parallel_for_each(std::size_t begin, std::size_t end, F& f) {
  for (std::size_t i = begin; i != end; ++i) f(i);
}

template <class It, class Less>
void parallel_sort(It first, It last, Less less) {
  std::sort(first, last, less);
}

template <class T>
class PerThreadSlots {
 public:
  T& local() {
    const std::lock_guard<std::mutex> lock(mMutex);
    auto [it, inserted] = mSlots.try_emplace(std::this_thread::get_id(), nullptr);
    if (inserted) it->second = &mStorage.emplace_back();
    return *it->second;
  }
  template <class F>
  void for_each(F&& f) {
    const std::lock_guard<std::mutex> lock(mMutex);
    for (T& t : mStorage) f(t);
  }

 private:
  std::mutex mMutex;
  std::map<std::thread::id, T*> mSlots;
  std::list<T> mStorage;
};

}  // namespace caliber::parallel::native
