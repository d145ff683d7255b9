#include "fieldrig/recording/session_reader.h"

#include "file_util.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

core::Result<SessionMetadata> parseSessionJson(const fs::path& path) {
  std::string error;
  const std::optional<std::string> text = detail::readWholeFile(path, error);
  if (!text)
    return core::Error{error};
  SessionMetadata metadata;
  try {
    metadata.raw = Json::parse(*text);
  } catch (const Json::parse_error& e) {
    return core::Error{path.string() + ":" + detail::lineOf(*text, e.byte) + ": " + e.what()};
  }
  const Json& raw = metadata.raw;
  try {
    if (!raw.is_object())
      throw std::invalid_argument("not a JSON object");
    if (raw.at("format").get<std::string>() != "fieldrig-session")
      throw std::invalid_argument("'format' is not \"fieldrig-session\"");
    metadata.format_version = raw.at("format_version").get<int>();
    if (metadata.format_version > kFormatVersion) {
      throw std::invalid_argument("format_version " + std::to_string(metadata.format_version) +
                                  " is newer than this reader's " + std::to_string(kFormatVersion));
    }
    metadata.software_version = raw.at("software_version").get<std::string>();
    metadata.start_time = raw.at("start_time").get<std::string>();
    metadata.configuration = raw.value("configuration", Json::object());
    for (const Json& reference : raw.value("calibration", Json::array())) {
      metadata.calibration.push_back(
          {reference.at("name").get<std::string>(), reference.at("path").get<std::string>()});
    }
    if (raw.contains("map") && !raw.at("map").is_null()) {
      metadata.map_path = raw.at("map").at("path").get<std::string>();
      metadata.map_sha256 = raw.at("map").at("sha256").get<std::string>();
    }
  } catch (const std::exception& e) {
    // Not a syntax error: the whole file is the place.
    return core::Error{path.string() + ": " + e.what()};
  }
  return metadata;
}

}  // namespace

core::Result<SessionReader> SessionReader::open(const fs::path& dir) {
  SessionReader reader;
  reader.dir_ = dir;
  core::Result<SessionMetadata> metadata = parseSessionJson(dir / kSessionFile);
  if (!metadata)
    return metadata.error();
  reader.metadata_ = std::move(metadata.value());

  const fs::path index_path = dir / kIndexFile;
  std::string error;
  const std::optional<std::string> content = detail::readWholeFile(index_path, error);
  if (!content)
    return core::Error{error};
  core::Result<detail::IndexScan> scan = detail::scanIndex(*content, index_path);
  if (!scan)
    return scan.error();
  reader.sets_ = std::move(scan->sets);
  reader.torn_line_ = scan->torn_line;
  for (std::size_t k = 0; k < reader.sets_.size(); ++k) {
    const IndexedSet& set = reader.sets_[k];
    reader.by_set_index_.emplace(set.set_index, k);
    // Trigger ids restart with each run; after a reopening the first set keeps the id.
    reader.by_trigger_id_.emplace(set.trigger_id, k);
    if (set.location_id)
      reader.by_location_id_.emplace(*set.location_id, k);
  }
  return reader;
}

const IndexedSet* SessionReader::bySetIndex(std::uint64_t set_index) const {
  const auto it = by_set_index_.find(set_index);
  return it == by_set_index_.end() ? nullptr : &sets_[it->second];
}

const IndexedSet* SessionReader::byTriggerId(std::uint64_t trigger_id) const {
  const auto it = by_trigger_id_.find(trigger_id);
  return it == by_trigger_id_.end() ? nullptr : &sets_[it->second];
}

std::vector<const IndexedSet*> SessionReader::byLocationId(std::string_view location_id) const {
  std::vector<const IndexedSet*> found;
  const auto [first, last] = by_location_id_.equal_range(location_id);
  for (auto it = first; it != last; ++it)
    found.push_back(&sets_[it->second]);
  return found;
}

