// Replays a recorded session: the camera's id is a camera index of the session, and trigger k
// after start() (counted by trigger id: set (id - first id) mod N of the session's N sets) serves
// that set's recorded frame of this camera. Counting by id rather than by triggers taken keeps
// the six cameras on the same set even when one of them refused a trigger. After the last set the
// replay wraps around to the first: a long replay (a bench, a soak test) never runs dry. What was
// recorded comes out again:
//   - the pixels, byte for byte, and the recorded pixel format (the configured one is ignored);
//   - kOk and kCorrupt frames with their status; a recorded kMissing frame is not delivered at
//     all, so the rig times it out as missing again; a recorded kDropped one is delivered as
//     kDropped without pixels (what the sim does when its pool is dry);
//   - the device timestamps relative to the set's earliest one, added to the trigger instant:
//     the recorded skew between cameras is the replayed skew.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/drivers/camera.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/sim/frame_source.h"

namespace fieldrig::sim {

// Thread contract: see FrameSource.
class SessionReplaySource final : public FrameSource {
 public:
  // Opens `session` for camera `camera_index`, configured as `config` (its id names the camera in
  // errors). Fails, naming the folder, when the session cannot be opened, has no sets, has no
  // frame of this camera, or when a recorded frame is not the configured width × height (the rig
  // sizes its pool from the configuration, so the configuration must say the recorded size).
  // This camera's frames are read into memory here when they total at most `preload_mb` MiB: the
  // worker then only copies, and a damaged file is an error here. A larger session is read frame
  // by frame on the worker thread: memory stays bounded whatever the session's length; a frame
  // that cannot be read then is delivered kCorrupt with zeroed pixels (the file is damaged;
  // `fieldrig session info --verify` names it).
  static core::Result<std::unique_ptr<SessionReplaySource>> open(
      const drivers::CameraConfig& config, std::uint32_t camera_index,
      const std::filesystem::path& session, std::uint64_t preload_mb);

  bool fill(const SimTrigger& trigger, core::FramePool& pool, core::Frame& frame) override;

  bool preloaded() const { return preloaded_; }

 private:
  // One recorded set, as this camera replays it.
  struct Entry {
    const recording::IndexedFrame* frame = nullptr;  // into reader_.sets(); null: not in the set
    std::int64_t offset_ns = 0;        // device timestamp after the set's earliest one
    std::vector<std::uint8_t> pixels;  // preloaded; empty when read per trigger
    bool damaged = false;              // preloaded pixels that do not match the index's CRC-32
  };

  explicit SessionReplaySource(recording::SessionReader reader) : reader_(std::move(reader)) {}

  recording::SessionReader reader_;
  std::vector<Entry> entries_;  // one per recorded set, in index order
  bool preloaded_ = false;
};

}  // namespace fieldrig::sim
