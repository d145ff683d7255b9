// Recording an imaging-location map by driving the field once: the operator marks each location
// and the mark becomes the latest fix's position, with a heading and the next free id.
//
// MapRecorder is pure and thread-compatible: fixes (or the sentences and bytes they come from,
// with their reception stamps) and the time of each mark are arguments; it prints and writes
// nothing. openRecordingMap() and a durable append of MapRecorder::map().csvLine() are the file
// side (`fieldrig map record`).
#pragma once

#include <chrono>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/core/gps_fix.h"
#include "fieldrig/core/result.h"
#include "fieldrig/core/time.h"
#include "fieldrig/gps/fix_assembler.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::gps {

// A mark needs a fix received this recently; older means the receiver or the link stalled and
// the position no longer says where the tractor is.
inline constexpr std::chrono::seconds kMaxMarkFixAge{2};

// The metadata columns of a recorded map, after id, lat, lon, heading: time, speed_mps, quality.
const std::vector<std::string>& recordingColumns();

// Opens the map file a recording appends to, durably: a new or empty file gets the recording
// header; an existing one must be a recording map (same header), whose locations are returned,
// and a missing final newline is added. The error names the file.
core::Result<LocationMap> openRecordingMap(const std::filesystem::path& path);

enum class HeadingSource {
  kCourse,  // the receiver's course over ground, while moving
  kTrack,   // the bearing from an earlier fix at least 1 m behind
  kNone,    // neither: the location has no heading
};
std::string_view toString(HeadingSource source);

struct MapRecorderOptions {
  std::string id_prefix = "P";  // ids are <prefix><number>
  // The first number; by default one past the highest <prefix><number> already in the map.
  // Numbers already used are skipped either way.
  std::optional<long> start_id;
};

// A mark that became a location.
struct RecordedLocation {
  ImagingLocation location;  // as added to the map
  HeadingSource heading_source = HeadingSource::kNone;
  core::GpsFix fix;           // the fix it was taken from
  core::Nanoseconds fix_age;  // how old that fix was at the mark
};

class MapRecorder {
 public:
  // Continues `map` (its metadata columns are recordingColumns()). GGA carries no date: until an
  // RMC gives one, fixes are dated `fallback_date`.
  MapRecorder(LocationMap map, MapRecorderOptions options,
              std::chrono::sys_days fallback_date = std::chrono::sys_days{});

  // Raw NMEA bytes that arrived at `received`.
  void feed(std::string_view bytes, const core::ReceptionStamp& received);
  // The end of the bytes: a last line without its newline is taken too.
  void flush();
  void onSentence(const Sentence& sentence, const core::ReceptionStamp& received);
  // A fix (the assembler's refinement of an epoch replaces the epoch's earlier fix); invalid
  // fixes are never marked.
  void addFix(const core::GpsFix& fix);

  // Marks the latest valid fix at steady time `now`: the location is added to map() and
  // returned. An error, and nothing added, without a valid fix received in the last
  // kMaxMarkFixAge.
  core::Result<RecordedLocation> mark(core::SteadyTime now);

  const LocationMap& map() const { return map_; }

 private:
  long highestNumber() const;
  std::optional<double> trackBearing() const;

  MapRecorderOptions options_;
  LocationMap map_;
  FixAssembler assembler_;
  NmeaParser parser_;
  core::ReceptionStamp stamp_{};     // of the bytes being parsed
  std::deque<core::GpsFix> recent_;  // valid fixes of the last few seconds, oldest first
  long next_number_ = 1;
};

}  // namespace fieldrig::gps
