#include "fieldrig/traits/cloud_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>

// Clouds come from anywhere (other tools, a copied folder, a truncated download), so no count in a
// header is trusted: each is checked against what the file's size can hold before anything is
// reserved, and every error names the file.
//
// PLY: our own reader (header checked against the size, a vertex element with x, y and z; then
//   ascii, binary little- or big-endian bodies), for the reasons given at loadPly.
// PCD: our own reader (header, then ascii, binary or binary_compressed data; x, y, z only) rather
//   than a check in front of PCL's. PCL 1.13's PCD reader segfaults on an empty file or any text
//   without a FIELDS line, and throws std::bad_alloc on a huge POINTS; guarding it would mean
//   parsing the whole header anyway and still leave its body and LZF paths untested against
//   damage. Reading three DATA kinds ourselves is short and every byte read is bounds-checked.

namespace fieldrig::traits {
namespace {

namespace fs = std::filesystem;
using core::Error;
using Points = std::vector<Eigen::Vector3f>;

// Headers are short (a PCD header is ~11 lines, a PLY one a few dozen); beyond this the file is
// not a cloud or its header has no end.
constexpr std::size_t kMaxHeaderBytes = 64 * 1024;

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// The first lines of a file, up to the line starting with `last_keyword` (included).
struct Header {
  std::vector<std::string> lines;  // without line ends
  std::size_t bytes = 0;           // offset of the data after the header
};

core::Result<Header> readHeader(const std::string& path, std::uintmax_t file_size,
                                std::string_view last_keyword) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return Error{path + ": cannot open"};
  std::string head(static_cast<std::size_t>(std::min<std::uintmax_t>(file_size, kMaxHeaderBytes)),
                   '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  Header header;
  std::size_t at = 0;
  while (at < head.size()) {
    const std::size_t end = head.find('\n', at);
    if (end == std::string::npos)
      break;
    std::string line = head.substr(at, end - at);
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    at = end + 1;
    header.lines.push_back(line);
    const std::string_view view(header.lines.back());
    if (view.substr(0, view.find(' ')) == last_keyword) {
      header.bytes = at;
      return header;
    }
  }
  return Error{path + ": no '" + std::string(last_keyword) + "' line in the first " +
               std::to_string(head.size()) + " bytes: not a cloud file or its header is cut off"};
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string word; in >> word;)
    out.push_back(word);
  return out;
}

std::optional<std::uint64_t> parseCount(const std::string& text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size())
    return std::nullopt;
  return value;
}

// The numbers of one text line [begin, end), separated by spaces or tabs, into `values`; std::
// from_chars (locale-free, no allocation) is what makes the ASCII readers fast. Returns the first
// token that is not a number, or nothing.
std::optional<std::string_view> parseNumberLine(const char* begin, const char* end,
                                                std::vector<double>& values) {
  values.clear();
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  for (const char* at = begin; at < end;) {
    while (at < end && space(*at))
      ++at;
    if (at == end)
      break;
    const char* token = at;
    while (at < end && !space(*at))
      ++at;
    double value = 0;
    const char* number = *token == '+' ? token + 1 : token;  // from_chars takes no '+'
    const auto [parsed, error] = std::from_chars(number, at, value);
    if (error != std::errc() || parsed != at)
      return std::string_view(token, static_cast<std::size_t>(at - token));
    values.push_back(value);
  }
  return std::nullopt;
}

// The rest of an open file, whose size is known to be bounded by the file's own.
core::Result<std::string> readRest(const std::string& path, std::ifstream& in,
                                   std::uint64_t bytes) {
  std::string data(static_cast<std::size_t>(bytes), '\0');
  if (!in || !in.read(data.data(), static_cast<std::streamsize>(data.size())))
    return Error{path + ": cannot read the data after the header"};
  return data;
}

// ---- PLY reader ---------------------------------------------------------------------------------

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> plyType(const std::string& name) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [text, type] : kNames) {
    if (name == text)
      return type;
  }
  return std::nullopt;
}

std::size_t plyTypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // of the value, or of a list's items
  bool list = false;
  PlyType count_type = PlyType::kUint8;  // of a list's count
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::uint64_t min_bytes = 0;  // the smallest one element can be written in
  int line = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::size_t bytes = 0;  // offset of the data
  int lines = 0;          // header lines, for the line numbers of ASCII data
  std::size_t vertex = 0;
  std::array<std::size_t, 3> xyz{};  // property indices of x, y and z within the vertex element
};

