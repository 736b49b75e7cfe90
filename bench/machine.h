#pragma once
// A description of the machine a benchmark ran on, for committed results.

#include <fstream>
#include <string>
#include <thread>

namespace caliber::bench {

/// The CPU's model name from /proc/cpuinfo ("unknown CPU" elsewhere).
inline std::string cpu_model() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown CPU";
}

/// The compiler this was built with.
inline std::string compiler() {
#if defined(__clang__)
  return "clang " __VERSION__;
#else
  return "g++ " __VERSION__;
#endif
}

/// "CPU model, N hardware threads, compiler".
inline std::string machine_description() {
  return cpu_model() + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads, " + compiler();
}

}  // namespace caliber::bench