SessionCounts SessionReader::counts() const {
  SessionCounts counts;
  counts.sets = sets_.size();
  for (const IndexedSet& set : sets_) {
    counts.complete_sets += set.complete ? 1 : 0;
    counts.frames += set.frames.size();
    for (const IndexedFrame& frame : set.frames)
      counts.frames_not_ok += frame.status == FrameStatus::kOk ? 0 : 1;
  }
  return counts;
}

std::uint64_t SessionReader::bytesOnDisk() const {
  std::uint64_t bytes = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir_, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    std::error_code size_ec;
    if (it->is_regular_file(size_ec)) {
      const std::uintmax_t size = it->file_size(size_ec);
      if (!size_ec)
        bytes += size;
    }
  }
  return bytes;
}

core::Result<Image> SessionReader::loadFrame(const IndexedFrame& frame) const {
  if (frame.file.empty())
    return core::Error{"camera " + std::to_string(frame.camera_index) + " (" + frame.camera_name +
                       "): no image recorded (" + std::string(toString(frame.status)) + ")"};
  const fs::path path = dir_ / frame.file;
  std::string error;
  const std::optional<std::string> content = detail::readWholeFile(path, error);
  if (!content)
    return core::Error{error};
  const std::optional<detail::PgmHeader> header = detail::parsePgmHeader(*content);
  if (!header || header->max_value != 255)
    return core::Error{path.string() + ": not an 8-bit binary PGM"};
  if (header->width != frame.width || header->height != frame.height) {
    return core::Error{path.string() + ": PGM is " + std::to_string(header->width) + "x" +
                       std::to_string(header->height) + ", the index says " +
                       std::to_string(frame.width) + "x" + std::to_string(frame.height)};
  }
  const std::size_t pixel_bytes =
      static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height);
  if (content->size() != header->header_bytes + pixel_bytes) {
    return core::Error{path.string() + ": " + std::to_string(content->size()) +
                       " bytes, expected " + std::to_string(header->header_bytes + pixel_bytes)};
  }
  Image image;
  image.width = frame.width;
  image.height = frame.height;
  const auto* begin = reinterpret_cast<const std::uint8_t*>(content->data()) + header->header_bytes;
  image.pixels.assign(begin, begin + pixel_bytes);
  return image;
}

bool SessionReader::pixelsMatchIndex(const IndexedFrame& frame, const Image& image) {
  return detail::crc32(image.pixels) == frame.crc32;
}

VerifyReport SessionReader::verify() const {
  VerifyReport report;
  for (const IndexedSet& set : sets_) {
    for (const IndexedFrame& frame : set.frames) {
      if (frame.file.empty()) {
        if (frame.status == FrameStatus::kOk) {
          report.problems.push_back("set " + std::to_string(set.set_index) + " camera " +
                                    std::to_string(frame.camera_index) +
                                    ": status ok but no file in the index");
        }
        continue;
      }
      ++report.frames_checked;
      core::Result<Image> image = loadFrame(frame);
      if (!image) {
        report.problems.push_back(image.error().message);
        continue;
      }
      // The index's size is what `session info` and the stem tool report: a size the file does
      // not have is a damaged index line even when the pixels are whole.
      std::error_code ec;
      const std::uintmax_t bytes = fs::file_size(dir_ / frame.file, ec);
      if (!ec && bytes != frame.file_bytes) {
        report.problems.push_back((dir_ / frame.file).string() + ": " + std::to_string(bytes) +
                                  " bytes, the index says " + std::to_string(frame.file_bytes));
      }
      report.bytes_checked += ec ? frame.file_bytes : bytes;
      const std::uint32_t crc = detail::crc32(image->pixels);
      if (crc != frame.crc32) {
        char text[64];
        std::snprintf(text, sizeof text, ": CRC-32 %08x, the index says %08x", crc, frame.crc32);
        report.problems.push_back((dir_ / frame.file).string() + text);
      }
    }
  }
  return report;
}

}  // namespace fieldrig::recording