core::Result<PlyHeader> readPlyHeader(const std::string& path, std::uintmax_t file_size) {
  // The magic first, so that any other file is named for what it is not.
  std::string magic(4, '\0');
  std::ifstream(path, std::ios::binary).read(magic.data(), 4);
  if (magic != "ply\n" && magic != "ply\r")
    return Error{path + ": not a PLY file (no 'ply' on the first line)"};
  core::Result<Header> text = readHeader(path, file_size, "end_header");
  if (!text)
    return text.error();
  const auto fail = [&](std::size_t index, const std::string& what) {
    return Error{path + ":" + std::to_string(index + 1) + ": " + what};
  };
  if (text->lines.empty() || text->lines[0] != "ply")
    return Error{path + ": not a PLY file (no 'ply' on the first line)"};
  PlyHeader h;
  h.bytes = text->bytes;
  h.lines = static_cast<int>(text->lines.size());
  bool has_format = false;
  for (std::size_t i = 1; i < text->lines.size(); ++i) {
    const std::vector<std::string> w = words(text->lines[i]);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info" || w[0] == "end_header")
      continue;
    if (w[0] == "format") {
      if (w.size() != 3 ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        return fail(i, "format is not ascii, binary_little_endian or binary_big_endian");
      h.format = w[1] == "ascii"                  ? PlyFormat::kAscii
                 : w[1] == "binary_little_endian" ? PlyFormat::kBinaryLittleEndian
                                                  : PlyFormat::kBinaryBigEndian;
      has_format = true;
    } else if (w[0] == "element") {
      const std::optional<std::uint64_t> count = w.size() == 3 ? parseCount(w[2]) : std::nullopt;
      if (!count)
        return fail(i, "expected 'element NAME COUNT' with a whole COUNT");
      h.elements.push_back({w[1], *count, 0, static_cast<int>(i + 1), {}});
    } else if (w[0] == "property") {
      if (h.elements.empty())
        return fail(i, "a property before any element");
      PlyProperty property;
      property.list = w.size() == 5 && w[1] == "list";
      const std::optional<PlyType> count_type =
          property.list ? plyType(w[2]) : std::optional<PlyType>(PlyType::kUint8);
      const std::optional<PlyType> type =
          property.list ? plyType(w[3]) : (w.size() == 3 ? plyType(w[1]) : std::nullopt);
      if (!count_type || !type ||
          (property.list && (*count_type == PlyType::kFloat32 || *count_type == PlyType::kFloat64)))
        return fail(i,
                    "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME' with "
                    "known types (a list's count an integer type)");
      property.type = *type;
      property.count_type = *count_type;
      property.name = w.back();
      h.elements.back().properties.push_back(std::move(property));
    } else {
      return fail(i, "unknown header line '" + w[0] + "'");
    }
  }
  if (!has_format)
    return Error{path + ": no 'format' line in the PLY header"};
  // ASCII: at least one digit and a separator per value; a list at least its count, "0 ".
  // Binary: the type's size; a list at least its count.
  for (PlyElement& element : h.elements) {
    for (const PlyProperty& property : element.properties) {
      element.min_bytes += h.format == PlyFormat::kAscii
                               ? 2
                               : plyTypeSize(property.list ? property.count_type : property.type);
    }
  }
  const auto vertex = std::find_if(h.elements.begin(), h.elements.end(),
                                   [](const PlyElement& e) { return e.name == "vertex"; });
  if (vertex == h.elements.end())
    return Error{path + ": no 'vertex' element in the PLY header"};
  h.vertex = static_cast<std::size_t>(vertex - h.elements.begin());
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const std::string name(1, "xyz"[axis]);
    const auto found = std::find_if(vertex->properties.begin(), vertex->properties.end(),
                                    [&](const PlyProperty& p) { return p.name == name; });
    if (found == vertex->properties.end() || found->list) {
      return Error{path + ":" + std::to_string(vertex->line) +
                   ": the 'vertex' element has no property '" + name + "'" +
                   (found == vertex->properties.end() ? "" : " that is a single value")};
    }
    h.xyz[axis] = static_cast<std::size_t>(found - vertex->properties.begin());
  }
  // Against the file size, before anything is reserved. The last value of an ASCII file may end
  // without a line break.
  const bool ascii = h.format == PlyFormat::kAscii;
  const std::uint64_t data_bytes = file_size - h.bytes + (ascii ? 1 : 0);
  std::uint64_t remaining = data_bytes;
  for (const PlyElement& element : h.elements) {
    if (element.count == 0)
      continue;
    if (element.min_bytes == 0) {
      return Error{path + ":" + std::to_string(element.line) + ": element '" + element.name +
                   "' has no properties"};
    }
    const std::uint64_t fits = remaining / element.min_bytes;
    if (element.count > fits) {
      return Error{path + ": the header declares " + std::to_string(element.count) + " '" +
                   element.name + "' elements, but the file's " + std::to_string(data_bytes) +
                   " bytes after the header hold at most " + std::to_string(fits) + " (" +
                   std::to_string(element.min_bytes) + " bytes each" +
                   (ascii ? " at the least in ASCII" : "") + ")"};
    }
    remaining -= element.count * element.min_bytes;
  }
  return h;
}

