#include "fieldrig/recording/session_format.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace fieldrig::recording {
namespace {

using Json = nlohmann::ordered_json;

template <typename T>
Json optionalJson(const std::optional<T>& value) {
  return value ? Json(*value) : Json(nullptr);
}

template <typename T>
std::optional<T> optionalFrom(const Json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end() || it->is_null())
    return std::nullopt;
  return it->template get<T>();
}

// A whole number of type T, or an error naming the key. nlohmann's get<T>() converts a fraction or
// a number beyond T with a plain cast: wrapped values, and undefined behaviour for a float such as
// 1e300 (the session index fuzzer found it).
template <typename T>
T whole(const Json& value, const char* key) {
  if (value.is_number_unsigned() && std::in_range<T>(value.get<std::uint64_t>()))
    return static_cast<T>(value.get<std::uint64_t>());
  if (value.is_number_integer() && !value.is_number_unsigned() &&
      std::in_range<T>(value.get<std::int64_t>()))
    return static_cast<T>(value.get<std::int64_t>());
  throw std::invalid_argument(std::string("'") + key + "' is not a whole number in [" +
                              std::to_string(std::numeric_limits<T>::min()) + ", " +
                              std::to_string(std::numeric_limits<T>::max()) + "]");
}

template <typename T>
std::optional<T> optionalWhole(const Json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end() || it->is_null())
    return std::nullopt;
  return whole<T>(*it, key);
}

Json fixJson(const core::GpsFix& fix) {
  Json out;
  out["time"] = core::formatIso8601(fix.time, 9);
  out["has_date"] = fix.has_date;
  out["lat"] = fix.latitude_deg;
  out["lon"] = fix.longitude_deg;
  out["valid"] = fix.valid;
  out["speed_mps"] = optionalJson(fix.speed_mps);
  out["course_deg"] = optionalJson(fix.course_deg);
  out["altitude_m"] = optionalJson(fix.altitude_m);
  out["hdop"] = optionalJson(fix.hdop);
  out["quality"] = fix.quality ? Json(static_cast<int>(*fix.quality)) : Json(nullptr);
  out["satellites"] = optionalJson(fix.satellites);
  out["talker"] = fix.talker;
  return out;
}

core::UtcTime timeFrom(const Json& value, const char* what) {
  const std::optional<core::UtcTime> time = core::parseIso8601(value.get<std::string>());
  if (!time)
    throw std::invalid_argument(std::string("'") + what + "' is not an ISO-8601 UTC time");
  return *time;
}

// An angle in [-limit, limit] degrees, or an error naming the key: a damaged or hand-edited
// latitude of 500 would place the set nowhere on Earth, and the map placement and the geodesic
// distances after it would take it as given.
double degreesWithin(const Json& value, const char* key, double limit) {
  const double degrees = value.get<double>();
  if (!(degrees >= -limit && degrees <= limit))
    throw std::invalid_argument(std::string("'") + key + "' is " + value.dump() +
                                ", not an angle in [-" + std::to_string(static_cast<int>(limit)) +
                                ", " + std::to_string(static_cast<int>(limit)) + "] degrees");
  return degrees;
}

core::GpsFix fixFrom(const Json& in) {
  core::GpsFix fix;
  fix.time = timeFrom(in.at("time"), "gps.time");
  fix.has_date = in.at("has_date").get<bool>();
  fix.latitude_deg = degreesWithin(in.at("lat"), "gps.lat", 90.0);
  fix.longitude_deg = degreesWithin(in.at("lon"), "gps.lon", 180.0);
  fix.valid = in.at("valid").get<bool>();
  fix.speed_mps = optionalFrom<double>(in, "speed_mps");
  fix.course_deg = optionalFrom<double>(in, "course_deg");
  fix.altitude_m = optionalFrom<double>(in, "altitude_m");
  fix.hdop = optionalFrom<double>(in, "hdop");
  if (const std::optional<int> quality = optionalWhole<int>(in, "quality"))
    fix.quality = static_cast<core::FixQuality>(*quality);
  fix.satellites = optionalWhole<int>(in, "satellites");
  fix.talker = in.value("talker", std::string());
  return fix;
}

Json frameJson(const IndexedFrame& frame) {
  Json out;
  out["camera"] = frame.camera_index;
  out["name"] = frame.camera_name;
  out["file"] = frame.file.empty() ? Json(nullptr) : Json(frame.file);
  out["width"] = frame.width;
  out["height"] = frame.height;
  out["pixel_format"] = core::toString(frame.pixel_format);
  out["file_bytes"] = frame.file_bytes;
  out["crc32"] = frame.crc32;
  out["sequence"] = frame.sequence;
  out["device_ns"] = frame.device_timestamp_ns;
  out["host_steady_ns"] = frame.host_steady_ns;
  out["host_system_ns"] = frame.host_system_ns;
  out["status"] = toString(frame.status);
  out["reason"] = frame.reason;
  return out;
}

