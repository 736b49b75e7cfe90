// caliber::Error's message is one bounded line of valid UTF-8 whatever it quotes: a path or token
// with NUL, newline or bytes that are not UTF-8 is shown escaped, never cut short or passed raw to
// a terminal (or to Python, which gave an empty caliber.Error for invalid UTF-8).

#include <string>

#include <gtest/gtest.h>

#include "caliber/error.h"

namespace caliber {
namespace {

std::string what(const std::string& source, const std::string& problem) {
  return Error(ErrorCode::unreadable, source, problem).what();
}

TEST(ErrorMessage, ControlAndNonUtf8BytesAreEscaped) {
  EXPECT_EQ(what(std::string("a\0b.off", 7), "line 1\nline 2\t\x7f"), "a\\x00b.off: line 1\\x0aline 2\\x09\\x7f");
  EXPECT_EQ(what("caf\xe9.off", "x"), "caf\\xe9.off: x");                                   // Latin-1, not UTF-8
  EXPECT_EQ(what("caf\xc3\xa9.off", "\xe2\x82\xac 1"), "caf\xc3\xa9.off: \xe2\x82\xac 1");  // UTF-8 kept
  EXPECT_EQ(what("", "\xc0\xaf"), "\\xc0\\xaf");                                            // overlong '/'
  EXPECT_EQ(what("", "\xed\xa0\x80"), "\\xed\\xa0\\x80");                                   // a surrogate
  EXPECT_EQ(what("", "\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");                          // past U+10FFFF
  EXPECT_EQ(what("", "ok \xe2\x82"), "ok \\xe2\\x82");                                      // cut short
  EXPECT_EQ(what("", "\xf0\x9f\x98\x80"), "\xf0\x9f\x98\x80");                              // 4 bytes, valid
}

TEST(ErrorMessage, IsBoundedAndKeepsTheRawSource) {
  const std::string path(5000, 'p'), problem(100000, 'q');
  const Error e(ErrorCode::bad_value, path, problem);
  const std::string message = e.what();
  EXPECT_LE(message.size(), 820u);
  EXPECT_EQ(message.substr(0, 300) + "...: " + std::string(500, 'q') + "...", message);
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.code(), ErrorCode::bad_value);
  // An escape is never split by the cut.
  const std::string escapes = Error(ErrorCode::bad_value, "", std::string(1000, '\x01')).what();
  EXPECT_EQ(escapes.size(), 500u + 3u);
  EXPECT_EQ(escapes.substr(496), "\\x01...");
}

}  // namespace
}  // namespace caliber
