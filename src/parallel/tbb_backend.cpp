// The oneTBB backend of executor.h (tbb_backend.h).

#include "parallel/tbb_backend.h"

#include <tbb/global_control.h>

namespace caliber::parallel::native {
namespace {
/// The process's limit on oneTBB's threads (max_allowed_parallelism: the CPU affinity's count
/// unless a host's tbb::global_control lowers it).
int process_limit() {
  const std::size_t limit = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  return static_cast<int>(std::clamp<std::size_t>(limit, 1, 1u << 20));
}
}  // namespace

Workers::Workers(int threads) : mRequested(threads) {
  // An arena no wider than the limit in force, so that its slot indices stay below threads().
  if (threads > 1) mArena = std::make_unique<tbb::task_arena>(std::min(threads, process_limit()));
}

Workers::~Workers() = default;

int Workers::threads() const {
  if (mRequested == 1) return 1;
  const int arena = mArena ? mArena->max_concurrency() : tbb::this_task_arena::max_concurrency();
  return std::max(1, std::min(arena, process_limit()));
}

void Workers::execute(const std::function<void()>& f) {
  const int concurrency = threads();
  if (concurrency > 1 && mArena) {
    mArena->execute([&] {
      const ConcurrencyScope scope(concurrency);
      f();
    });
    return;
  }
  // The caller's arena (the jobs oneTBB runs go to it), or the calling thread alone.
  const ConcurrencyScope scope(concurrency);
  f();
}

int thread_index() {
  if (t_concurrency == 0) return -1;
  if (t_concurrency == 1) return 0;
  const int index = tbb::this_task_arena::current_thread_index();
  return index == tbb::task_arena::not_initialized ? -1 : index;
}

void parallel_for(std::size_t begin, std::size_t end, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& body) {
  // simple_partitioner: split down to the grain. The default (auto) partitioner stops splitting
  // early when nobody steals, so a thread would run ~16 consecutive items as one chunk. Even so the
  // halving hands out contiguous blocks: where the order matters, use for_each_in_order.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(begin, end, grain),
      [&body, c = t_concurrency](const tbb::blocked_range<std::size_t>& r) {
        const ConcurrencyScope scope(c);
        body(r.begin(), r.end());
      },
      tbb::simple_partitioner());
}

}  // namespace caliber::parallel::native
