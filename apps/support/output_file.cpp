// Outputs written to a temporary file, checked, then renamed into place.

#include "output_file.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <system_error>

#include <fcntl.h>
#include <unistd.h>

#include "caliber/error.h"
#include "caliber/scene.h"
#include "interrupt.h"

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

/// The system's reason for the call that just failed (read at once, before anything else sets errno).
std::string system_reason() { return errno != 0 ? std::strerror(errno) : "the system gave no reason"; }

/// The temporary file's name for `name` in its folder: ".NAME.caliber-PID-N.tmp", NAME cut so that
/// the whole stays within the 255 bytes a file name may take (a long name that is valid stays
/// writable), N counting this process's outputs (two long names cut to the same prefix get two).
std::string temporary_name(const std::string& name) {
  constexpr std::size_t kNameMax = 255;
  static std::atomic<unsigned> outputs{0};
  const std::string suffix = ".caliber-" + std::to_string(::getpid()) + "-" + std::to_string(outputs++) + ".tmp";
  std::string temporary(".");
  temporary.append(name, 0, kNameMax - 1 - suffix.size());
  return temporary + suffix;
}

/// Why `folder` cannot hold a new file: it does not exist, it is not a folder, or the reason the
/// system gives (a folder that cannot be searched, say). Empty when it is a folder.
std::string folder_problem(const std::filesystem::path& folder) {
  std::error_code ec;
  const auto status = std::filesystem::status(folder, ec);
  if (std::filesystem::is_directory(status)) return "";
  if (status.type() == std::filesystem::file_type::not_found) return "no folder " + folder.string();
  if (std::filesystem::exists(status)) return folder.string() + " is not a folder";
  return "folder " + folder.string() + ": " + ec.message();
}

/// Waits until a reader has opened the named pipe `path`, so that opening it to write does not
/// block where a signal could not stop it (the handlers restart system calls): a non-blocking
/// open every 20 ms, until one succeeds or SIGINT or SIGTERM comes (then an Error, which the
/// command reports and exits 128 + the signal's number on). Returns that open's descriptor, for
/// the caller to close once its own open has returned: until then the reader sees a writer, not
/// the end of the pipe.
int wait_for_reader(const std::filesystem::path& path, const std::string& option) {
  for (bool told = false;; told = true) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd >= 0) return fd;
    if (errno != ENXIO) fail(path, "cannot be opened for writing (" + option + "): " + system_reason());
    if (interrupted()) {
      throw Stopped(ErrorCode::unreadable, path.string(),
                    std::string("no reader opened the pipe (") + option + ") before " + interrupt_name());
    }
    if (!told) std::fprintf(stderr, "caliber: waiting for a reader of the pipe %s (%s)\n", path.c_str(), option.c_str());
    ::usleep(20000);
  }
}

}  // namespace

OutputFile::OutputFile(const std::string& path, const std::string& option) : mPath(path) {
  if (path.empty()) throw Error(ErrorCode::bad_value, option, "needs a file name");
  std::error_code ec;
  const auto status = std::filesystem::status(mPath, ec);
  // A name too long, a folder that cannot be searched: refused now, for the reason the system gives.
  if (ec && status.type() != std::filesystem::file_type::not_found)
    fail(mPath, "cannot be written (" + option + "): " + ec.message());
  if (!ec && std::filesystem::is_directory(status)) fail(mPath, "is a directory (" + option + " names the file to write)");
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    const int held = status.type() == std::filesystem::file_type::fifo ? wait_for_reader(mPath, option) : -1;
    errno = 0;
    mOut.open(mPath, std::ios::binary | std::ios::trunc);  // a device or a pipe: no rename possible
    const std::string why = mOut ? std::string() : system_reason();
    if (held >= 0) ::close(held);
    if (!mOut) fail(mPath, "cannot be opened for writing (" + option + "): " + why);
    return;
  }
  const std::filesystem::path folder = mPath.has_parent_path() ? mPath.parent_path() : std::filesystem::path(".");
  if (const std::string problem = folder_problem(folder); !problem.empty()) {
    fail(mPath, "cannot be written (" + option + "): " + problem);
  }
  mTemp = folder / temporary_name(mPath.filename().string());
  errno = 0;
  mOut.open(mTemp, std::ios::binary | std::ios::trunc);
  if (!mOut) {
    const std::string why = system_reason();
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
    const std::string why = ec.message();  // before the removal below sets ec again
    std::filesystem::remove(mTemp, ec);
    fail(mPath, "could not be put in place: " + why);
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
