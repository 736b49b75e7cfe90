#pragma once
// SIGINT (Ctrl-C) and SIGTERM (kill, timeout, systemd, batch schedulers) during a long command
// (run, run --continuous, view, bench, refine): the handler only records the signal; the command
// stops after the step in progress, writes what it measured (or, where nothing can be written whole,
// removes what it began) and exits 128 + the signal's number: 130 for SIGINT, 143 for SIGTERM. So
// no temporary file is left behind, whenever the signal comes.

#include <atomic>
#include <csignal>

#include <signal.h>

#include "caliber/error.h"

namespace caliber::cli {

/// The first SIGINT or SIGTERM received while an InterruptGuard lives (0: none).
inline std::atomic<int> gSignal{0};

extern "C" inline void on_interrupt(int signal) {
  int none = 0;
  gSignal.compare_exchange_strong(none, signal);  // lock-free: safe in a signal handler
}

/// Whether a signal asked the command to stop.
[[nodiscard]] inline bool interrupted() { return gSignal.load() != 0; }

/// "SIGINT" or "SIGTERM": the signal that asked the command to stop.
[[nodiscard]] inline const char* interrupt_name() { return gSignal.load() == SIGTERM ? "SIGTERM" : "SIGINT"; }

/// The exit status of a command a signal stopped: 128 + the signal's number, as a shell reports a
/// process the signal ended.
[[nodiscard]] inline int interrupted_exit_code() { return 128 + gSignal.load(); }

/// Thrown where a signal stopped a command before it had begun its work (waiting for a pipe's
/// reader): the command reports it and exits interrupted_exit_code(), as a stopped run does.
class Stopped : public Error {
 public:
  using Error::Error;
};

/// SIGINT and SIGTERM handled for the lifetime of the object (the previous handlers restored
/// after). Made before the command opens (or creates) any output, and kept until its outputs are
/// in place; never two at once.
class InterruptGuard {
 public:
  InterruptGuard() {
    gSignal.store(0);
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;  // a write or a wait in progress goes on; the loops read the flag
    sigaction(SIGINT, &action, &mPreviousInt);
    sigaction(SIGTERM, &action, &mPreviousTerm);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &mPreviousInt, nullptr);
    sigaction(SIGTERM, &mPreviousTerm, nullptr);
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction mPreviousInt {};
  struct sigaction mPreviousTerm {};
};

}  // namespace caliber::cli
