#include "fieldrig/gps/location_map.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>
#include <system_error>
#include <tuple>
#include <utility>

#include "fieldrig/core/durable_file.h"

// The CSV reader is hand-written on purpose: maps are small (a season's field is ~100,000
// lines) and what matters is that a bad map is rejected at start-up with an error naming the
// file, the line and the column. Of Debian's CSV libraries, libcsv-dev (C, callbacks) reports
// neither line numbers nor comments, and libfccp-dev (fast-cpp-csv-parser) fixes the column set
// at compile time, so it cannot keep unknown columns as metadata; the RFC 4180 subset below is
// about a hundred lines and needs no new dependency.

namespace fieldrig::gps {
namespace {

constexpr std::string_view kIdColumn = "id";
constexpr std::string_view kLatitudeColumn = "lat";
constexpr std::string_view kLongitudeColumn = "lon";
constexpr std::string_view kHeadingColumn = "heading";

bool isBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && isBlank(text.front()))
    text.remove_prefix(1);
  while (!text.empty() && isBlank(text.back()))
    text.remove_suffix(1);
  return text;
}

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

// One CSV record (possibly several physical lines when a quoted field holds a newline).
struct Record {
  std::size_t line = 0;  // 1-based line where the record starts
  std::vector<std::string> fields;
};

// A tokenizing failure: the message and the 0-based column it happened in.
struct TokenError {
  std::size_t line = 0;
  std::size_t column = 0;
  std::string message;
};

// Splits RFC 4180 text into records, skipping blank lines and lines whose first non-blank
// character is '#'. Unquoted fields are trimmed of spaces and tabs; quoted fields are kept as is.
class CsvReader {
 public:
  explicit CsvReader(std::string_view text) : text_(text) {
    // A UTF-8 byte order mark is what spreadsheet programs put first; it is not part of "id".
    if (text_.substr(0, 3) == "\xEF\xBB\xBF")
      text_.remove_prefix(3);
  }

  // False at end of input; `error` is set (and false returned) on malformed input.
  bool next(Record& record, std::optional<TokenError>& error) {
    record.fields.clear();
    while (pos_ < text_.size()) {
      const std::size_t end = lineEnd(pos_);
      const std::string_view line = trim(text_.substr(pos_, end - pos_));
      if (line.empty() || line.front() == '#') {
        advancePastLine(end);
        continue;
      }
      record.line = line_;
      return readRecord(record, error);
    }
    return false;
  }

 private:
  std::size_t lineEnd(std::size_t from) const {
    const std::size_t end = text_.find('\n', from);
    return end == std::string_view::npos ? text_.size() : end;
  }

  void advancePastLine(std::size_t end) {
    pos_ = end + 1;
    ++line_;
  }

  bool readRecord(Record& record, std::optional<TokenError>& error) {
    const std::size_t start_line = line_;
    while (true) {
      while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t'))
        ++pos_;
      std::string field;
      if (pos_ < text_.size() && text_[pos_] == '"') {
        ++pos_;
        bool closed = false;
        while (pos_ < text_.size()) {
          const char c = text_[pos_++];
          if (c == '"') {
            if (pos_ < text_.size() && text_[pos_] == '"') {
              field += '"';
              ++pos_;
            } else {
              closed = true;
              break;
            }
          } else {
            if (c == '\n')
              ++line_;
            field += c;
          }
        }
        if (!closed) {
          error = TokenError{start_line, record.fields.size(), "unterminated quoted field"};
          return false;
        }
        while (pos_ < text_.size() && isBlank(text_[pos_]))
          ++pos_;
        if (pos_ < text_.size() && text_[pos_] != ',' && text_[pos_] != '\n') {
          error = TokenError{start_line, record.fields.size(), "text after the closing quote"};
          return false;
        }
      } else {
        const std::size_t begin = pos_;
        while (pos_ < text_.size() && text_[pos_] != ',' && text_[pos_] != '\n')
          ++pos_;
        const std::string_view raw = trim(text_.substr(begin, pos_ - begin));
        if (raw.find('"') != std::string_view::npos) {
          error = TokenError{start_line, record.fields.size(),
                             "a quote inside an unquoted field (quote the whole field)"};
          return false;
        }
        field = raw;
      }
      record.fields.push_back(std::move(field));
      if (pos_ >= text_.size()) {
        ++line_;
        return true;
      }
      if (text_[pos_] == '\n') {
        advancePastLine(pos_);
        return true;
      }
      ++pos_;  // the comma
    }
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

// Range checks shared by parse() and add(); the message names the field.
std::optional<std::string> checkLocation(const ImagingLocation& location) {
  auto outside = [](std::string_view field, double value, std::string_view range) {
    std::ostringstream out;
    out << "field '" << field << "': " << value << " is outside " << range;
    return out.str();
  };
  if (location.id.empty())
    return std::string("field 'id': empty id");
  if (!std::isfinite(location.latitude_deg))
    return std::string("field 'lat': not finite");
  if (!std::isfinite(location.longitude_deg))
    return std::string("field 'lon': not finite");
  if (location.latitude_deg < -90 || location.latitude_deg > 90) {
    return outside(kLatitudeColumn, location.latitude_deg, "[-90, 90]");
  }
  if (location.longitude_deg < -180 || location.longitude_deg > 180) {
    return outside(kLongitudeColumn, location.longitude_deg, "[-180, 180]");
  }
  if (location.heading_deg) {
    if (!std::isfinite(*location.heading_deg))
      return std::string("field 'heading': not finite");
    if (*location.heading_deg < 0 || *location.heading_deg >= 360) {
      return outside(kHeadingColumn, *location.heading_deg, "[0, 360)");
    }
  }
  return std::nullopt;
}

// "'text' why". By append, not "'" + std::string: GCC 12 -O3 gives a false-positive -Wrestrict.
std::string quotedText(std::string_view text, std::string_view why) {
  std::string message(1, '\'');
  message.append(text).append("' ").append(why);
  return message;
}

// Parses a whole field as a finite double; the message says why not.
std::optional<std::string> parseNumber(std::string_view text, double& out) {
  std::string_view digits = text;
  if (!digits.empty() && digits.front() == '+')
    digits.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), out);
  if (digits.empty() || ec == std::errc::invalid_argument || ptr != digits.data() + digits.size()) {
    return quotedText(text, "is not a number");
  }
  if (ec == std::errc::result_out_of_range || !std::isfinite(out)) {
    return quotedText(text, "is not a finite number");
  }
  return std::nullopt;
}

