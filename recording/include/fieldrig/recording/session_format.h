// The on-disk session format, shared by the writer and the reader.
//
// A session is a folder that ordinary tools can open:
//   session.json   what recorded it: software version, configuration, calibration references,
//                  map checksum, start time (and each later reopening)
//   frames/        one binary PGM (P5, 8-bit) per frame: SSSSSS_C_name.pgm (set, camera)
//   index.jsonl    append-only, one JSON line per FrameSet; a set exists once its line, newline
//                  included, is in the file: its frames were renamed into place before
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/core/gps_fix.h"
#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/time.h"
#include "fieldrig/recording/frame_set_record.h"

namespace fieldrig::recording {

inline constexpr std::string_view kSessionFile = "session.json";
inline constexpr std::string_view kIndexFile = "index.jsonl";
inline constexpr std::string_view kFramesDir = "frames";
inline constexpr int kFormatVersion = 1;

// The software version written into session.json (the project's version).
std::string_view softwareVersion();

// A calibration file the session's images are to be interpreted with.
struct CalibrationReference {
  std::string name;  // "head_bottom", "extrinsics", …
  std::string path;  // as the configuration named it
};

// What the caller tells SessionWriter::open() about the run.
struct SessionInfo {
  nlohmann::ordered_json configuration = nlohmann::ordered_json::object();
  std::vector<CalibrationReference> calibration;
  std::optional<std::filesystem::path> map_file;  // its SHA-256 goes into session.json
  core::SystemTime start_time = std::chrono::system_clock::now();
};

// How much the writer asks the kernel to put on the disk before a set counts as recorded.
// kNone survives a crash of the process (kill -9) but not a power loss; kPerSet and kPerFrame
// survive both, kPerFrame at the cost of a flush per file.
enum class FsyncPolicy { kNone, kPerSet, kPerFrame };

std::string_view toString(FsyncPolicy policy);
std::optional<FsyncPolicy> parseFsyncPolicy(std::string_view name);  // "none", "per_set", …

// A frame as the index describes it.
struct IndexedFrame {
  int camera_index = 0;
  std::string camera_name;
  std::string file;  // relative to the session folder; empty when there is no image (missing)
  int width = 0;
  int height = 0;
  core::PixelFormat pixel_format = core::PixelFormat::kMono8;
  std::uint64_t file_bytes = 0;  // the PGM file, header included
  std::uint32_t crc32 = 0;       // of the pixels (width × height bytes, no header, no padding)
  std::uint64_t sequence = 0;
  std::int64_t device_timestamp_ns = 0;
  std::int64_t host_steady_ns = 0;  // steady clock since its epoch (boot)
  std::int64_t host_system_ns = 0;  // system clock since 1970
  FrameStatus status = FrameStatus::kOk;
  std::string reason;
};

// A FrameSet as the index describes it.
struct IndexedSet {
  std::uint64_t set_index = 0;  // 0, 1, 2… across reopenings
  std::uint64_t trigger_id = 0;
  std::optional<std::string> location_id;
  std::optional<core::GpsFix> fix;  // its reception stamp is not recorded
  core::UtcTime trigger_time{};
  // From the planner's trigger event, when a location asked for the set: the predicted crossing,
  // when the rig sent the trigger (host clock), and "on_time" or "late".
  std::optional<core::UtcTime> planned_time;
  std::optional<core::UtcTime> sent_time;
  std::optional<std::string> trigger_status;
  bool complete = true;
  double skew_us = 0;
  std::vector<IndexedFrame> frames;
};

// A last index line without its newline: a write cut short by a crash. Ignored by the reader,
// cut away by the writer when it reopens the session.
struct TornLine {
  std::uint64_t line = 0;    // 1-based line number in index.jsonl
  std::uint64_t offset = 0;  // where it starts
  std::uint64_t bytes = 0;   // its length
};

// Frame file name for camera `camera_index` ("bottom_left") of set `set_index`, relative to the
// session folder: "frames/000042_0_bottom_left.pgm".
std::string frameFileName(std::uint64_t set_index, int camera_index, std::string_view camera_name);

// The index line (without newline) of a set, and back. fromIndexLine's error names no file; the
// caller adds "index.jsonl:LINE: ".
std::string toIndexLine(const IndexedSet& set);
std::optional<IndexedSet> fromIndexLine(std::string_view line, std::string& error);

}  // namespace fieldrig::recording
