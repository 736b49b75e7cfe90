#pragma once
// Outputs that are never lost or left half-written: every output path is checked before the work
// starts, written to a temporary file in the same folder, flushed and checked, then renamed into
// place. A write error is a caliber::Error naming the path (exit 2).

#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace caliber {
struct Scene;
}

namespace caliber::cli {

class OutputFile {
 public:
  /// Checks that `path` can be written (its folder exists and takes a new file; a directory is
  /// refused) and opens the temporary file beside it. A path that exists and is not a regular file
  /// (/dev/null, /dev/stdout, a pipe) is written directly. Throws caliber::Error naming `option`
  /// and the path.
  OutputFile(const std::string& path, const std::string& option);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Where to write.
  std::ostream& stream() { return mOut; }
  /// Flushes, checks, closes and renames into place. Throws caliber::Error naming the path when
  /// anything was not written (a full disk, an I/O error); the target is then left as it was.
  void commit();

 private:
  std::filesystem::path mPath;
  std::filesystem::path mTemp;  ///< empty when writing directly
  std::ofstream mOut;
  bool mDone = false;
};

/// (what, path) pairs: an option or an input's description, and the file it names.
using NamedFiles = std::vector<std::pair<std::string, std::string>>;

/// Refuses outputs that name the same file as each other or as an input: `outputs` and `inputs`
/// are (option, path) pairs, empty paths skipped. Throws caliber::Error naming both options.
/// Every command that writes calls it before it opens (or creates) anything.
void check_distinct_files(const NamedFiles& outputs, const NamedFiles& inputs);

/// The files a scene reads, for check_distinct_files: the scene file and every object's mesh.
[[nodiscard]] NamedFiles scene_inputs(const std::string& scene_file, const Scene& scene);

/// Flushes standard output and throws caliber::Error if anything written to it was lost (a full
/// disk, a closed pipe), so that a command never exits 0 after failing to write its answer.
void check_stdout();

}  // namespace caliber::cli
