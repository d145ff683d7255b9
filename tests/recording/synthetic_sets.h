// Synthetic FrameSets for the recording tests, the record_forever helper and the benchmark: six
// cameras (three stereo heads) whose pixels are a known function of trigger, camera and position,
// so that what is read back can be checked without keeping what was written.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fieldrig/recording/frame_set_record.h"

namespace fieldrig::testing_support {

inline const std::array<std::string, 6> kCameraNames{"bottom_left",  "bottom_right", "middle_left",
                                                     "middle_right", "top_left",     "top_right"};

inline std::uint8_t expectedPixel(std::uint64_t trigger_id, int camera, int x, int y) {
  return static_cast<std::uint8_t>(trigger_id * 31 + static_cast<std::uint64_t>(camera) * 7 +
                                   static_cast<std::uint64_t>(x) * 3 +
                                   static_cast<std::uint64_t>(y) * 5);
}

// Owns six frame buffers (width × height, rows `stride` apart) and lends them as FrameViews.
class SyntheticRig {
 public:
  SyntheticRig(int width, int height, int stride = 0)
      : width_(width), height_(height), stride_(stride > 0 ? stride : width) {
    for (auto& buffer : buffers_)
      buffer.assign(static_cast<std::size_t>(stride_) * static_cast<std::size_t>(height_), 0xEE);
  }

  // Fills every pixel for `trigger_id` (the padding keeps 0xEE, which must never be written).
  void fill(std::uint64_t trigger_id) {
    for (int camera = 0; camera < 6; ++camera) {
      for (int y = 0; y < height_; ++y) {
        for (int x = 0; x < width_; ++x) {
          buffers_[static_cast<std::size_t>(camera)]
                  [static_cast<std::size_t>(y) * static_cast<std::size_t>(stride_) +
                   static_cast<std::size_t>(x)] = expectedPixel(trigger_id, camera, x, y);
        }
      }
    }
  }

  // Views of the buffers as they are now, with metadata derived from `trigger_id`.
  recording::FrameSetRecord record(std::uint64_t trigger_id,
                                   std::optional<std::string> location_id) const {
    recording::FrameSetRecord set;
    set.trigger_id = trigger_id;
    set.location_id = std::move(location_id);
    set.trigger_time = core::UtcTime{} + std::chrono::hours{24 * 20000} +
                       std::chrono::milliseconds{100 * static_cast<std::int64_t>(trigger_id)};
    core::GpsFix fix;
    fix.time = set.trigger_time - std::chrono::milliseconds{40};
    fix.has_date = true;
    fix.latitude_deg = 40.0 + 1e-6 * static_cast<double>(trigger_id);
    fix.longitude_deg = -88.2;
    fix.valid = true;
    fix.speed_mps = 1.5;
    fix.course_deg = 90.0;
    fix.quality = core::FixQuality::kRtkFixed;
    fix.satellites = 14;
    fix.talker = "GN";
    set.fix = fix;
    set.skew_us = 12.5;
    for (int camera = 0; camera < 6; ++camera) {
      recording::FrameView frame;
      frame.camera_index = camera;
      frame.camera_name = kCameraNames[static_cast<std::size_t>(camera)];
      frame.width = width_;
      frame.height = height_;
      frame.stride = stride_;
      frame.pixel_format = core::PixelFormat::kBayerRG8;
      frame.pixels = buffers_[static_cast<std::size_t>(camera)];
      frame.device_timestamp_ns = static_cast<std::int64_t>(trigger_id) * 100'000'000 + camera;
      frame.sequence = trigger_id;
      frame.received = core::ReceptionStamp::now();
      set.frames.push_back(std::move(frame));
    }
    return set;
  }

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_;
  int height_;
  int stride_;
  std::array<std::vector<std::uint8_t>, 6> buffers_;
};

}  // namespace fieldrig::testing_support
