#pragma once
// SIGINT during a run: the run stops after the step in progress and writes what it measured.

#include <atomic>
#include <csignal>

namespace caliber::cli {

/// Set by SIGINT while an InterruptGuard lives.
inline std::atomic<bool> gInterrupted{false};

extern "C" inline void on_interrupt(int) { gInterrupted.store(true); }

/// SIGINT handled for the lifetime of the object (the previous handler restored after).
struct InterruptGuard {
  InterruptGuard() {
    gInterrupted.store(false);
    previous = std::signal(SIGINT, on_interrupt);
  }
  ~InterruptGuard() { std::signal(SIGINT, previous); }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  void (*previous)(int) = SIG_DFL;
};

}  // namespace caliber::cli