std::string formatNumber(double value) {
  // Shortest text that reads back as the same double.
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

std::string quoteIfNeeded(std::string_view value) {
  // Quote whatever the reader would otherwise split, trim or take for a comment.
  const bool needs_quotes =
      value.find_first_of(",\"\r\n") != std::string_view::npos ||
      (!value.empty() && (isBlank(value.front()) || isBlank(value.back()) || value.front() == '#'));
  if (!needs_quotes)
    return std::string(value);
  std::string out = "\"";
  for (char c : value) {
    if (c == '"')
      out += '"';
    out += c;
  }
  out += '"';
  return out;
}

std::string prefix(std::string_view source_name, std::size_t line) {
  return std::string(source_name) + ":" + std::to_string(line) + ": ";
}

}  // namespace

LocationMap::LocationMap(std::vector<std::string> metadata_columns)
    : metadata_columns_(std::move(metadata_columns)) {}

core::Result<LocationMap> LocationMap::load(const std::filesystem::path& path) {
  std::string error;
  const std::optional<std::string> text = core::readWholeFile(path, error);
  if (!text)
    return core::Error{error};
  return parse(*text, path.string());
}

core::Result<LocationMap> LocationMap::parse(std::string_view text, std::string_view source_name) {
  CsvReader reader(text);
  Record record;
  std::optional<TokenError> token_error;

  if (!reader.next(record, token_error)) {
    if (token_error) {
      return core::Error{prefix(source_name, token_error->line) + "column " +
                         std::to_string(token_error->column + 1) +
                         " of the header: " + token_error->message};
    }
    return core::Error{std::string(source_name) +
                       ": no header line (expected at least id,lat,lon)"};
  }

  // Header: find the required columns wherever they are; the rest is metadata, in order.
  const std::size_t header_line = record.line;
  const std::vector<std::string> header = record.fields;
  constexpr std::size_t kAbsent = static_cast<std::size_t>(-1);
  std::size_t id_col = kAbsent, lat_col = kAbsent, lon_col = kAbsent, heading_col = kAbsent;
  std::vector<std::string> metadata_columns;
  std::vector<std::size_t> metadata_positions;
  for (std::size_t i = 0; i < header.size(); ++i) {
    const std::string& name = header[i];
    if (name.empty()) {
      return core::Error{prefix(source_name, header_line) + "column " + std::to_string(i + 1) +
                         " of the header has no name"};
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (equalsIgnoreCase(header[j], name)) {
        return core::Error{prefix(source_name, header_line) + "column '" + name +
                           "' appears twice in the header"};
      }
    }
    if (equalsIgnoreCase(name, kIdColumn)) {
      id_col = i;
    } else if (equalsIgnoreCase(name, kLatitudeColumn)) {
      lat_col = i;
    } else if (equalsIgnoreCase(name, kLongitudeColumn)) {
      lon_col = i;
    } else if (equalsIgnoreCase(name, kHeadingColumn)) {
      heading_col = i;
    } else {
      metadata_columns.push_back(name);
      metadata_positions.push_back(i);
    }
  }
  for (const auto& [col, name] : {std::pair{id_col, kIdColumn}, std::pair{lat_col, kLatitudeColumn},
                                  std::pair{lon_col, kLongitudeColumn}}) {
    if (col == kAbsent) {
      return core::Error{prefix(source_name, header_line) +
                         "the header lacks the required column '" + std::string(name) + "'"};
    }
  }

  LocationMap map(std::move(metadata_columns));
  std::vector<std::size_t> lines;  // line of each location, for "first on line N"
  while (reader.next(record, token_error)) {
    const std::string where = prefix(source_name, record.line);
    if (record.fields.size() != header.size()) {
      return core::Error{where + "expected " + std::to_string(header.size()) +
                         " fields as in the header (line " + std::to_string(header_line) +
                         "), found " + std::to_string(record.fields.size())};
    }
    ImagingLocation location;
    location.id = record.fields[id_col];
    for (const auto& [col, name, target] :
         {std::tuple{lat_col, kLatitudeColumn, &location.latitude_deg},
          std::tuple{lon_col, kLongitudeColumn, &location.longitude_deg}}) {
      if (auto bad = parseNumber(record.fields[col], *target)) {
        return core::Error{where + "field '" + std::string(name) + "': " + *bad};
      }
    }
    // An empty heading means "any direction", so maps can mix headed and unheaded locations.
    if (heading_col != kAbsent && !record.fields[heading_col].empty()) {
      double heading = 0;
      if (auto bad = parseNumber(record.fields[heading_col], heading)) {
        return core::Error{where + "field 'heading': " + *bad};
      }
      location.heading_deg = heading;
    }
    for (std::size_t position : metadata_positions) {
      location.metadata.push_back(record.fields[position]);
    }
    if (auto bad = checkLocation(location))
      return core::Error{where + *bad};
    if (const auto found = map.index_by_id_.find(location.id); found != map.index_by_id_.end()) {
      return core::Error{where + "duplicate id '" + location.id + "' (first on line " +
                         std::to_string(lines[found->second]) + ")"};
    }
    lines.push_back(record.line);
    map.index_by_id_.emplace(location.id, map.locations_.size());
    map.locations_.push_back(std::move(location));
  }
  if (token_error) {
    const std::string field = token_error->column < header.size()
                                  ? "field '" + header[token_error->column] + "'"
                                  : "column " + std::to_string(token_error->column + 1);
    return core::Error{prefix(source_name, token_error->line) + field + ": " +
                       token_error->message};
  }
  return map;
}

