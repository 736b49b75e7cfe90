// Tokens and numbers of the text mesh formats (OFF, OBJ): see text_lines.h.

#include "mesh/text_lines.h"

#include <cctype>
#include <charconv>
#include <fstream>
#include <iterator>

#include "caliber/error.h"

namespace caliber::mesh_io {
namespace {

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

/// `token` without one leading '+' (std::from_chars takes '-' but not '+'), or empty when the
/// token is only a sign or has more than one.
std::optional<std::string_view> unsigned_part(std::string_view token) {
  const bool plus = !token.empty() && token[0] == '+';
  if (plus) token.remove_prefix(1);
  const bool minus = !token.empty() && token[0] == '-';
  const std::string_view digits = token.substr(minus ? 1 : 0);
  if ((plus && minus) || digits.empty() || digits[0] == '+' || digits[0] == '-') return std::nullopt;
  return token;
}

}  // namespace

Lines tokenize(const std::string& data, bool backslash_joins) {
  Lines lines;
  std::size_t pos = 0, number = 0;
  if (data.rfind("\xEF\xBB\xBF", 0) == 0) pos = 3;  // a UTF-8 byte order mark says nothing about the mesh
  bool numbered = false;                            // the logical line being read (tokens from first.back() on) has its number
  while (pos < data.size()) {
    std::size_t eol = data.find_first_of("\r\n", pos);
    if (eol == std::string::npos) eol = data.size();
    const std::size_t next = (eol + 1 < data.size() && data[eol] == '\r' && data[eol + 1] == '\n') ? eol + 2 : eol + 1;
    ++number;
    std::string_view text(data.data() + pos, eol - pos);
    if (const auto hash = text.find('#'); hash != std::string_view::npos) text = text.substr(0, hash);
    while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
    const bool joins = backslash_joins && !text.empty() && text.back() == '\\';
    if (joins) text.remove_suffix(1);
    for (std::size_t i = 0; i < text.size();) {
      while (i < text.size() && is_space(text[i])) ++i;
      std::size_t j = i;
      while (j < text.size() && !is_space(text[j])) ++j;
      if (j > i) lines.tokens.push_back(text.substr(i, j - i));
      i = j;
    }
    const bool has_tokens = lines.tokens.size() > lines.first.back();
    if (has_tokens && !numbered) {
      lines.number.push_back(number);
      numbered = true;
    }
    if (!joins) {
      if (has_tokens) lines.first.push_back(lines.tokens.size());
      numbered = false;
    }
    pos = next;
  }
  if (lines.tokens.size() > lines.first.back()) lines.first.push_back(lines.tokens.size());  // the file ended on a '\\'
  return lines;
}

std::optional<double> parse_number(std::string_view token) {
  const auto digits = unsigned_part(token);
  if (!digits) return std::nullopt;
  double v = 0.0;
  const char* end = digits->data() + digits->size();
  const auto [stop, ec] = std::from_chars(digits->data(), end, v);
  if (ec != std::errc() || stop != end) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_integer(std::string_view token) {
  const auto digits = unsigned_part(token);
  if (!digits) return std::nullopt;
  std::int64_t v = 0;
  const char* end = digits->data() + digits->size();
  const auto [stop, ec] = std::from_chars(digits->data(), end, v);
  if (ec != std::errc() || stop != end) return std::nullopt;
  return v;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::unreadable, path, "cannot be opened for reading");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(ErrorCode::unreadable, path, "read failed");
  return data;
}

}  // namespace caliber::mesh_io
