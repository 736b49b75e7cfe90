#pragma once
/// \file
/// A host's own job system, lent to caliber (EngineOptions::host, BuildOptions::host): caliber then
/// creates no thread and runs its parallel work only on the threads the host gives it, for the
/// length of each call. In the spirit of Box2D v3's enqueueTask / finishTask callbacks and Jolt's
/// JobSystem: an OpenMP program, a game engine or a simulator implements these three functions
/// over its scheduler (examples/host_openmp.cpp, examples/host_thread_pool.cpp).

#include <cstddef>
#include <functional>

#include "caliber/export.h"

namespace caliber {

/// The host's side of the contract. caliber calls it from the thread that called it (a step, a
/// batch, a build), one call at a time per engine. For each call it reads thread_count() once
/// (at most 1024 threads are taken) and enqueues that many ranges less one, of one item each: each
/// range keeps its thread working for caliber until the call's work is over, and the calling thread
/// works too. enqueue() and finish() must not throw once a range is queued.
class CALIBER_EXPORT HostExecutor {
 public:
  virtual ~HostExecutor() = default;

  /// The most threads that may work for caliber at once, the calling thread included (>= 1; 1:
  /// caliber runs on the calling thread alone).
  [[nodiscard]] virtual int thread_count() const = 0;

  /// A range of items: job(begin, end, worker) runs items [begin, end) on one thread; `worker` is
  /// the host's index of that thread, in [0, thread_count()).
  using Job = std::function<void(std::size_t begin, std::size_t end, int worker)>;

  /// Starts `job` over the items [0, count), in ranges of at least `grain` items, on the host's
  /// threads, and returns without waiting for them: a handle for finish(). Or runs every range
  /// itself, on the calling thread, before returning, and answers nullptr ("ran inline"). It must
  /// not wait for ranges that run on other threads: caliber's work starts once it returns. `job`
  /// stays valid until finish(handle) returns, so the host may keep a reference to it.
  [[nodiscard]] virtual void* enqueue(const Job& job, std::size_t count, std::size_t grain) = 0;

  /// Waits until every range of `handle` (from enqueue) has run; the calling thread may run some
  /// of them meanwhile.
  virtual void finish(void* handle) = 0;
};

}  // namespace caliber