core::Result<void> LocationMap::add(ImagingLocation location) {
  const std::string where = "location '" + location.id + "': ";
  if (auto bad = checkLocation(location))
    return core::Error{where + *bad};
  if (location.metadata.size() != metadata_columns_.size()) {
    return core::Error{where + std::to_string(location.metadata.size()) + " metadata values for " +
                       std::to_string(metadata_columns_.size()) + " metadata columns"};
  }
  if (index_by_id_.count(location.id) != 0) {
    return core::Error{where + "duplicate id"};
  }
  index_by_id_.emplace(location.id, locations_.size());
  locations_.push_back(std::move(location));
  return {};
}

const ImagingLocation* LocationMap::find(std::string_view id) const {
  const auto found = index_by_id_.find(std::string(id));
  return found == index_by_id_.end() ? nullptr : &locations_[found->second];
}

std::string LocationMap::csvHeader() const {
  // The heading column is always written so that a header written before any location exists
  // (append-as-you-go recording) matches every line csvLine() writes.
  std::string out = "id,lat,lon,heading";
  for (const std::string& column : metadata_columns_) {
    out += ',';
    out += quoteIfNeeded(column);
  }
  out += '\n';
  return out;
}

std::string LocationMap::csvLine(const ImagingLocation& location) const {
  std::string out = quoteIfNeeded(location.id);
  out += ',';
  out += formatNumber(location.latitude_deg);
  out += ',';
  out += formatNumber(location.longitude_deg);
  out += ',';
  if (location.heading_deg)
    out += formatNumber(*location.heading_deg);
  for (const std::string& value : location.metadata) {
    out += ',';
    out += quoteIfNeeded(value);
  }
  out += '\n';
  return out;
}

std::string LocationMap::toCsv() const {
  std::string out = csvHeader();
  for (const ImagingLocation& location : locations_)
    out += csvLine(location);
  return out;
}

core::Result<void> LocationMap::save(const std::filesystem::path& path) const {
  // Replaced whole or not at all: a crash never leaves half a map.
  if (std::string error = core::replaceFileAtomically(path, toCsv()); !error.empty())
    return core::Error{error};
  return {};
}

}  // namespace fieldrig::gps
