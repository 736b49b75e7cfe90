#pragma once
/// \file
/// The one exception type the library throws for bad input.

#include "caliber/export.h"
#include <stdexcept>
#include <string>

namespace caliber {

/// What kind of bad input an Error reports.
enum class ErrorCode {
  file_not_found,  ///< the path does not exist or is not a regular file
  unreadable,      ///< the file exists but could not be read or parsed
  bad_value,       ///< a value is out of range or not finite (coordinate, pose, option)
  bad_index,       ///< a face refers to a vertex that does not exist
  empty_mesh,      ///< the input holds no triangle at all
  bad_argument,    ///< an API argument is invalid (for example a null model)
  out_of_memory,   ///< the input needs more memory than there is (the message says what was being done)
};

/// Thrown for every bad input: missing or malformed files, non-finite values, bad options.
/// `what()` is a complete message that names the source (file path or option) and the problem.
/// Nothing in the library crashes or returns a silent wrong answer on such input instead.
///
/// `what()` is one line of valid UTF-8 of bounded length, whatever the source and the problem
/// hold: control characters (newline and NUL included) and bytes that are not UTF-8 are written
/// as \xNN, and a source past 300 bytes or a problem past 500 is cut, ending in "...".
class CALIBER_EXPORT Error : public std::runtime_error {
 public:
  /// `source` names where the problem is (a file path, an option name); may be empty.
  Error(ErrorCode code, std::string source, const std::string& problem);

  /// The kind of problem.
  [[nodiscard]] ErrorCode code() const noexcept { return mCode; }
  /// The file path or option the problem is in.
  [[nodiscard]] const std::string& source() const noexcept { return mSource; }

 private:
  ErrorCode mCode;
  std::string mSource;
};

}  // namespace caliber
