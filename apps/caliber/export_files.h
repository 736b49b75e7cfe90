#pragma once
// caliber run --export DIR: files other tools open (MeshLab, CloudCompare, Blender, ParaView). For
// each chosen step, PLY files of the posed meshes, of the contacts (points, and normals as
// segments) and, on request, of every object's BVH boxes down to a depth (docs/exports.md).

#include <filesystem>
#include <string>
#include <vector>

#include "caliber/engine.h"
#include "caliber/world.h"

namespace caliber::cli {

struct ExportOptions {
  std::string dir;            ///< the folder (created if missing); empty: no export
  std::vector<int> steps{0};  ///< the steps to write
  int bvh_depth = -1;         ///< write BVH boxes down to this depth (-1: none)
};

/// The files an export will write (to check them against the run's inputs and other outputs).
[[nodiscard]] std::vector<std::string> export_paths(const ExportOptions& options);

/// Writes the chosen steps' files as the run reaches them.
class Exporter {
 public:
  /// Checks the options against the scene's step count and creates the folder. Throws
  /// caliber::Error naming the option (exit 2) on a step out of range, a depth below -1, or a
  /// folder that cannot be made or is a file.
  Exporter(ExportOptions options, int scene_steps);

  /// Whether step k is to be written.
  [[nodiscard]] bool wants(int k) const;

  /// Writes step<k>_objects.ply, step<k>_contacts.ply and (with a BVH depth) step<k>_bvh.ply.
  void write(const World& world, const StepResult& step) const;

  /// The files written so far.
  [[nodiscard]] const std::vector<std::string>& written() const { return mWritten; }

  /// Keeps what was written. Without it (a run that fails), the destructor removes the files
  /// written and the folders this exporter made.
  void commit() { mCommitted = true; }
  ~Exporter();
  Exporter(const Exporter&) = delete;
  Exporter& operator=(const Exporter&) = delete;

 private:
  ExportOptions mOptions;
  mutable std::vector<std::string> mWritten;
  std::vector<std::filesystem::path> mMadeFolders;
  bool mCommitted = false;
};

}  // namespace caliber::cli
