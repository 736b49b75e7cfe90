#pragma once
// The text mesh formats (OFF, OBJ) as lines of whitespace-separated tokens, and the strict number
// parsing both readers share: a token is a number only when all of it is one, as written.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace caliber::mesh_io {

/// A file's lines of tokens: comments ('#' to the end of the line) and blank lines dropped, each
/// line remembering its number for error messages. Flat arrays, so that a file of millions of
/// lines costs no allocation per line.
struct Lines {
  std::vector<std::string_view> tokens;
  std::vector<std::size_t> first{0};  ///< line l's tokens are tokens[first[l] .. first[l + 1])
  std::vector<std::size_t> number;    ///< line l's number in the file (1-based: its first line)

  [[nodiscard]] std::size_t size() const { return number.size(); }
  [[nodiscard]] bool empty() const { return number.empty(); }
  [[nodiscard]] std::size_t count(std::size_t l) const { return first[l + 1] - first[l]; }
  [[nodiscard]] std::string_view token(std::size_t l, std::size_t k) const { return tokens[first[l] + k]; }
};

/// Splits `data` (which must outlive the result) into lines of tokens. Lines end with LF, CR LF or
/// a lone CR; a leading UTF-8 byte order mark is skipped. With `backslash_joins` (OBJ), a line
/// whose last character is '\' goes on on the next line.
[[nodiscard]] Lines tokenize(const std::string& data, bool backslash_joins = false);

/// The whole token as a double: an optional sign ('+' or '-'), then decimal digits with an
/// optional point and exponent ("1e5", ".5", "-0."), or "inf"/"nan". Nothing else: "1d2", "0x10",
/// "2abc" and "1-2" are not numbers. Empty when the token is not one.
[[nodiscard]] std::optional<double> parse_number(std::string_view token);

/// The whole token as a signed integer (optional sign, then decimal digits); empty when it is not
/// one or does not fit in 64 bits.
[[nodiscard]] std::optional<std::int64_t> parse_integer(std::string_view token);

/// The file's bytes (throws caliber::Error naming `path` when it cannot be read).
[[nodiscard]] std::string read_file(const std::string& path);

}  // namespace caliber::mesh_io