// One binary value as a double, in the file's byte order.
double readPlyBinary(const char* at, PlyType type, bool big_endian) {
  unsigned char bytes[8];
  const std::size_t size = plyTypeSize(type);
  std::memcpy(bytes, at, size);
  if (big_endian)
    std::reverse(bytes, bytes + size);
  const auto as = [&]<typename T>(T value) {
    std::memcpy(&value, bytes, sizeof value);
    return static_cast<double>(value);
  };
  switch (type) {
    case PlyType::kInt8:
      return as(std::int8_t{});
    case PlyType::kUint8:
      return as(std::uint8_t{});
    case PlyType::kInt16:
      return as(std::int16_t{});
    case PlyType::kUint16:
      return as(std::uint16_t{});
    case PlyType::kInt32:
      return as(std::int32_t{});
    case PlyType::kUint32:
      return as(std::uint32_t{});
    case PlyType::kFloat32:
      return as(float{});
    case PlyType::kFloat64:
      return as(double{});
  }
  return 0;
}

// A list's count: a whole, non-negative number.
std::optional<std::uint64_t> listCount(double value) {
  if (!(value >= 0) || value != std::floor(value) || value > 4294967295.0)
    return std::nullopt;
  return static_cast<std::uint64_t>(value);
}

core::Result<Points> readPlyBinaryBody(const std::string& path, const PlyHeader& h,
                                       const std::string& data) {
  const bool big_endian = h.format == PlyFormat::kBinaryBigEndian;
  const char* at = data.data();
  const char* const end = data.data() + data.size();
  Points points;
  for (std::size_t e = 0; e <= h.vertex; ++e) {
    const PlyElement& element = h.elements[e];
    const bool vertex = e == h.vertex;
    if (vertex)
      points.reserve(static_cast<std::size_t>(element.count));  // bounded by the file's size
    for (std::uint64_t i = 0; i < element.count; ++i) {
      const auto cutOff = [&] {
        return Error{path + ": cut off in '" + element.name + "' element " + std::to_string(i) +
                     " of " + std::to_string(element.count)};
      };
      Eigen::Vector3f point;
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (property.list) {
          const std::size_t count_size = plyTypeSize(property.count_type);
          if (static_cast<std::size_t>(end - at) < count_size)
            return cutOff();
          const std::optional<std::uint64_t> count =
              listCount(readPlyBinary(at, property.count_type, big_endian));
          if (!count) {
            return Error{path + ": '" + element.name + "' element " + std::to_string(i) +
                         ": list '" + property.name + "' has a negative count"};
          }
          at += count_size;
          const std::uint64_t bytes = *count * plyTypeSize(property.type);
          if (static_cast<std::uint64_t>(end - at) < bytes)
            return cutOff();
          at += bytes;
          continue;
        }
        const std::size_t size = plyTypeSize(property.type);
        if (static_cast<std::size_t>(end - at) < size)
          return cutOff();
        if (vertex) {
          for (std::size_t axis = 0; axis < 3; ++axis) {
            if (h.xyz[axis] == p) {
              point[static_cast<Eigen::Index>(axis)] =
                  static_cast<float>(readPlyBinary(at, property.type, big_endian));
            }
          }
        }
        at += size;
      }
      if (vertex)
        points.push_back(point);
    }
  }
  if (h.vertex + 1 == h.elements.size() && at != end) {
    return Error{path + ": " + std::to_string(end - at) + " bytes after the " +
                 std::to_string(h.elements[h.vertex].count) +
                 " 'vertex' elements the header declares (the last element): the header's count "
                 "is wrong or the file is damaged"};
  }
  return points;
}

