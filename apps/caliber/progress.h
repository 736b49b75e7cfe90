#pragma once
// A progress bar on a terminal, plain lines elsewhere (logs, CI, pipes).

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
      if (done == mTotal) std::fputc('\n', stderr);
    } else {
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    std::fflush(stderr);
  }

 private:
  std::size_t mTotal;
  bool mTerminal;
};

}  // namespace caliber::cli
