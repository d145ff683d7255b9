#include "fieldrig/stem/measurement_log.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "fieldrig/core/durable_file.h"

namespace fieldrig::stem {
namespace {

constexpr int kColumns = 18;

// RFC 4180 quoting: fields with a comma, quote or line break are quoted, quotes doubled.
std::string quoted(const std::string& field) {
  if (field.find_first_of(",\"\r\n") == std::string::npos)
    return field;
  std::string out = "\"";
  for (char c : field) {
    if (c == '"')
      out += '"';
    out += c;
  }
  return out + "\"";
}

std::string number(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

// One CSV record (RFC 4180) from `text` at `pos`: its fields, with quoted fields holding commas,
// doubled quotes and line breaks, as toCsvRow writes a label typed with a line break. Advances
// `pos` past the record's line end and `line` by the physical lines it took. False for a quoted
// field that the file ends inside.
bool nextCsvRecord(std::string_view text, std::size_t& pos, int& line,
                   std::vector<std::string>& fields) {
  fields.assign(1, std::string());
  bool in_quotes = false;
  for (; pos < text.size(); ++pos) {
    const char c = text[pos];
    if (in_quotes) {
      if (c == '"' && pos + 1 < text.size() && text[pos + 1] == '"') {
        fields.back() += '"';
        ++pos;
      } else if (c == '"') {
        in_quotes = false;
      } else {
        line += c == '\n' ? 1 : 0;
        fields.back() += c;
      }
    } else if (c == '"') {
      in_quotes = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c == '\n') {
      ++pos;
      ++line;
      return true;
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return !in_quotes;
}

bool parseDouble(const std::string& text, double& value) {
  if (text.empty())
    return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return errno == 0 && end == text.c_str() + text.size() && std::isfinite(value);
}

bool parseUnsigned(const std::string& text, std::uint64_t& value) {
  if (text.empty() || text[0] == '-')
    return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtoull(text.c_str(), &end, 10);
  return errno == 0 && end == text.c_str() + text.size();
}

const char* const kHeaderNames[kColumns] = {
    "session", "set_index",    "trigger_id", "head",        "stem_label", "x1",
    "y1",      "x2",           "y2",         "x3",          "y3",         "x4",
    "y4",      "disparity_px", "ncc",        "diameter_mm", "time",       "repeat"};

}  // namespace

std::string csvHeader() {
  std::string header = kHeaderNames[0];
  for (int i = 1; i < kColumns; ++i) {
    header += ',';
    header += kHeaderNames[i];
  }
  return header;
}

std::string toCsvRow(const MeasurementRecord& r) {
  // append, not `"," + std::string`: GCC 12 -O3 gives a false-positive -Wrestrict on that insert.
  std::string row = quoted(r.session);
  const auto field = [&row](const std::string& text) { row.append(1, ',').append(text); };
  field(std::to_string(r.set_index));
  field(std::to_string(r.trigger_id));
  field(quoted(r.head));
  field(quoted(r.stem_label));
  for (const cv::Point2d& p : r.points) {
    field(number(p.x, 2));
    field(number(p.y, 2));
  }
  field(number(r.disparity_px, 3));
  field(number(r.ncc, 4));
  field(number(r.diameter_mm, 3));
  field(quoted(r.time));
  field(std::to_string(r.repeat));
  return row;
}

core::Result<std::vector<MeasurementRecord>> readMeasurementLog(const std::filesystem::path& file) {
  std::vector<MeasurementRecord> records;
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    return records;
  std::string error;
  const std::optional<std::string> text = core::readWholeFile(file, error);
  if (!text)
    return core::Error{std::move(error)};
  std::vector<std::string> fields;
  int next_line = 1;
  for (std::size_t pos = 0; pos < text->size();) {
    const int line_number = next_line;  // where the record starts
    const std::string where = file.string() + ":" + std::to_string(line_number) + ": ";
    if (!nextCsvRecord(*text, pos, next_line, fields))
      return core::Error{where + "unterminated quoted field"};
    if (fields.size() == 1 && fields[0].empty())
      continue;
    if (line_number == 1 && fields[0] == "session")
      continue;
    if (fields.size() != static_cast<std::size_t>(kColumns)) {
      return core::Error{where + std::to_string(fields.size()) + " fields, expected " +
                         std::to_string(kColumns)};
    }
    MeasurementRecord r;
    r.session = fields[0];
    r.head = fields[3];
    r.stem_label = fields[4];
    r.time = fields[16];
    std::uint64_t repeat = 0;
    if (!parseUnsigned(fields[1], r.set_index))
      return core::Error{where + "field 'set_index': not a count"};
    if (!parseUnsigned(fields[2], r.trigger_id))
      return core::Error{where + "field 'trigger_id': not a count"};
    if (!parseUnsigned(fields[17], repeat))
      return core::Error{where + "field 'repeat': not a count"};
    r.repeat = static_cast<int>(repeat);
    double values[11];
    for (int i = 0; i < 11; ++i) {
      const int column = i < 8 ? 5 + i : 13 + (i - 8);
      if (!parseDouble(fields[static_cast<std::size_t>(column)], values[i])) {
        return core::Error{where + "field '" + kHeaderNames[column] + "': not a number"};
      }
    }
    for (std::size_t i = 0; i < 4; ++i)
      r.points[i] = cv::Point2d(values[2 * i], values[2 * i + 1]);
    r.disparity_px = values[8];
    r.ncc = values[9];
    r.diameter_mm = values[10];
    records.push_back(std::move(r));
  }
  return records;
}

core::Result<void> appendMeasurement(const std::filesystem::path& file,
                                     const MeasurementRecord& record) {
  std::error_code ec;
  const bool fresh =
      !std::filesystem::exists(file, ec) || std::filesystem::file_size(file, ec) == 0;
  // One durable append (header and row together for a new file): a measurement that was
  // reported saved survives a crash, and a crash never leaves a header without its row. (Built by
  // appending: GCC 12 -O3 gives a false-positive -Wrestrict on string + string.)
  std::string text;
  if (fresh)
    text.append(csvHeader()).append(1, '\n');
  text.append(toCsvRow(record)).append(1, '\n');
  // The durable helper syncs the file's folder, which must be named even for a bare file name.
  if (std::string failed = core::appendDurably(std::filesystem::absolute(file), text);
      !failed.empty())
    return core::Error{std::move(failed)};
  return {};
}

core::Result<std::optional<MeasurementRecord>> removeLastMeasurement(
    const std::filesystem::path& file, const std::string& session) {
  core::Result<std::vector<MeasurementRecord>> records = readMeasurementLog(file);
  if (!records)
    return records.error();
  std::optional<std::size_t> last;
  for (std::size_t i = 0; i < records->size(); ++i) {
    if ((*records)[i].session == session)
      last = i;
  }
  if (!last)
    return std::optional<MeasurementRecord>();
  MeasurementRecord removed = std::move((*records)[*last]);
  records->erase(records->begin() + static_cast<std::ptrdiff_t>(*last));
  std::string text = csvHeader() + '\n';
  for (const MeasurementRecord& r : *records)
    text.append(toCsvRow(r)).append(1, '\n');
  if (std::string failed = core::replaceFileAtomically(std::filesystem::absolute(file), text);
      !failed.empty())
    return core::Error{std::move(failed)};
  return std::optional<MeasurementRecord>(std::move(removed));
}

int nextRepeat(const std::vector<MeasurementRecord>& records, const std::string& session,
               const std::string& stem_label) {
  int highest = 0;
  for (const MeasurementRecord& r : records) {
    if (r.session == session && r.stem_label == stem_label)
      highest = std::max(highest, r.repeat);
  }
  return highest + 1;
}

std::vector<StemSummary> summarizeRepeats(const std::vector<MeasurementRecord>& records) {
  std::vector<StemSummary> summaries;
  std::vector<std::vector<double>> values;
  for (const MeasurementRecord& r : records) {
    std::size_t i = 0;
    while (i < summaries.size() &&
           (summaries[i].session != r.session || summaries[i].stem_label != r.stem_label))
      ++i;
    if (i == summaries.size()) {
      summaries.push_back({r.session, r.stem_label, 0, 0.0, 0.0});
      values.emplace_back();
    }
    values[i].push_back(r.diameter_mm);
  }
  for (std::size_t i = 0; i < summaries.size(); ++i) {
    const std::vector<double>& v = values[i];
    double sum = 0.0;
    for (double x : v)
      sum += x;
    const double mean = sum / static_cast<double>(v.size());
    double squares = 0.0;
    for (double x : v)
      squares += (x - mean) * (x - mean);
    summaries[i].count = static_cast<int>(v.size());
    summaries[i].mean_mm = mean;
    summaries[i].sd_mm =
        v.size() > 1 ? std::sqrt(squares / static_cast<double>(v.size() - 1)) : 0.0;
  }
  return summaries;
}

}  // namespace fieldrig::stem