// ASCII: one element a line, values separated by spaces or tabs.
core::Result<Points> readPlyAsciiBody(const std::string& path, const PlyHeader& h,
                                      const std::string& data) {
  const char* at = data.data();
  const char* const end = data.data() + data.size();
  int line = h.lines;
  std::vector<double> values;
  Points points;
  for (std::size_t e = 0; e <= h.vertex; ++e) {
    const PlyElement& element = h.elements[e];
    const bool vertex = e == h.vertex;
    if (vertex)
      points.reserve(static_cast<std::size_t>(element.count));  // bounded by the file's size
    for (std::uint64_t i = 0; i < element.count;) {
      if (at == end) {
        return Error{path + ": cut off: " + std::to_string(i) + " of the " +
                     std::to_string(element.count) + " '" + element.name +
                     "' elements the header declares"};
      }
      ++line;
      const char* line_end = static_cast<const char*>(std::memchr(at, '\n', end - at));
      if (line_end == nullptr)
        line_end = end;
      if (const auto bad = parseNumberLine(at, line_end, values)) {
        return Error{path + ":" + std::to_string(line) + ": '" + std::string(*bad) +
                     "' is not a number"};
      }
      at = line_end == end ? end : line_end + 1;
      if (values.empty())
        continue;  // a blank line
      // Walk the properties over the line's values: lists take their count from it.
      std::size_t v = 0;
      Eigen::Vector3f point;
      bool complete = true;
      for (std::size_t p = 0; p < element.properties.size() && complete; ++p) {
        const PlyProperty& property = element.properties[p];
        if (v >= values.size()) {
          complete = false;
          break;
        }
        if (property.list) {
          const std::optional<std::uint64_t> count = listCount(values[v]);
          if (!count) {
            return Error{path + ":" + std::to_string(line) + ": list '" + property.name +
                         "' has no whole, non-negative count"};
          }
          if (*count > values.size() - v - 1) {
            complete = false;
            break;
          }
          v += 1 + static_cast<std::size_t>(*count);
          continue;
        }
        if (vertex) {
          for (std::size_t axis = 0; axis < 3; ++axis) {
            if (h.xyz[axis] == p)
              point[static_cast<Eigen::Index>(axis)] = static_cast<float>(values[v]);
          }
        }
        ++v;
      }
      if (!complete || v != values.size()) {
        return Error{path + ":" + std::to_string(line) + ": " + std::to_string(values.size()) +
                     " values do not make one '" + element.name + "' element (" +
                     std::to_string(element.properties.size()) + " properties)"};
      }
      if (vertex)
        points.push_back(point);
      ++i;
    }
  }
  // Whitespace may end the file; a value past the declared elements means a wrong count.
  if (h.vertex + 1 == h.elements.size()) {
    while (at != end && std::isspace(static_cast<unsigned char>(*at))) {
      if (*at == '\n')
        ++line;
      ++at;
    }
    if (at != end) {
      return Error{path + ":" + std::to_string(line + 1) + ": a value after the " +
                   std::to_string(h.elements[h.vertex].count) +
                   " 'vertex' elements the header declares (the last element): the header's "
                   "count is wrong or the file is damaged"};
    }
  }
  return points;
}

// Our own PLY reader rather than PCL's: PCL 1.13's reader fails assert()s (abort) on colour
// properties out of order and on damaged list properties, converts a zero-vertex file through
// `&cloud[0]` (undefined behaviour), reads non-numbers as NaN without a word, and takes ~7x
// longer on ASCII than a from_chars parser. Reading x, y and z of one element is short, and
// every byte read here is bounds-checked.
core::Result<Points> loadPly(const std::string& path, std::uintmax_t file_size) {
  core::Result<PlyHeader> header = readPlyHeader(path, file_size);
  if (!header)
    return header.error();
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(header->bytes));
  const core::Result<std::string> data = readRest(path, in, file_size - header->bytes);
  if (!data)
    return data.error();
  return header->format == PlyFormat::kAscii ? readPlyAsciiBody(path, *header, *data)
                                             : readPlyBinaryBody(path, *header, *data);
}

