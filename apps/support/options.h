#pragma once
// What the programs' command lines share: an option check with a plain message, and a command
// registered on an app and run if it was the one given.

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace caliber::cli {

/// An option check with a plain message (CLI11's own number checks print their range's limits as
/// 300-digit numbers): a whole number >= `least`.
inline CLI::Validator at_least(long long least) {
  return CLI::Validator(
      [least](std::string& text) -> std::string {
        long long value = 0;
        return CLI::detail::lexical_cast(text, value) && value >= least
                   ? std::string()
                   : "must be a whole number >= " + std::to_string(least) + ", not " + text;
      },
      "N >= " + std::to_string(least));
}

/// Numbers as people write them, on an option of whole numbers or of numbers (CLI11 reads whole
/// numbers as C does, 010 as 8 and 0x10 as 16, and a number below the doubles' range as 0):
/// whole numbers in decimal digits (leading zeros dropped: 010 is 10), an optional minus sign;
/// numbers as strtod reads them but a hexadecimal one, and none that rounds to 0 from a non-zero
/// value (1e-400). Each value is checked (a list's too); other options are left alone.
inline void check_number_syntax(CLI::Option& option) {
  const std::string type = option.get_type_name();
  const bool whole = type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0;
  const bool real = type.rfind("FLOAT", 0) == 0;
  if (!whole && !real) return;
  option.transform(CLI::Validator(
      [whole](std::string& text) -> std::string {
        const bool minus = !text.empty() && text[0] == '-';
        if (whole) {
          const std::string digits = text.substr(minus ? 1 : 0);
          if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) {
            return "must be a whole number in decimal digits, not '" + text + "'";
          }
          const std::size_t first = std::min(digits.find_first_not_of('0'), digits.size() - 1);
          text = (minus ? "-" : "") + digits.substr(first);
          return std::string();
        }
        if (text.find_first_of("xX") != std::string::npos || text.find_first_of(" \t") != std::string::npos) {
          return "must be a decimal number, not '" + text + "'";
        }
        const std::size_t exponent = text.find_first_of("eE");
        const bool nonzero = text.substr(0, exponent).find_first_of("123456789") != std::string::npos;
        const double value = std::strtod(text.c_str(), nullptr);
        if (nonzero && value == 0.0) return "is too small for a double (it would be read as 0): '" + text + "'";
        return std::string();
      },
      "", "NUMBER"));
}

/// A subcommand: registered on the app, then run if it was the one parsed.
using Runner = std::function<int()>;

}  // namespace caliber::cli
