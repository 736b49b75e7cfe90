#pragma once
// A folder of its own for one test process, removed when the test ends.

#include <filesystem>
#include <string>

#include <unistd.h>

namespace caliber::test {

/// Creates <tmp>/caliber_<name>_<pid> on construction and removes it on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : mPath(std::filesystem::temp_directory_path() / ("caliber_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(mPath);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(mPath, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  /// The folder.
  [[nodiscard]] const std::filesystem::path& path() const { return mPath; }

 private:
  std::filesystem::path mPath;
};

}  // namespace caliber::test