// ---- PCD reader ---------------------------------------------------------------------------------

struct PcdField {
  std::string name;
  int size = 0;     // bytes of one value
  char type = 'F';  // I, U or F
  std::uint64_t count = 1;
  std::uint64_t offset = 0;  // within one point (binary); value index (ascii)
};

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0, height = 1, points = 0;
  bool has_width = false, has_points = false;
  PcdData data = PcdData::kAscii;
  std::uint64_t point_bytes = 0;   // Σ size × count
  std::uint64_t point_values = 0;  // Σ count
  std::size_t header_bytes = 0;
  std::array<std::size_t, 3> xyz{};  // indices into fields
};

double readBinaryValue(const char* at, char type, int size) {
  switch (type) {
    case 'F':
      if (size == 4) {
        float v;
        std::memcpy(&v, at, 4);
        return v;
      } else {
        double v;
        std::memcpy(&v, at, 8);
        return v;
      }
    case 'I': {
      std::int64_t v = 0;
      if (size == 1) {
        std::int8_t x;
        std::memcpy(&x, at, 1);
        v = x;
      } else if (size == 2) {
        std::int16_t x;
        std::memcpy(&x, at, 2);
        v = x;
      } else if (size == 4) {
        std::int32_t x;
        std::memcpy(&x, at, 4);
        v = x;
      } else {
        std::memcpy(&v, at, 8);
      }
      return static_cast<double>(v);
    }
    default: {
      std::uint64_t v = 0;
      std::memcpy(&v, at, static_cast<std::size_t>(size));  // little-endian, as PCL writes
      return static_cast<double>(v);
    }
  }
}

