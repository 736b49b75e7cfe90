// caliber's own PLY reader (ascii, binary little and big endian). assimp's PLY importer hangs
// forever on a header without `end_header` (found by tests/fuzz/mesh_loader_fuzz.cpp) and has
// known ways of shifting binary data silently; this reader is strict instead: every count is
// checked against the bytes that are really there before anything is allocated, and every problem
// is an error naming the file.

#include "mesh/readers.h"
#include "mesh/text_lines.h"

#include <cstdio>
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "caliber/error.h"

namespace caliber::mesh_io {
namespace {

enum class Format { ascii, little, big };
enum class Type { i8, u8, i16, u16, i32, u32, f32, f64 };

struct Property {
  std::string name;
  Type type = Type::f32;
  bool list = false;
  Type count_type = Type::u8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

std::optional<Type> parse_type(const std::string& t) {
  if (t == "char" || t == "int8") return Type::i8;
  if (t == "uchar" || t == "uint8") return Type::u8;
  if (t == "short" || t == "int16") return Type::i16;
  if (t == "ushort" || t == "uint16") return Type::u16;
  if (t == "int" || t == "int32") return Type::i32;
  if (t == "uint" || t == "uint32") return Type::u32;
  if (t == "float" || t == "float32") return Type::f32;
  if (t == "double" || t == "float64") return Type::f64;
  return std::nullopt;
}

std::size_t size_of(Type t) {
  switch (t) {
    case Type::i8:
    case Type::u8:
      return 1;
    case Type::i16:
    case Type::u16:
      return 2;
    case Type::i32:
    case Type::u32:
    case Type::f32:
      return 4;
    case Type::f64:
      return 8;
  }
  return 1;
}

bool is_integer(Type t) { return t != Type::f32 && t != Type::f64; }

/// Reads the data section, value by value, in the file's format.
class Reader {
 public:
  Reader(const std::string& path, Format format, const std::string& data, std::size_t pos)
      : mPath(path), mFormat(format), mData(data), mPos(pos) {}

  /// The next value, as a double (integers up to 2^32 are exact in a double).
  double next(Type type, const std::string& what) {
    if (mFormat == Format::ascii) return next_ascii(type, what);
    const std::size_t n = size_of(type);
    if (mData.size() - mPos < n) fail("file ends inside " + what + " (truncated file?)");
    std::array<unsigned char, 8> b{};
    std::memcpy(b.data(), mData.data() + mPos, n);
    mPos += n;
    const bool swap = (mFormat == Format::big) == (std::endian::native == std::endian::little);
    if (swap) std::reverse(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n));
    switch (type) {
      case Type::i8: {
        std::int8_t v;
        std::memcpy(&v, b.data(), 1);
        return v;
      }
      case Type::u8:
        return b[0];
      case Type::i16: {
        std::int16_t v;
        std::memcpy(&v, b.data(), 2);
        return v;
      }
      case Type::u16: {
        std::uint16_t v;
        std::memcpy(&v, b.data(), 2);
        return v;
      }
      case Type::i32: {
        std::int32_t v;
        std::memcpy(&v, b.data(), 4);
        return v;
      }
      case Type::u32: {
        std::uint32_t v;
        std::memcpy(&v, b.data(), 4);
        return v;
      }
      case Type::f32: {
        float v;
        std::memcpy(&v, b.data(), 4);
        return v;
      }
      case Type::f64: {
        double v;
        std::memcpy(&v, b.data(), 8);
        return v;
      }
    }
    return 0.0;
  }

  /// Bytes (binary) or characters (ascii) not read yet.
  [[nodiscard]] std::size_t remaining() const { return mData.size() - mPos; }

  /// True when nothing but (ascii) white space is left.
  [[nodiscard]] bool at_end() const {
    return mFormat != Format::ascii ? mPos == mData.size() : mData.find_first_not_of(" \t\r\n", mPos) == std::string::npos;
  }

