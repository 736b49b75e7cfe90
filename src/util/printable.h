#pragma once
// Text from outside (paths, object names, tokens of a file) made safe to write: caliber::Error's
// messages use printable(); JSON outputs use utf8_or_escaped() (JSON escapes control characters
// itself, but cannot hold bytes that are not UTF-8); one-line text formats (a PLY header comment)
// use printable().

#include <string>
#include <string_view>

namespace caliber {

/// `text` with control characters (newline and NUL included) and bytes that are not UTF-8 written
/// as \xNN, valid UTF-8 kept; cut after `limit` bytes (never inside an escape or a character),
/// then "...".
[[nodiscard]] std::string printable(std::string_view text, std::size_t limit = std::string_view::npos);

/// `text` with only the bytes that are not UTF-8 written as \xNN: valid UTF-8, for JSON strings.
[[nodiscard]] std::string utf8_or_escaped(std::string_view text);

}  // namespace caliber
