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

/// Appends `text` to `out` with every byte outside printable ASCII as \xNN, while `out` is shorter
/// than `max_out` bytes; returns how many bytes of `text` went in (a quoted token, an importer's
/// message).
std::size_t append_ascii_escaped(std::string& out, std::string_view text, std::size_t max_out = std::string::npos);

}  // namespace caliber