  [[noreturn]] void fail(const std::string& why) const { throw Error(ErrorCode::unreadable, mPath, "cannot parse mesh: " + why); }

 private:
  double next_ascii(Type type, const std::string& what) {
    while (mPos < mData.size() && std::isspace(static_cast<unsigned char>(mData[mPos]))) ++mPos;
    if (mPos == mData.size()) fail("file ends inside " + what + " (truncated file?)");
    if (mData[mPos] == '+') ++mPos;  // from_chars takes no '+'; some writers put one
    const char* first = mData.data() + mPos;
    const char* last = mData.data() + mData.size();
    double value = 0.0;
    const auto [end, ec] = std::from_chars(first, last, value);
    if (ec != std::errc() || (end != last && !std::isspace(static_cast<unsigned char>(*end)))) {
      std::size_t len = 0;
      while (first + len < last && !std::isspace(static_cast<unsigned char>(first[len])) && len < 32) ++len;
      fail("'" + std::string(first, len) + "' is not a number, in " + what);
    }
    mPos = static_cast<std::size_t>(end - mData.data());
    if (is_integer(type) && (value != std::floor(value))) fail("'" + std::string(first, end) + "' is not an integer, in " + what);
    return value;
  }

  const std::string& mPath;
  Format mFormat;
  const std::string& mData;
  std::size_t mPos;
};

}  // namespace

bool looks_like_ply(const std::string& head) { return head.rfind("ply\n", 0) == 0 || head.rfind("ply\r", 0) == 0; }

namespace {

/// PLY's header, read up to end_header.
struct Header {
  Format format;
  std::vector<Element> elements;
  std::size_t body = 0;  ///< offset of the first byte after the header
};

[[noreturn]] void parse_failure(const std::string& path, const std::string& why) {
  throw Error(ErrorCode::unreadable, path, "cannot parse mesh: " + why);
}

/// Reads one header line's property declaration into e.
void read_property(std::istringstream& words, const std::string& where, const std::string& path, Element& e) {
  const auto fail = [&](const std::string& why) { parse_failure(path, why); };
  Property p;
  std::string type;
  words >> type;
  if (type == "list") {
    std::string count_type, item_type;
    words >> count_type >> item_type >> p.name;
    const auto ct = parse_type(count_type), it = parse_type(item_type);
    if (!ct || !it || !is_integer(*ct)) fail(where + ": bad list property (expected 'property list <int type> <type> <name>')");
    p.list = true;
    p.count_type = *ct;
    p.type = *it;
  } else {
    const auto t = parse_type(type);
    if (!t) fail(where + ": unknown property type " + quote_token(type));
    p.type = *t;
    words >> p.name;
  }
  if (p.name.empty()) fail(where + ": a property needs a name");
  e.properties.push_back(std::move(p));
}

Header read_header(const std::string& data, const std::string& path) {
  const auto fail = [&](const std::string& why) { parse_failure(path, why); };
  std::optional<Format> format;
  std::vector<Element> elements;
  std::size_t pos = 0, line_no = 0;
  bool ended = false;
  while (!ended) {
    // Header lines end with LF, CR LF or a lone CR.
    const std::size_t eol = data.find_first_of("\r\n", pos);
    if (eol == std::string::npos) fail("the header has no 'end_header' line (truncated file?)");
    std::string line = data.substr(pos, eol - pos);
    pos = (data[eol] == '\r' && eol + 1 < data.size() && data[eol + 1] == '\n') ? eol + 2 : eol + 1;
    ++line_no;
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    const std::string where = "header line " + std::to_string(line_no);
    std::string extra;
    if (line_no == 1 || keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
    if (keyword == "format") {
      std::string name, version;
      words >> name >> version;
      if (name == "ascii")
        format = Format::ascii;
      else if (name == "binary_little_endian")
        format = Format::little;
      else if (name == "binary_big_endian")
        format = Format::big;
      else
        fail(where + ": unknown format " + quote_token(name));
      if (version != "1.0") fail(where + ": unsupported version " + quote_token(version));
    } else if (keyword == "element") {
      Element e;
      std::string count;
      words >> e.name >> count;
      std::uint64_t n = 0;
      const auto [end, ec] = std::from_chars(count.data(), count.data() + count.size(), n);
      if (e.name.empty() || ec != std::errc() || end != count.data() + count.size())
        fail(where + ": expected 'element <name> <count>'");
      e.count = n;
      elements.push_back(std::move(e));
    } else if (keyword == "property") {
      if (elements.empty()) fail(where + ": a property before any element");
      read_property(words, where, path, elements.back());
    } else if (keyword == "end_header") {
      ended = true;
      continue;
    } else {
      fail(where + ": unknown header keyword " + quote_token(keyword));
    }
    if (words >> extra) fail(where + ": unexpected " + quote_token(extra));
  }
  if (!format) fail("the header has no 'format' line");
  return Header{*format, std::move(elements), pos};
}

/// Reads one face's vertex index list (kept when `keep`) into corners.
void read_indices(Reader& reader, const Property& p, Format format, const std::string& what, bool keep, std::uint64_t face,
                  std::uint64_t vertex_count, const std::string& path, std::vector<std::uint32_t>& corners) {
  const double count = reader.next(p.count_type, what);
  if (count < 0) parse_failure(path, what + ": negative list length");
  const std::size_t item = format == Format::ascii ? 2 : size_of(p.type);
  if (count > static_cast<double>((reader.remaining() + 1) / item)) {
    parse_failure(path, what + ": list longer than the rest of the file (truncated file?)");
  }
  for (std::uint64_t j = 0; j < static_cast<std::uint64_t>(count); ++j) {
    const double index = reader.next(p.type, what);
    if (!keep) continue;
    if (index < 0 || index >= static_cast<double>(std::numeric_limits<std::uint32_t>::max())) {
      // As written: an integer where it is one (a cast of 1e300 to an integer would be undefined).
      char written[32];
      if (std::abs(index) < 0x1p53 && index == std::floor(index)) {
        std::snprintf(written, sizeof written, "%.0f", index);
      } else {
        *std::to_chars(written, written + sizeof written - 1, index).ptr = '\0';  // shortest round trip
      }
      throw Error(ErrorCode::bad_index, path,
                  "face " + std::to_string(face) + " refers to vertex " + written + " but there are only " +
                      std::to_string(vertex_count));
    }
    corners.push_back(static_cast<std::uint32_t>(index));
  }
}

/// Adds a face's triangles (a fan over its corners) to the mesh, its corners checked.
void add_face(const std::vector<std::uint32_t>& corners, std::uint64_t i, std::uint64_t vertex_count, const std::string& path,
              Mesh& mesh) {
  if (corners.size() < 3) {
    throw Error(ErrorCode::bad_index, path,
                "face " + std::to_string(i) + " has " + std::to_string(corners.size()) + " corner(s); a face needs at least 3");
  }
  for (const std::uint32_t c : corners) {
    if (c >= vertex_count) {
      throw Error(ErrorCode::bad_index, path,
                  "face " + std::to_string(i) + " refers to vertex " + std::to_string(c) + " but there are only " +
                      std::to_string(vertex_count));
    }
  }
  for (std::size_t c = 1; c + 1 < corners.size(); ++c) mesh.triangles.push_back({corners[0], corners[c], corners[c + 1]});
}

/// Reads every entry of one element; the first 'vertex' element gives the vertices (vertex_count
/// of them, whichever element comes first), the first 'face' element the faces, the others are
/// read past.
void read_element(Reader& reader, const Element& e, Format format, bool is_vertex, bool is_face, std::uint64_t vertex_count,
                  const std::string& path, Mesh& mesh) {
  const auto fail = [&](const std::string& why) { parse_failure(path, why); };
  // Every element takes at least one byte (binary) or two characters (ascii): a count the file
  // cannot hold is an error before anything is allocated.
  // (ascii: a value and its separator; the file's last value may go without one.)
  if (e.properties.empty() && e.count > 0) fail("element '" + e.name + "' has entries but no properties");
  std::size_t min_size = 0;
  for (const Property& p : e.properties) min_size += format == Format::ascii ? 2 : size_of(p.list ? p.count_type : p.type);
  if (min_size > 0 && e.count > (reader.remaining() + 1) / min_size) {
    fail("element '" + e.name + "' declares " + std::to_string(e.count) + " entries, more than the file holds (truncated file?)");
  }
  int xyz[3] = {-1, -1, -1};
  int indices = -1;
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    const Property& p = e.properties[k];
    if (is_vertex && !p.list && (p.name == "x" || p.name == "y" || p.name == "z")) xyz[p.name[0] - 'x'] = static_cast<int>(k);
    if (is_face && p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) indices = static_cast<int>(k);
  }
  if (is_vertex && (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)) fail("element 'vertex' needs properties x, y and z");
  if (is_face && indices < 0) fail("element 'face' needs a list property 'vertex_indices'");
  if (is_face && !is_integer(e.properties[static_cast<std::size_t>(indices)].type)) {
    fail("property '" + e.properties[static_cast<std::size_t>(indices)].name +
         "' of element 'face' holds floating-point values; vertex indices must have an integer type");
  }
  if (is_vertex) mesh.vertices.reserve(e.count);
  std::vector<std::uint32_t> corners;
  for (std::uint64_t i = 0; i < e.count; ++i) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    corners.clear();
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      const std::string what = e.name + " " + std::to_string(i) + ", property '" + p.name + "'";
      if (p.list) {
        read_indices(reader, p, format, what, is_face && indices == static_cast<int>(k), i, vertex_count, path, corners);
        continue;
      }
      const double value = reader.next(p.type, what);
      for (int c = 0; c < 3; ++c) {
        if (is_vertex && xyz[c] == static_cast<int>(k)) v[c] = value;
      }
    }
    if (is_vertex) {
      if (!v.allFinite()) throw Error(ErrorCode::bad_value, path, "vertex " + std::to_string(i) + " has a non-finite coordinate");
      mesh.vertices.push_back(v);
    }
    if (is_face) add_face(corners, i, vertex_count, path, mesh);
  }
}

}  // namespace

