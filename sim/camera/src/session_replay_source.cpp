#include "fieldrig/sim/session_replay_source.h"

#include <algorithm>
#include <cstring>
#include <optional>
#include <string>

namespace fieldrig::sim {
namespace {

std::string sizeText(std::uint64_t width, std::uint64_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace

core::Result<std::unique_ptr<SessionReplaySource>> SessionReplaySource::open(
    const drivers::CameraConfig& config, std::uint32_t camera_index,
    const std::filesystem::path& session, std::uint64_t preload_mb) {
  const std::string where = "sim camera " + config.id + ": session '" + session.string() + "': ";
  auto opened = recording::SessionReader::open(session);
  if (!opened)
    return core::Error{where + opened.error().message};
  std::unique_ptr<SessionReplaySource> source(new SessionReplaySource(std::move(opened).value()));
  const std::vector<recording::IndexedSet>& sets = source->reader_.sets();
  if (sets.empty())
    return core::Error{where + "no sets recorded"};
  source->entries_.resize(sets.size());
  std::uint64_t listed = 0;       // sets that name this camera, with or without pixels
  std::uint64_t pixel_bytes = 0;  // of this camera's frames with pixels
  for (std::size_t s = 0; s < sets.size(); ++s) {
    Entry& entry = source->entries_[s];
    // Offsets from the earliest frame with pixels: frames without have no meaningful timestamp.
    std::optional<std::int64_t> earliest;
    for (const recording::IndexedFrame& frame : sets[s].frames) {
      if (!frame.file.empty())
        earliest =
            std::min(earliest.value_or(frame.device_timestamp_ns), frame.device_timestamp_ns);
      if (frame.camera_index == static_cast<int>(camera_index))
        entry.frame = &frame;
    }
    if (entry.frame == nullptr)
      continue;
    ++listed;
    if (entry.frame->file.empty())
      continue;
    entry.offset_ns = entry.frame->device_timestamp_ns - *earliest;
    if (static_cast<std::uint64_t>(entry.frame->width) != config.width ||
        static_cast<std::uint64_t>(entry.frame->height) != config.height) {
      return core::Error{where + entry.frame->file + " is " +
                         sizeText(static_cast<std::uint64_t>(entry.frame->width),
                                  static_cast<std::uint64_t>(entry.frame->height)) +
                         ", the camera is configured " + sizeText(config.width, config.height) +
                         ": configure the recorded size"};
    }
    pixel_bytes += std::uint64_t{config.width} * config.height;
  }
  if (listed == 0) {
    return core::Error{where + "no frame of camera " + std::to_string(camera_index) + " in its " +
                       std::to_string(sets.size()) + " sets"};
  }
  constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
  source->preloaded_ = (pixel_bytes + kMiB - 1) / kMiB <= preload_mb;
  if (source->preloaded_) {
    for (Entry& entry : source->entries_) {
      if (entry.frame == nullptr || entry.frame->file.empty())
        continue;
      auto image = source->reader_.loadFrame(*entry.frame);
      if (!image)
        return core::Error{where + image.error().message};
      entry.damaged = !recording::SessionReader::pixelsMatchIndex(*entry.frame, *image);
      entry.pixels = std::move(image->pixels);
    }
  }
  return source;
}

bool SessionReplaySource::fill(const SimTrigger& trigger, core::FramePool& pool,
                               core::Frame& frame) {
  core::FrameMetadata& m = frame.metadata;
  const Entry& entry = entries_[trigger.since_first % entries_.size()];
  const recording::IndexedFrame* recorded = entry.frame;
  if (recorded == nullptr)
    return false;  // the camera was not in this set: it is missing again
  if (recorded->file.empty() && recorded->status != recording::FrameStatus::kDropped)
    return false;  // recorded missing: deliver nothing, the rig's timeout marks it again
  m.format = recorded->pixel_format;
  m.device_timestamp_ns += entry.offset_ns;
  if (recorded->file.empty()) {
    m.status = core::FrameStatus::kDropped;
    return true;
  }
  frame.buffer = pool.acquire();
  if (!frame.buffer) {
    m.status = core::FrameStatus::kDropped;
    return true;
  }
  // The width × height was checked by open(): the recorded rows are packed like the buffer.
  std::uint8_t* out = frame.buffer.bytes().data();
  const std::size_t bytes = std::size_t{m.width} * m.height;
  // A frame whose pixels no longer match the CRC-32 recorded with them is replayed as corrupt:
  // replayed as ok, the new session would store a fresh checksum and hide the damage.
  m.status = recorded->status == recording::FrameStatus::kCorrupt ? core::FrameStatus::kCorrupt
                                                                  : core::FrameStatus::kOk;
  if (preloaded_) {
    std::memcpy(out, entry.pixels.data(), bytes);
    if (entry.damaged)
      m.status = core::FrameStatus::kCorrupt;
    return true;
  }
  // Read here, on the worker thread: a large session never has to fit in memory. loadFrame()
  // allocates the image it returns: the price of streaming (the preloaded path only copies).
  const auto image = reader_.loadFrame(*recorded);
  if (!image || image->pixels.size() != bytes) {
    std::memset(out, 0, bytes);
    m.status = core::FrameStatus::kCorrupt;
    return true;
  }
  std::memcpy(out, image->pixels.data(), bytes);
  if (!recording::SessionReader::pixelsMatchIndex(*recorded, *image))
    m.status = core::FrameStatus::kCorrupt;
  return true;
}

}  // namespace fieldrig::sim
