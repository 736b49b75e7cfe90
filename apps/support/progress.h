#pragma once
// A progress bar on a terminal, plain lines elsewhere (logs, CI, pipes): every unit's line for the
// first 100, then at most one a second and the last, so that a run of a million steps does not
// write a million lines.

#include <chrono>
#include <cstdio>
#include <string>

#include <unistd.h>

namespace caliber::cli {

/// Reports progress of `total` units of work on stderr.
class Progress {
 public:
  explicit Progress(std::size_t total) : mTotal(total), mTerminal(isatty(STDERR_FILENO) != 0) {}

  /// Whether the output is a terminal (a bar) rather than plain lines.
  [[nodiscard]] bool terminal() const { return mTerminal; }

  /// Reports that `done` units are finished; `line` describes the last one.
  void update(std::size_t done, const std::string& line) const {
    if (mTerminal) {
      constexpr int kWidth = 30;
      const int filled = mTotal ? static_cast<int>(kWidth * done / mTotal) : kWidth;
      std::fprintf(stderr, "\r[%s%s] %zu/%zu %s\033[K", std::string(filled, '#').c_str(),
                   std::string(kWidth - filled, '.').c_str(), done, mTotal, line.c_str());
      mOpen = done != mTotal;
      if (!mOpen) std::fputc('\n', stderr);
    } else {
      const auto now = std::chrono::steady_clock::now();
      if (++mLines > kEveryLine && done != mTotal && now - mLast < std::chrono::seconds(1)) return;
      mLast = now;
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    std::fflush(stderr);
  }

  /// Ends the bar's line when the work stopped short of the total (a signal stopped it), so that
  /// what is written next starts on a line of its own.
  void end() const {
    if (!mOpen) return;
    mOpen = false;
    std::fputc('\n', stderr);
    std::fflush(stderr);
  }

 private:
  static constexpr std::size_t kEveryLine = 100;
  std::size_t mTotal;
  bool mTerminal;
  mutable std::size_t mLines = 0;
  mutable bool mOpen = false;  ///< a bar is on the terminal's last line, not ended
  mutable std::chrono::steady_clock::time_point mLast{};
};

}  // namespace caliber::cli
