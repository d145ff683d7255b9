// A camera frame and a set of frames of one trigger, as they travel from the rig to the
// recorder and the pipeline. Value types: copying shares the pixel buffers (FrameBuffer is a
// counted reference into a FramePool) and allocates nothing.
#pragma once

#include <array>
#include <cstdint>

#include "fieldrig/core/frame_pool.h"
#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/time.h"
#include "fieldrig/core/trigger_event.h"

namespace fieldrig::core {

enum class FrameStatus : std::uint8_t {
  kOk,
  kMissing,  // the camera delivered nothing for this trigger before the rig's timeout
  kCorrupt,  // delivered, but incomplete or damaged (lost packets, bad size)
  kDropped,  // no buffer was free: the pool was exhausted
};

struct FrameMetadata {
  std::uint32_t camera = 0;  // index in the rig (0-5: bottom L/R, middle L/R, top L/R)
  std::uint64_t trigger_id = 0;
  std::uint64_t sequence = 0;  // the camera's own frame counter
  std::int64_t device_timestamp_ns = 0;
  ReceptionStamp received{};  // when the host got the frame
  FrameStatus status = FrameStatus::kOk;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint32_t stride = 0;  // bytes per row
  PixelFormat format = PixelFormat::kMono8;
};

struct Frame {
  FrameBuffer buffer;  // empty when status is not kOk/kCorrupt
  FrameMetadata metadata;
};

// The frames of one trigger. Fixed capacity so that moving sets through queues never allocates.
struct FrameSet {
  static constexpr std::size_t kMaxCameras = 8;

  std::uint64_t trigger_id = 0;
  // What the trigger was for: location, fix, planned and sent times (trigger.trigger_id equals
  // trigger_id). Its strings fit the small-string buffer for map ids of up to 15 characters, so
  // moving a set through the queues still allocates nothing in the field.
  TriggerEvent trigger;
  std::uint32_t camera_count = 0;
  std::array<Frame, kMaxCameras> frames{};
  std::int64_t skew_ns = 0;  // spread of the device timestamps of the frames present

  bool complete() const {
    for (std::uint32_t i = 0; i < camera_count; ++i) {
      if (frames[i].metadata.status != FrameStatus::kOk)
        return false;
    }
    return camera_count > 0;
  }
};

}  // namespace fieldrig::core