core::Result<PcdHeader> readPcdHeader(const std::string& path, std::uintmax_t file_size) {
  core::Result<Header> text = readHeader(path, file_size, "DATA");
  if (!text)
    return text.error();
  PcdHeader h;
  h.header_bytes = text->bytes;
  bool has_size = false, has_type = false, has_count = false;
  std::vector<std::string> sizes, types, counts;
  for (std::size_t i = 0; i < text->lines.size(); ++i) {
    const auto fail = [&](const std::string& what) {
      return Error{path + ":" + std::to_string(i + 1) + ": " + what};
    };
    const std::vector<std::string> w = words(text->lines[i]);
    if (w.empty() || w[0][0] == '#')
      continue;
    const std::vector<std::string> rest(w.begin() + 1, w.end());
    const auto single = [&](std::uint64_t& out) -> core::Result<void> {
      const std::optional<std::uint64_t> n = rest.size() == 1 ? parseCount(rest[0]) : std::nullopt;
      if (!n)
        return fail(w[0] + " is not one whole number");
      out = *n;
      return {};
    };
    if (w[0] == "VERSION" || w[0] == "VIEWPOINT") {
      continue;
    } else if (w[0] == "FIELDS") {
      if (rest.empty())
        return fail("FIELDS names no field");
      for (const std::string& name : rest)
        h.fields.push_back({name});
    } else if (w[0] == "SIZE") {
      sizes = rest;
      has_size = true;
    } else if (w[0] == "TYPE") {
      types = rest;
      has_type = true;
    } else if (w[0] == "COUNT") {
      counts = rest;
      has_count = true;
    } else if (w[0] == "WIDTH") {
      if (auto ok = single(h.width); !ok)
        return ok.error();
      h.has_width = true;
    } else if (w[0] == "HEIGHT") {
      if (auto ok = single(h.height); !ok)
        return ok.error();
    } else if (w[0] == "POINTS") {
      if (auto ok = single(h.points); !ok)
        return ok.error();
      h.has_points = true;
    } else if (w[0] == "DATA") {
      if (rest.size() != 1 ||
          (rest[0] != "ascii" && rest[0] != "binary" && rest[0] != "binary_compressed"))
        return fail("DATA is not ascii, binary or binary_compressed");
      h.data = rest[0] == "ascii"    ? PcdData::kAscii
               : rest[0] == "binary" ? PcdData::kBinary
                                     : PcdData::kBinaryCompressed;
    } else {
      return fail("unknown header line '" + w[0] + "'");
    }
  }
  if (h.fields.empty())
    return Error{path + ": not a PCD file (no FIELDS line)"};
  if (!has_size || !has_type)
    return Error{path + ": the PCD header lacks " + (has_size ? "TYPE" : "SIZE")};
  if (sizes.size() != h.fields.size() || types.size() != h.fields.size() ||
      (has_count && counts.size() != h.fields.size())) {
    return Error{path + ": FIELDS names " + std::to_string(h.fields.size()) +
                 " fields but SIZE, TYPE or COUNT gives another number of entries"};
  }
  std::uint64_t value_index = 0;
  for (std::size_t f = 0; f < h.fields.size(); ++f) {
    PcdField& field = h.fields[f];
    const std::optional<std::uint64_t> size = parseCount(sizes[f]);
    if (!size || (*size != 1 && *size != 2 && *size != 4 && *size != 8))
      return Error{path + ": SIZE of '" + field.name + "' is not 1, 2, 4 or 8"};
    field.size = static_cast<int>(*size);
    if (types[f].size() != 1 || std::string_view("IUF").find(types[f][0]) == std::string::npos)
      return Error{path + ": TYPE of '" + field.name + "' is not I, U or F"};
    field.type = types[f][0];
    if (field.type == 'F' && field.size != 4 && field.size != 8)
      return Error{path + ": '" + field.name + "' is a float of " + sizes[f] + " bytes"};
    if (has_count) {
      const std::optional<std::uint64_t> count = parseCount(counts[f]);
      // A field of more than 2^20 values per point is no point cloud (PCL writes at most a
      // histogram of a few hundred); the bound keeps the sums below from overflowing.
      if (!count || *count == 0 || *count > (1U << 20))
        return Error{path + ": COUNT of '" + field.name + "' is not between 1 and 1048576"};
      field.count = *count;
    }
    field.offset = h.point_bytes;
    h.point_bytes += static_cast<std::uint64_t>(field.size) * field.count;
    value_index += field.count;
  }
  h.point_values = value_index;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const std::string name(1, "xyz"[axis]);
    const auto found = std::find_if(h.fields.begin(), h.fields.end(),
                                    [&](const PcdField& f) { return f.name == name; });
    if (found == h.fields.end())
      return Error{path + ": the PCD file has no field '" + name + "'"};
    if (found->count != 1)
      return Error{path + ": field '" + name + "' has COUNT " + std::to_string(found->count)};
    h.xyz[axis] = static_cast<std::size_t>(found - h.fields.begin());
  }
  if (!h.has_width && !h.has_points)
    return Error{path + ": the PCD header gives neither WIDTH nor POINTS"};
  if (h.height == 0 ||
      (h.has_width && h.width > std::numeric_limits<std::uint64_t>::max() / h.height))
    return Error{path + ": WIDTH x HEIGHT is not a number of points"};
  if (!h.has_points)
    h.points = h.width * h.height;
  if (h.has_width && h.width * h.height != h.points) {
    return Error{path + ": WIDTH x HEIGHT = " + std::to_string(h.width) + " x " +
                 std::to_string(h.height) + " but POINTS = " + std::to_string(h.points)};
  }
  // Against the file size, before anything is reserved.
  const std::uint64_t data_bytes = file_size - h.header_bytes;
  const auto tooMany = [&](std::uint64_t fits, const std::string& per_point) {
    return Error{path + ": the header declares " + std::to_string(h.points) +
                 " points, but the file's " + std::to_string(data_bytes) +
                 " bytes after the header hold at most " + std::to_string(fits) + " (" + per_point +
                 ")"};
  };
  switch (h.data) {
    case PcdData::kAscii: {
      // At least one digit and a separator per value; the last line may lack its line break.
      const std::uint64_t per_point = 2 * h.point_values;
      if (h.points > (data_bytes + 1) / per_point)
        return tooMany((data_bytes + 1) / per_point,
                       std::to_string(per_point) + " bytes each at the least in ASCII");
      break;
    }
    case PcdData::kBinary:
      if (h.points > data_bytes / h.point_bytes)
        return tooMany(data_bytes / h.point_bytes, std::to_string(h.point_bytes) + " bytes each");
      break;
    case PcdData::kBinaryCompressed:
      break;  // checked against the compressed block's own sizes in readPcdCompressed
  }
  return h;
}

