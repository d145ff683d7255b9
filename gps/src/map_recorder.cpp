#include "fieldrig/gps/map_recorder.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <system_error>
#include <utility>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/gps/local_frame.h"

namespace fieldrig::gps {
namespace {

// Below this ground speed the receiver's course over ground is not a direction of travel.
constexpr double kMinCourseSpeedMps = 0.3;  // as the trigger planner's minimum speed
// Fixes kept for the heading fallback (bearing from an earlier fix).
constexpr std::chrono::seconds kFixHistory{10};
// Without an RMC course, the heading is the bearing from the latest earlier fix at least this
// far away: over one 10 Hz step (20 cm at 2 m/s) 1-2 cm of RTK noise would swing it by degrees.
constexpr double kMinBearingBaseM = 1.0;

// The first line that is not blank or a comment, without its line end and trailing blanks.
std::string firstRecordLine(std::string_view text) {
  std::size_t pos = 0;
  if (text.substr(0, 3) == "\xEF\xBB\xBF")
    pos = 3;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos)
      end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' '))
      line.remove_suffix(1);
    const std::size_t first = line.find_first_not_of(" \t");
    if (first != std::string_view::npos && line[first] != '#')
      return std::string(line);
    pos = end + 1;
  }
  return {};
}

}  // namespace

const std::vector<std::string>& recordingColumns() {
  static const std::vector<std::string> columns = {"time", "speed_mps", "quality"};
  return columns;
}

core::Result<LocationMap> openRecordingMap(const std::filesystem::path& path) {
  LocationMap recording(recordingColumns());
  std::string text;
  std::error_code ignored;
  if (std::filesystem::exists(path, ignored)) {
    std::string error;
    std::optional<std::string> read = core::readWholeFile(path, error);
    if (!read)
      return core::Error{error};
    text = std::move(*read);
  }
  if (text.empty()) {
    if (std::string error = core::appendDurably(path, recording.csvHeader()); !error.empty())
      return core::Error{error};
    return recording;
  }
  core::Result<LocationMap> existing = LocationMap::parse(text, path.string());
  if (!existing)
    return existing;
  const std::string expected = recording.csvHeader().substr(0, recording.csvHeader().size() - 1);
  const std::string header = firstRecordLine(text);
  if (header != expected || existing->metadataColumns() != recordingColumns()) {
    return core::Error{path.string() + ": its header '" + header +
                       "' is not the recording header '" + expected + "'; give another --out"};
  }
  // A run killed mid-line leaves no partial last line (lines are appended whole), but a
  // hand-edited file may lack the final newline.
  if (text.back() != '\n') {
    if (std::string error = core::appendDurably(path, "\n"); !error.empty())
      return core::Error{error};
  }
  return existing;
}

std::string_view toString(HeadingSource source) {
  constexpr std::array<std::string_view, 3> kNames = {"course", "track", "none"};  // enum order
  return kNames[static_cast<std::size_t>(source)];
}

MapRecorder::MapRecorder(LocationMap map, MapRecorderOptions options,
                         std::chrono::sys_days fallback_date)
    : options_(std::move(options)),
      map_(std::move(map)),
      assembler_(fallback_date),
      parser_([this](const Sentence& sentence) { onSentence(sentence, stamp_); }) {
  next_number_ = options_.start_id ? *options_.start_id : highestNumber() + 1;
}

void MapRecorder::feed(std::string_view bytes, const core::ReceptionStamp& received) {
  stamp_ = received;
  parser_.feed(bytes);
}

void MapRecorder::flush() {
  parser_.flush();
}

void MapRecorder::onSentence(const Sentence& sentence, const core::ReceptionStamp& received) {
  if (const std::optional<core::GpsFix> fix = assembler_.add(sentence, received))
    addFix(*fix);
}

void MapRecorder::addFix(const core::GpsFix& fix) {
  // The assembler refines an epoch sentence by sentence: replace, don't append.
  if (!recent_.empty() && recent_.back().time == fix.time)
    recent_.pop_back();
  if (fix.valid)
    recent_.push_back(fix);
  while (!recent_.empty() && fix.received.steady - recent_.front().received.steady > kFixHistory) {
    recent_.pop_front();
  }
}

core::Result<RecordedLocation> MapRecorder::mark(core::SteadyTime now) {
  if (recent_.empty())
    return core::Error{"no valid fix yet"};
  RecordedLocation recorded;
  recorded.fix = recent_.back();
  const core::GpsFix& fix = recorded.fix;
  recorded.fix_age = now - fix.received.steady;
  if (recorded.fix_age > kMaxMarkFixAge) {
    return core::Error{
        fmt::format("the latest valid fix is {:.2f} s old", core::toSeconds(recorded.fix_age))};
  }

  ImagingLocation& location = recorded.location;
  while (map_.find(options_.id_prefix + std::to_string(next_number_)) != nullptr)
    ++next_number_;
  location.id = options_.id_prefix + std::to_string(next_number_);
  location.latitude_deg = fix.latitude_deg;
  location.longitude_deg = fix.longitude_deg;
  // At a standstill (operators stop on the spot to mark it) receivers report course 0 or a
  // stale value: a course counts only while moving.
  if (fix.course_deg && *fix.course_deg >= 0 && *fix.course_deg < 360 && fix.speed_mps &&
      *fix.speed_mps >= kMinCourseSpeedMps) {
    location.heading_deg = fix.course_deg;
    recorded.heading_source = HeadingSource::kCourse;
  } else if (const std::optional<double> bearing = trackBearing()) {
    location.heading_deg = bearing;
    recorded.heading_source = HeadingSource::kTrack;
  }
  location.metadata = {core::formatIso8601(fix.time, 3),
                       fix.speed_mps ? fmt::format("{:.3f}", *fix.speed_mps) : std::string(),
                       fix.quality ? std::to_string(static_cast<int>(*fix.quality)) : ""};
  if (core::Result<void> added = map_.add(location); !added)
    return added.error();
  ++next_number_;
  return recorded;
}

long MapRecorder::highestNumber() const {
  long highest = 0;
  const std::string& prefix = options_.id_prefix;
  for (const ImagingLocation& location : map_.locations()) {
    const std::string& id = location.id;
    if (id.size() <= prefix.size() || id.compare(0, prefix.size(), prefix) != 0)
      continue;
    long number = 0;
    const char* end = id.data() + id.size();
    const auto [ptr, ec] = std::from_chars(id.data() + prefix.size(), end, number);
    if (ec == std::errc() && ptr == end)
      highest = std::max(highest, number);
  }
  return highest;
}

std::optional<double> MapRecorder::trackBearing() const {
  const core::GpsFix& latest = recent_.back();
  const LocalFrame frame(latest.latitude_deg, latest.longitude_deg);
  for (auto it = recent_.rbegin() + 1; it != recent_.rend(); ++it) {
    const EnuPoint earlier = frame.toLocal(it->latitude_deg, it->longitude_deg);
    // The vector from the earlier fix to the latest one (at the local frame's origin).
    if (std::hypot(earlier.east_m, earlier.north_m) >= kMinBearingBaseM)
      return bearingDegrees(-earlier.east_m, -earlier.north_m);
  }
  return std::nullopt;
}

}  // namespace fieldrig::gps