Mesh read_ply(const std::filesystem::path& file) {
  const std::string path = file.string();
  const std::string data = read_file(path);
  if (!looks_like_ply(data)) parse_failure(path, "a PLY file starts with the line 'ply'");
  const Header header = read_header(data, path);
  Reader reader(path, header.format, data, header.body);
  Mesh mesh;
  mesh.source = path;
  // PLY lets 'face' come before 'vertex': faces are checked against the declared vertex count.
  const auto vertex_element =
      std::find_if(header.elements.begin(), header.elements.end(), [](const Element& e) { return e.name == "vertex"; });
  const std::uint64_t vertex_count = vertex_element == header.elements.end() ? 0 : vertex_element->count;
  bool have_vertices = false, have_faces = false;
  for (const Element& e : header.elements) {
    const bool is_vertex = e.name == "vertex" && !have_vertices;
    const bool is_face = e.name == "face" && !have_faces;
    read_element(reader, e, header.format, is_vertex, is_face, vertex_count, path, mesh);
    have_vertices = have_vertices || is_vertex;
    have_faces = have_faces || is_face;
  }
  if (!reader.at_end()) {
    parse_failure(
        path, std::to_string(reader.remaining()) + " bytes after the last element the header declares (a wrong element count?)");
  }
  if (!have_vertices) parse_failure(path, "no 'vertex' element");
  if (!have_faces) throw Error(ErrorCode::empty_mesh, path, "mesh has no triangles (no 'face' element)");
  return mesh;
}

}  // namespace caliber::mesh_io