Eigen::Vector3f pointFromBinary(const PcdHeader& h, const char* point) {
  Eigen::Vector3f p;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const PcdField& f = h.fields[h.xyz[axis]];
    p[static_cast<Eigen::Index>(axis)] =
        static_cast<float>(readBinaryValue(point + f.offset, f.type, f.size));
  }
  return p;
}

core::Result<Points> readPcdAscii(const std::string& path, const PcdHeader& h,
                                  const std::string& data) {
  // Value index of x, y and z within a line.
  std::array<std::uint64_t, 3> column{};
  std::uint64_t index = 0;
  for (std::size_t f = 0; f < h.fields.size(); ++f) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (h.xyz[axis] == f)
        column[axis] = index;
    }
    index += h.fields[f].count;
  }
  Points points;
  points.reserve(static_cast<std::size_t>(h.points));
  std::vector<double> values;
  std::uint64_t line_number = 0;
  const char* at = data.data();
  const char* const end = data.data() + data.size();
  while (points.size() < h.points && at < end) {
    ++line_number;
    const char* line_end = static_cast<const char*>(std::memchr(at, '\n', end - at));
    if (line_end == nullptr)
      line_end = end;
    const std::optional<std::string_view> bad = parseNumberLine(at, line_end, values);
    at = line_end == end ? end : line_end + 1;
    const auto where = [&] { return path + ": data line " + std::to_string(line_number); };
    if (bad)
      return Error{where() + ": '" + std::string(*bad) + "' is not a number"};
    if (values.empty())
      continue;
    if (values.size() != h.point_values) {
      return Error{where() + ": " + std::to_string(values.size()) + " values, expected " +
                   std::to_string(h.point_values)};
    }
    points.emplace_back(static_cast<float>(values[column[0]]),
                        static_cast<float>(values[column[1]]),
                        static_cast<float>(values[column[2]]));
  }
  if (points.size() < h.points) {
    return Error{path + ": cut off: " + std::to_string(points.size()) + " of the " +
                 std::to_string(h.points) + " points the header declares"};
  }
  return points;
}

// LZF (liblzf's format, which PCL writes): literal runs and back references; every read and
// write is checked against the buffers. Returns the bytes written, or nothing when the stream is
// damaged.
std::optional<std::size_t> lzfDecompress(const unsigned char* in, std::size_t in_size,
                                         unsigned char* out, std::size_t out_size) {
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    std::size_t ctrl = in[ip++];
    if (ctrl < 32) {
      const std::size_t length = ctrl + 1;
      if (ip + length > in_size || op + length > out_size)
        return std::nullopt;
      std::memcpy(out + op, in + ip, length);
      ip += length;
      op += length;
      continue;
    }
    std::size_t length = ctrl >> 5;
    if (ip >= in_size)
      return std::nullopt;
    if (length == 7) {
      length += in[ip++];
      if (ip >= in_size)
        return std::nullopt;
    }
    const std::size_t back = ((ctrl & 0x1f) << 8) + in[ip++] + 1;
    length += 2;
    if (back > op || op + length > out_size)
      return std::nullopt;
    for (std::size_t k = 0; k < length; ++k, ++op)
      out[op] = out[op - back];  // byte by byte: the source may overlap what is written
  }
  return op;
}

