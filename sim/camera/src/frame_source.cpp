#include "fieldrig/sim/frame_source.h"

namespace fieldrig::sim {

core::Frame stampedFrame(const SimTrigger& trigger, std::uint32_t camera_index, std::uint32_t width,
                         std::uint32_t height, core::PixelFormat format) {
  core::Frame frame;
  core::FrameMetadata& m = frame.metadata;
  m.camera = camera_index;
  m.trigger_id = trigger.id;
  m.width = width;
  m.height = height;
  m.stride = width;
  m.format = format;
  m.device_timestamp_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(trigger.issued.time_since_epoch())
          .count();
  return frame;
}

}  // namespace fieldrig::sim
