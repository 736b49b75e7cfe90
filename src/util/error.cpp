// caliber::Error's message: one printable line of valid UTF-8, bounded (see caliber/error.h); and
// the same escaping for names and paths written into outputs (src/util/printable.h).

#include "caliber/error.h"

#include <cstdio>
#include <string_view>

#include "util/printable.h"

namespace caliber {
namespace {

/// The length of the valid UTF-8 sequence at text[i] (2 to 4 bytes; not overlong, no surrogate,
/// at most U+10FFFF), or 0 when there is none.
std::size_t utf8_sequence(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[i + k]); };
  const unsigned char b0 = byte(0);
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // the range of the second byte
  if (b0 >= 0xc2 && b0 <= 0xdf) {
    n = 2;
  } else if (b0 >= 0xe0 && b0 <= 0xef) {
    n = 3;
    if (b0 == 0xe0) lo = 0xa0;
    if (b0 == 0xed) hi = 0x9f;
  } else if (b0 >= 0xf0 && b0 <= 0xf4) {
    n = 4;
    if (b0 == 0xf0) lo = 0x90;
    if (b0 == 0xf4) hi = 0x8f;
  }
  if (n == 0 || i + n > text.size() || byte(1) < lo || byte(1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k) {
    if (byte(k) < 0x80 || byte(k) > 0xbf) return 0;
  }
  return n;
}

void escape(std::string& out, unsigned char c) {
  char hex[8];
  std::snprintf(hex, sizeof hex, "\\x%02x", c);
  out += hex;
}

/// `text` with bytes that are not UTF-8, and control characters unless `keep_controls`, as \xNN;
/// cut after `limit` bytes.
std::string escaped(std::string_view text, std::size_t limit, bool keep_controls) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    if (out.size() >= limit) return out + "...";
    const auto c = static_cast<unsigned char>(text[i]);
    const bool plain = c < 0x80 && (keep_controls || (c >= 0x20 && c < 0x7f));
    if (const std::size_t n = plain ? 1 : c >= 0x80 ? utf8_sequence(text, i) : 0; n > 0) {
      out.append(text.substr(i, n));
      i += n;
    } else {
      escape(out, c);
      ++i;
    }
  }
  return out;
}

}  // namespace

std::string printable(std::string_view text, std::size_t limit) { return escaped(text, limit, false); }

std::string utf8_or_escaped(std::string_view text) { return escaped(text, std::string_view::npos, true); }

std::size_t append_ascii_escaped(std::string& out, std::string_view text, std::size_t max_out) {
  std::size_t i = 0;
  for (; i < text.size() && out.size() < max_out; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      escape(out, c);
    }
  }
  return i;
}

namespace {

std::string message(const std::string& source, const std::string& problem) {
  constexpr std::size_t kSourceBytes = 300, kProblemBytes = 500;
  return source.empty() ? printable(problem, kProblemBytes)
                        : printable(source, kSourceBytes) + ": " + printable(problem, kProblemBytes);
}

}  // namespace

Error::Error(ErrorCode code, std::string source, const std::string& problem)
    : std::runtime_error(message(source, problem)), mCode(code), mSource(std::move(source)) {}

}  // namespace caliber
