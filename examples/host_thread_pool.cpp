// A host with its own thread pool lends its threads to caliber (caliber/executor.h): the engine and
// the build run on the pool's threads and create none of their own. Checks, for every method, that
// the process has the same threads before and after, and that the contacts are the sequential
// engine's (exit 1 otherwise).
//   host_thread_pool

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include <caliber/caliber.h>
#include <caliber/procedural.h>

/// The host's pool: N threads taking ranges of items from one queue. enqueue() queues a call's
/// ranges; finish() runs queued ranges on the calling thread until that call's are all done.
class ThreadPool final : public caliber::HostExecutor {
 public:
  explicit ThreadPool(int threads) {
    for (int t = 1; t < threads; ++t) mThreads.emplace_back([this, t] { work(t); });
  }
  ~ThreadPool() override {
    {
      const std::lock_guard<std::mutex> lock(mMutex);
      mStop = true;
    }
    mChanged.notify_all();
    for (std::thread& t : mThreads) t.join();
  }
  int thread_count() const override { return static_cast<int>(mThreads.size()) + 1; }
  void* enqueue(const Job& job, std::size_t count, std::size_t grain) override {
    auto* call = new Call{&job, 0};
    {
      const std::lock_guard<std::mutex> lock(mMutex);
      for (std::size_t begin = 0; begin < count; begin += grain, ++call->left) {
        mQueue.push_back({call, begin, std::min(count, begin + grain)});
      }
    }
    mChanged.notify_all();
    return call;
  }
  void finish(void* handle) override {
    auto* call = static_cast<Call*>(handle);
    std::unique_lock<std::mutex> lock(mMutex);
    while (call->left > 0) {
      if (!mQueue.empty()) {
        run_one(lock, 0);
      } else {
        mChanged.wait(lock);
      }
    }
    delete call;
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
  void run_one(std::unique_lock<std::mutex>& lock, int worker) {
    const Range r = mQueue.front();
    mQueue.pop_front();
    lock.unlock();
    (*r.call->job)(r.begin, r.end, worker);
    lock.lock();
    if (--r.call->left == 0) mChanged.notify_all();
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
  std::vector<std::thread> mThreads;
  bool mStop = false;
};

static std::size_t os_threads() {
  std::size_t n = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) n += entry.is_directory();
  return n;
}

/// A torus and twelve spheres just off its outer rim, built on `host`'s threads; the broad phase
/// picks the pairs.
static caliber::Frame make_frame(caliber::HostExecutor* host) {
  caliber::BuildOptions build;
  build.host = host;
  caliber::Frame frame;
  frame.models = {caliber::build_model(caliber::make_torus(1.0, 0.3, 64, 32), build)};
  frame.poses = {caliber::Pose{}};
  const auto sphere = caliber::build_model(caliber::make_sphere(0.3, 24, 48), build);
  for (int i = 0; i < 12; ++i) {
    caliber::Pose pose;
    pose.translation = {1.605 * std::cos(i * 0.5236), 1.605 * std::sin(i * 0.5236), 0.0};
    frame.models.push_back(sphere);
    frame.poses.push_back(pose);
  }
  frame.request.kind = caliber::QueryKind::contact;
  frame.request.tolerance = 0.02;
  frame.pairs = caliber::broad_phase(frame.models, frame.poses, caliber::reach(frame.request));
  return frame;
}

static bool same(const caliber::StepResult& x, const caliber::StepResult& y) {
  if (x.contacts.size() != y.contacts.size()) return false;
  for (std::size_t i = 0; i < x.contacts.size(); ++i) {
    const caliber::Contact &p = x.contacts[i], &q = y.contacts[i];
    if (p.object_a != q.object_a || p.object_b != q.object_b || p.tri_a != q.tri_a || p.tri_b != q.tri_b ||
        p.point_a != q.point_a || p.point_b != q.point_b)
      return false;
  }
  return true;
}

int main() {
  caliber::EngineOptions sequential;
  sequential.method = caliber::Method::sequential;
  ThreadPool pool(4);
  const std::size_t before = os_threads();
  const caliber::Frame frame = make_frame(&pool);
  const caliber::StepResult reference = caliber::Engine(sequential).step(frame);
  bool ok = !reference.contacts.empty();
  for (const caliber::Method method : {caliber::Method::exploitation, caliber::Method::stealing, caliber::Method::aposteriori,
                                       caliber::Method::apriori, caliber::Method::hybrid}) {
    caliber::EngineOptions options;
    options.method = method;
    options.host = &pool;  // the engine runs on the pool's threads
    caliber::Engine engine(options);
    const bool equal = same(engine.step(frame), reference);
    std::printf("%s on %d threads of the host's pool: %s\n", std::string(caliber::to_string(method)).c_str(), engine.threads(),
                equal ? "the sequential engine's contacts" : "DIFFERENT contacts");
    ok = ok && equal;
  }
  const std::size_t after = os_threads();
  std::printf("%zu contacts; process threads %zu before, %zu after: %s\n", reference.contacts.size(), before, after,
              ok && after == before ? "ok" : "FAILED");
  return ok && after == before ? 0 : 1;
}
