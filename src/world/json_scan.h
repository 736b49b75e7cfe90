#pragma once
/// \file
/// A first pass over a scene file's JSON (SAX, before the tree is built) that refuses what a JSON
/// parser accepts silently, each naming the file and the path of the value
/// ("objects[1].motion.type"): a key given twice in one object (parsers keep one of the two values),
/// a number too small for a double (1e-400, read as 0), nesting deeper than kMaxDepth (no scene
/// nests more than a few levels; each level costs memory); and turns a syntax error into caliber's
/// (a number beyond the doubles' range with its path). An empty key is shown as "".
/// (nlohmann's callback parser scans the enclosing array at every object's end: quadratic.)

#include <cstddef>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "caliber/error.h"

namespace caliber::world {

class JsonScan final : public nlohmann::json_sax<nlohmann::json> {
 public:
  static constexpr std::size_t kMaxDepth = 256;

  explicit JsonScan(std::string source) : mSource(std::move(source)) {}
  bool null() override { return element_done(); }
  bool boolean(bool) override { return element_done(); }
  bool number_integer(number_integer_t) override { return element_done(); }
  bool number_unsigned(number_unsigned_t) override { return element_done(); }
  bool number_float(number_float_t value, const string_t& text) override {
    // A mantissa with a digit other than 0 that the parser read as 0 (below the doubles' range).
    if (value == 0.0 && text.substr(0, text.find_first_of("eE")).find_first_of("123456789") != string_t::npos) {
      fail(path(nullptr), "is too small for a double (it would be read as 0): " + text);
    }
    return element_done();
  }
  bool string(string_t&) override { return element_done(); }
  bool binary(binary_t&) override { return element_done(); }
  bool start_object(std::size_t) override { return push(true); }
  bool start_array(std::size_t) override { return push(false); }
  bool end_object() override { return pop(); }
  bool end_array() override { return pop(); }
  bool key(string_t& key) override {
    if (!mStack.back().keys.insert(key).second) fail(path(&key), "the key is given twice in one object (which value was meant?)");
    mStack.back().key = key;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    // A number beyond the doubles' range (out_of_range 406) is a value: its path is known.
    if (e.id == 406) fail(path(nullptr), std::string("not valid JSON: ") + e.what());
    throw Error(ErrorCode::unreadable, mSource, std::string("not valid JSON: ") + e.what());
  }

 private:
  struct Level {
    bool object = false;
    std::set<std::string> keys;
    std::string key;
    std::size_t index = 0;
  };
  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw Error(ErrorCode::unreadable, mSource, (where.empty() ? std::string() : "'" + where + "': ") + problem);
  }
  /// The path of the value being read: given `key`, that key's in the innermost object; else the
  /// innermost level's current key or index.
  [[nodiscard]] std::string path(const std::string* key) const {
    std::string out;
    const auto name = [&out](const std::string& part) {
      if (!out.empty()) out.push_back('.');
      out.append(part.empty() ? std::string("\"\"") : part);  // an empty key, seen
    };
    const std::size_t levels = key != nullptr ? mStack.size() - 1 : mStack.size();
    for (std::size_t i = 0; i < levels; ++i) {
      if (mStack[i].object) {
        name(mStack[i].key);
      } else {
        out.append("[").append(std::to_string(mStack[i].index)).append("]");
      }
    }
    if (key != nullptr) name(*key);
    return out;
  }
  bool element_done() {
    if (!mStack.empty() && !mStack.back().object) ++mStack.back().index;
    return true;
  }
  bool push(bool object) {
    if (mStack.size() == kMaxDepth) {
      // The problem first: the path, 256 levels long, is cut to fit the message.
      throw Error(ErrorCode::unreadable, mSource,
                  "nests deeper than " + std::to_string(kMaxDepth) + " levels, at '" + path(nullptr) + "'");
    }
    mStack.push_back(Level{object, {}, {}, 0});
    return true;
  }
  bool pop() {
    mStack.pop_back();
    return element_done();
  }

  std::string mSource;
  std::vector<Level> mStack;
};

}  // namespace caliber::world
