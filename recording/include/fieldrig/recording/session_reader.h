// Opens a recorded session for offline use: its description, its sets by index, trigger id or
// location id, their frames, and a check that every indexed frame is on disk intact.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/recording/session_format.h"

namespace fieldrig::recording {

// session.json, parsed.
struct SessionMetadata {
  int format_version = 0;
  std::string software_version;
  std::string start_time;  // ISO-8601 UTC as written
  nlohmann::ordered_json configuration;
  std::vector<CalibrationReference> calibration;
  std::optional<std::string> map_path;
  std::optional<std::string> map_sha256;
  nlohmann::ordered_json raw;  // the whole file, for fields this version does not know
};

// A frame loaded back: width × height bytes, rows packed.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
};

struct VerifyReport {
  std::uint64_t frames_checked = 0;
  std::uint64_t bytes_checked = 0;
  std::vector<std::string> problems;  // each names the damaged file and what is wrong with it
  bool ok() const { return problems.empty(); }
};

// The index counted: sets (complete or not) and their frames (ok or not).
struct SessionCounts {
  std::uint64_t sets = 0;
  std::uint64_t complete_sets = 0;
  std::uint64_t frames = 0;
  std::uint64_t frames_not_ok = 0;
};

// Thread contract: thread-compatible; once opened, its const members may be used from any
// number of threads at once.
class SessionReader {
 public:
  // Reads session.json and index.jsonl. A corrupt file is an error naming it (and the line); a
  // torn last index line is not: it is left out and reported by tornLine().
  static core::Result<SessionReader> open(const std::filesystem::path& dir);

  const std::filesystem::path& dir() const { return dir_; }
  const SessionMetadata& metadata() const { return metadata_; }
  const std::vector<IndexedSet>& sets() const { return sets_; }
  const std::optional<TornLine>& tornLine() const { return torn_line_; }

  const IndexedSet* bySetIndex(std::uint64_t set_index) const;
  const IndexedSet* byTriggerId(std::uint64_t trigger_id) const;
  // Every pass over a location (a plot may be imaged again on a later pass), in index order.
  std::vector<const IndexedSet*> byLocationId(std::string_view location_id) const;

  SessionCounts counts() const;
  // Bytes of every regular file below the session folder (frames, index, metadata, and whatever
  // else was stored beside them), as found now; unreadable entries count nothing.
  std::uint64_t bytesOnDisk() const;

  // The frame's image; an error names the file when it is absent, unreadable or not the PGM the
  // index describes.
  core::Result<Image> loadFrame(const IndexedFrame& frame) const;

  // Whether `image`'s pixels match the CRC-32 the index stored for `frame` (loadFrame checks the
  // file's shape, not its pixels: a frame damaged inside still loads).
  static bool pixelsMatchIndex(const IndexedFrame& frame, const Image& image);

  // Reads every indexed frame file: present, the size and PGM header the index says, pixels
  // matching the stored CRC-32.
  VerifyReport verify() const;

 private:
  std::filesystem::path dir_;
  SessionMetadata metadata_;
  std::vector<IndexedSet> sets_;
  std::optional<TornLine> torn_line_;
  std::unordered_map<std::uint64_t, std::size_t> by_set_index_;
  std::unordered_map<std::uint64_t, std::size_t> by_trigger_id_;
  std::multimap<std::string, std::size_t, std::less<>> by_location_id_;
};

}  // namespace fieldrig::recording