IndexedFrame frameFrom(const Json& in) {
  IndexedFrame frame;
  frame.camera_index = whole<int>(in.at("camera"), "camera");
  frame.camera_name = in.at("name").get<std::string>();
  if (!in.at("file").is_null()) {
    frame.file = in.at("file").get<std::string>();
    // Readers join it to the session folder: a damaged or hand-edited index must not make them
    // read (or verify, or replay) a file outside it.
    const std::filesystem::path file(frame.file);
    if (file.is_absolute() || std::find(file.begin(), file.end(), "..") != file.end())
      throw std::invalid_argument("frame file '" + frame.file + "' is outside the session folder");
  }
  frame.width = whole<int>(in.at("width"), "width");
  frame.height = whole<int>(in.at("height"), "height");
  const std::optional<core::PixelFormat> format =
      core::parsePixelFormat(in.at("pixel_format").get<std::string>());
  if (!format)
    throw std::invalid_argument("unknown pixel_format '" +
                                in.at("pixel_format").get<std::string>() + "'");
  frame.pixel_format = *format;
  frame.file_bytes = whole<std::uint64_t>(in.at("file_bytes"), "file_bytes");
  frame.crc32 = whole<std::uint32_t>(in.at("crc32"), "crc32");
  frame.sequence = whole<std::uint64_t>(in.at("sequence"), "sequence");
  frame.device_timestamp_ns = whole<std::int64_t>(in.at("device_ns"), "device_ns");
  frame.host_steady_ns = whole<std::int64_t>(in.at("host_steady_ns"), "host_steady_ns");
  frame.host_system_ns = whole<std::int64_t>(in.at("host_system_ns"), "host_system_ns");
  const std::optional<FrameStatus> status = parseFrameStatus(in.at("status").get<std::string>());
  if (!status)
    throw std::invalid_argument("unknown frame status '" + in.at("status").get<std::string>() +
                                "'");
  frame.status = *status;
  frame.reason = in.value("reason", std::string());
  if (frame.width < 0 || frame.height < 0)
    throw std::invalid_argument("negative frame size");
  return frame;
}

}  // namespace

std::string_view softwareVersion() {
  return FIELDRIG_VERSION;
}

std::string_view toString(FrameStatus status) {
  switch (status) {
    case FrameStatus::kOk:
      return "ok";
    case FrameStatus::kMissing:
      return "missing";
    case FrameStatus::kCorrupt:
      return "corrupt";
    case FrameStatus::kDropped:
      return "dropped";
  }
  return "unknown";
}

std::optional<FrameStatus> parseFrameStatus(std::string_view name) {
  for (FrameStatus status :
       {FrameStatus::kOk, FrameStatus::kMissing, FrameStatus::kCorrupt, FrameStatus::kDropped}) {
    if (toString(status) == name)
      return status;
  }
  return std::nullopt;
}

std::string_view toString(FsyncPolicy policy) {
  switch (policy) {
    case FsyncPolicy::kNone:
      return "none";
    case FsyncPolicy::kPerSet:
      return "per_set";
    case FsyncPolicy::kPerFrame:
      return "per_frame";
  }
  return "unknown";
}

std::optional<FsyncPolicy> parseFsyncPolicy(std::string_view name) {
  for (FsyncPolicy policy : {FsyncPolicy::kNone, FsyncPolicy::kPerSet, FsyncPolicy::kPerFrame}) {
    if (toString(policy) == name)
      return policy;
  }
  return std::nullopt;
}

std::string frameFileName(std::uint64_t set_index, int camera_index, std::string_view camera_name) {
  // The name is only a hint for people browsing the folder; anything that is not safe in a file
  // name on every system becomes '_'.
  std::string safe;
  for (char c : camera_name) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '-' || c == '_';
    safe += plain ? c : '_';
  }
  char prefix[48];
  std::snprintf(prefix, sizeof prefix, "%06llu_%d", static_cast<unsigned long long>(set_index),
                camera_index);
  std::string name = std::string(kFramesDir) + "/" + prefix;
  if (!safe.empty())
    name += "_" + safe;
  return name + ".pgm";
}

std::string toIndexLine(const IndexedSet& set) {
  Json out;
  out["set"] = set.set_index;
  out["trigger_id"] = set.trigger_id;
  out["location_id"] = optionalJson(set.location_id);
  out["trigger_time"] = core::formatIso8601(set.trigger_time, 9);
  // Written only for sets a location asked for, so that older readers see the lines they know.
  if (set.planned_time)
    out["planned_time"] = core::formatIso8601(*set.planned_time, 9);
  if (set.sent_time)
    out["sent_time"] = core::formatIso8601(*set.sent_time, 9);
  if (set.trigger_status)
    out["trigger_status"] = *set.trigger_status;
  out["complete"] = set.complete;
  out["skew_us"] = set.skew_us;
  out["gps"] = set.fix ? fixJson(*set.fix) : Json(nullptr);
  Json frames = Json::array();
  for (const IndexedFrame& frame : set.frames)
    frames.push_back(frameJson(frame));
  out["frames"] = std::move(frames);
  // Replacement of invalid UTF-8 keeps a bad camera name or reason from failing a live write.
  return out.dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::optional<IndexedSet> fromIndexLine(std::string_view line, std::string& error) {
  try {
    const Json in = Json::parse(line);
    if (!in.is_object()) {
      error = "not a JSON object";
      return std::nullopt;
    }
    IndexedSet set;
    set.set_index = whole<std::uint64_t>(in.at("set"), "set");
    set.trigger_id = whole<std::uint64_t>(in.at("trigger_id"), "trigger_id");
    set.location_id = optionalFrom<std::string>(in, "location_id");
    set.trigger_time = timeFrom(in.at("trigger_time"), "trigger_time");
    if (in.contains("planned_time"))
      set.planned_time = timeFrom(in.at("planned_time"), "planned_time");
    if (in.contains("sent_time"))
      set.sent_time = timeFrom(in.at("sent_time"), "sent_time");
    set.trigger_status = optionalFrom<std::string>(in, "trigger_status");
    set.complete = in.at("complete").get<bool>();
    set.skew_us = in.at("skew_us").get<double>();
    if (!in.at("gps").is_null())
      set.fix = fixFrom(in.at("gps"));
    for (const Json& frame : in.at("frames"))
      set.frames.push_back(frameFrom(frame));
    return set;
  } catch (const std::exception& e) {
    error = e.what();
    return std::nullopt;
  }
}

}  // namespace fieldrig::recording
