// Outputs written to a temporary file, checked, then renamed into place.

#include "output_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <system_error>

#include <unistd.h>

#include "caliber/error.h"
#include "caliber/scene.h"

namespace caliber::cli {
namespace {

std::filesystem::path canonical_or_same(const std::filesystem::path& p) {
  std::error_code ec;
  const auto c = std::filesystem::weakly_canonical(p, ec);
  return ec ? std::filesystem::absolute(p) : c;
}

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& problem) {
  throw Error(ErrorCode::unreadable, path.string(), problem);
}

}  // namespace

OutputFile::OutputFile(const std::string& path, const std::string& option) : mPath(path) {
  if (path.empty()) throw Error(ErrorCode::bad_value, option, "needs a file name");
  std::error_code ec;
  const auto status = std::filesystem::status(mPath, ec);
  if (!ec && std::filesystem::is_directory(status)) fail(mPath, "is a directory (" + option + " names the file to write)");
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    mOut.open(mPath, std::ios::binary | std::ios::trunc);  // a device or a pipe: no rename possible
    if (!mOut) fail(mPath, "cannot be opened for writing (" + option + "): " + std::strerror(errno));
    return;
  }
  const std::filesystem::path folder = mPath.has_parent_path() ? mPath.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(folder, ec)) fail(mPath, "cannot be written (" + option + "): no folder " + folder.string());
  std::string name = ".";
  name += mPath.filename().string();
  name += ".caliber-";
  name += std::to_string(::getpid());
  name += ".tmp";
  mTemp = folder / name;
  mOut.open(mTemp, std::ios::binary | std::ios::trunc);
  if (!mOut) {
    const std::string why = std::strerror(errno);
    mTemp.clear();
    fail(mPath, "cannot be written (" + option + "): " + why);
  }
}

OutputFile::~OutputFile() {
  if (mDone || mTemp.empty()) return;
  mOut.close();
  std::error_code ec;
  std::filesystem::remove(mTemp, ec);
}

void OutputFile::commit() {
  mOut.flush();
  const bool written = static_cast<bool>(mOut);
  mOut.close();
  if (!written || mOut.fail()) {
    const std::string why = errno != 0 ? std::strerror(errno) : "write error";
    if (!mTemp.empty()) {
      std::error_code ec;
      std::filesystem::remove(mTemp, ec);
    }
    mDone = true;
    fail(mPath, "could not be written completely: " + why);
  }
  mDone = true;
  if (mTemp.empty()) return;
  std::error_code ec;
  std::filesystem::rename(mTemp, mPath, ec);
  if (ec) {
    std::filesystem::remove(mTemp, ec);
    fail(mPath, "could not be put in place: " + ec.message());
  }
}

void check_distinct_files(const NamedFiles& outputs, const NamedFiles& inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].second.empty()) continue;
    const auto mine = canonical_or_same(outputs[i].second);
    // Two outputs may share a device or a pipe (--json /dev/null --contacts /dev/null), not a file.
    std::error_code ec;
    const bool shareable = std::filesystem::exists(mine, ec) && !std::filesystem::is_regular_file(mine, ec);
    for (std::size_t j = 0; j < i && !shareable; ++j) {
      if (!outputs[j].second.empty() && canonical_or_same(outputs[j].second) == mine) {
        throw Error(ErrorCode::bad_value, outputs[i].first,
                    "names the same file as " + outputs[j].first + " (" + outputs[i].second + "); give each output its own file");
      }
    }
    for (const auto& [option, path] : inputs) {
      if (!path.empty() && canonical_or_same(path) == mine) {
        throw Error(ErrorCode::bad_value, outputs[i].first,
                    "would overwrite the input " + option + " (" + path + "); write the output elsewhere");
      }
    }
  }
}

NamedFiles scene_inputs(const std::string& scene_file, const Scene& scene) {
  NamedFiles inputs{{"scene file", scene_file}};
  for (const SceneObject& o : scene.objects) inputs.emplace_back("mesh of object '" + o.name + "'", o.mesh.string());
  return inputs;
}

void check_stdout() {
  std::cout.flush();
  if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
    throw Error(ErrorCode::unreadable, "standard output", std::string("could not be written: ") + std::strerror(errno));
  }
}

}  // namespace caliber::cli
