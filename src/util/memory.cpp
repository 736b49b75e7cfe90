// Memory the process may still take: /proc/meminfo's MemAvailable, within RLIMIT_AS.

#include "util/memory.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include <sys/resource.h>

namespace caliber::util {
namespace {

/// A field of /proc/self/status or /proc/meminfo in bytes ("VmSize:   1234 kB"), or UINT64_MAX.
std::uint64_t field_kib(const char* file, const std::string& name) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(name + ":", 0) != 0) continue;
    std::istringstream words(line.substr(name.size() + 1));
    std::uint64_t kib = 0;
    if (words >> kib) return kib * 1024;
  }
  return std::numeric_limits<std::uint64_t>::max();
}

}  // namespace

std::uint64_t available_memory() {
  std::uint64_t available = field_kib("/proc/meminfo", "MemAvailable");
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    const std::uint64_t used = field_kib("/proc/self/status", "VmSize");
    const std::uint64_t cap = static_cast<std::uint64_t>(limit.rlim_cur);
    const std::uint64_t left = used == std::numeric_limits<std::uint64_t>::max() ? cap : (cap > used ? cap - used : 0);
    available = std::min(available, left);
  }
  return available;
}

std::string format_bytes(double bytes) {
  char text[32];
  if (bytes >= 1024.0 * 1024 * 1024) {
    std::snprintf(text, sizeof text, "%.1f GiB", bytes / (1024.0 * 1024 * 1024));
  } else {
    std::snprintf(text, sizeof text, "%.0f MiB", bytes / (1024.0 * 1024));
  }
  return text;
}

}  // namespace caliber::util