core::Result<Points> readPcdCompressed(const std::string& path, const PcdHeader& h,
                                       std::ifstream& in, std::uint64_t data_bytes) {
  std::uint32_t sizes[2] = {0, 0};  // compressed, uncompressed
  if (data_bytes < sizeof sizes || !in.read(reinterpret_cast<char*>(sizes), sizeof sizes))
    return Error{path + ": cut off before the compressed block's sizes"};
  const std::uint64_t compressed = sizes[0];
  const std::uint64_t uncompressed = sizes[1];
  if (h.points > std::numeric_limits<std::uint32_t>::max() / h.point_bytes) {
    return Error{path + ": the header declares " + std::to_string(h.points) + " points of " +
                 std::to_string(h.point_bytes) +
                 " bytes, more than a compressed block (at most 4 GiB) holds"};
  }
  const std::uint64_t expected = h.points * h.point_bytes;
  if (uncompressed != expected) {
    return Error{path + ": the compressed block holds " + std::to_string(uncompressed) +
                 " bytes, but the header's " + std::to_string(h.points) + " points of " +
                 std::to_string(h.point_bytes) + " bytes need " + std::to_string(expected)};
  }
  if (compressed > data_bytes - sizeof sizes) {
    return Error{path + ": the compressed block claims " + std::to_string(compressed) +
                 " bytes, but the file has " + std::to_string(data_bytes - sizeof sizes) +
                 " after its sizes"};
  }
  // One LZF back reference (3 bytes) expands to at most 264 bytes: a bound on what the file's
  // bytes can hold, checked before reserving the uncompressed size.
  if (uncompressed > compressed * 88) {
    return Error{path + ": the header declares " + std::to_string(h.points) + " points (" +
                 std::to_string(uncompressed) + " bytes), more than the " +
                 std::to_string(compressed) + " compressed bytes can hold"};
  }
  if (expected == 0)
    return Points{};
  std::vector<unsigned char> packed(static_cast<std::size_t>(compressed));
  if (!in.read(reinterpret_cast<char*>(packed.data()), static_cast<std::streamsize>(compressed)))
    return Error{path + ": cut off inside the compressed block"};
  std::vector<unsigned char> data(static_cast<std::size_t>(uncompressed));
  const std::optional<std::size_t> written =
      lzfDecompress(packed.data(), packed.size(), data.data(), data.size());
  if (!written || *written != data.size())
    return Error{path + ": the compressed block is damaged (LZF data does not decode)"};
  // Decompressed, the fields follow each other: all x, then all y, ... (PCL's layout).
  std::array<std::uint64_t, 3> start{};
  for (std::size_t axis = 0; axis < 3; ++axis)
    start[axis] = h.points * h.fields[h.xyz[axis]].offset;
  Points points(static_cast<std::size_t>(h.points));
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      const PcdField& f = h.fields[h.xyz[axis]];
      const char* at = reinterpret_cast<const char*>(data.data()) + start[axis] + i * f.size;
      points[i][static_cast<Eigen::Index>(axis)] =
          static_cast<float>(readBinaryValue(at, f.type, f.size));
    }
  }
  return points;
}

core::Result<Points> loadPcd(const std::string& path, std::uintmax_t file_size) {
  core::Result<PcdHeader> header = readPcdHeader(path, file_size);
  if (!header)
    return header.error();
  const PcdHeader& h = *header;
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(h.header_bytes));
  if (!in)
    return Error{path + ": cannot read"};
  const std::uint64_t data_bytes = file_size - h.header_bytes;
  switch (h.data) {
    case PcdData::kAscii: {
      const core::Result<std::string> data = readRest(path, in, data_bytes);
      if (!data)
        return data.error();
      return readPcdAscii(path, h, *data);
    }
    case PcdData::kBinaryCompressed:
      return readPcdCompressed(path, h, in, data_bytes);
    case PcdData::kBinary:
      break;
  }
  // Checked in readPcdHeader: the file holds all points' bytes.
  std::vector<char> data(static_cast<std::size_t>(h.points * h.point_bytes));
  if (!in.read(data.data(), static_cast<std::streamsize>(data.size())))
    return Error{path + ": cannot read the binary data"};
  Points points;
  points.reserve(static_cast<std::size_t>(h.points));
  for (std::uint64_t i = 0; i < h.points; ++i)
    points.push_back(pointFromBinary(h, data.data() + i * h.point_bytes));
  return points;
}

}  // namespace

core::Result<std::vector<Eigen::Vector3f>> loadCloud(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status))
    return Error{path + ": no such file"};
  if (fs::is_directory(status))
    return Error{path + ": is a folder, not a cloud file"};
  if (!fs::is_regular_file(status))
    return Error{path + ": not a regular file"};
  const std::uintmax_t file_size = fs::file_size(path, ec);
  if (ec)
    return Error{path + ": cannot read its size: " + ec.message()};
  const std::string ext = lowerExtension(path);
  if (ext != ".ply" && ext != ".pcd")
    return Error{path + ": unknown cloud format '" + ext + "' (expected .ply or .pcd)"};
  if (file_size == 0)
    return Error{path + ": empty file"};
  return ext == ".ply" ? loadPly(path, file_size) : loadPcd(path, file_size);
}

}  // namespace fieldrig::traits
