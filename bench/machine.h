#pragma once
// A one-line description of the machine a benchmark ran on, for committed results.

#include <fstream>
#include <string>
#include <thread>

namespace caliber::bench {

/// "CPU model, N hardware threads, compiler".
inline std::string machine_description() {
  std::string model = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads, " +
#if defined(__clang__)
         "clang "
#else
         "g++ "
#endif
         + std::string(__VERSION__);
}

}  // namespace caliber::bench
