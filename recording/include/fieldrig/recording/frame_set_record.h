// What the recorder is given to persist: one trigger's frames with their metadata, as views of
// memory owned by someone else (the rig's pool, a test's vector), so that recording does not
// depend on how frames are allocated and copies nothing before the write.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/core/frame.h"
#include "fieldrig/core/gps_fix.h"
#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/time.h"

namespace fieldrig::recording {

// Why a frame is (or is not) what the camera should have delivered: the drivers' own status
// (ok, missing, corrupt, dropped), so frames are recorded as the rig reported them.
using FrameStatus = core::FrameStatus;

std::string_view toString(FrameStatus status);
std::optional<FrameStatus> parseFrameStatus(std::string_view name);

// One camera's frame, borrowed for the duration of SessionWriter::write().
struct FrameView {
  int camera_index = 0;     // position in the rig, 0-based
  std::string camera_name;  // "bottom_left", …; part of the file name
  int width = 0;
  int height = 0;
  core::PixelFormat pixel_format = core::PixelFormat::kMono8;
  std::span<const std::uint8_t> pixels;  // `height` rows of `stride` bytes (the last may be short)
  int stride = 0;                        // bytes from one row to the next; 0 means `width`
  std::int64_t device_timestamp_ns = 0;  // the camera's own clock
  core::ReceptionStamp received{};       // when the host got the frame
  std::uint64_t sequence = 0;            // the camera's frame counter
  FrameStatus status = FrameStatus::kOk;
  std::string reason;  // why the status is not ok ("timeout after 200 ms", …)
};

// One trigger's FrameSet: what the rig grouped, ready to be written.
struct FrameSetRecord {
  std::uint64_t trigger_id = 0;
  std::optional<std::string> location_id;  // the map's imaging location; none for manual triggers
  std::optional<core::GpsFix> fix;         // the fix the trigger was planned on, if any
  core::UtcTime trigger_time{};            // GPS time at which the trigger fired
  // From the planner's trigger event, when a location asked for the set: the predicted crossing,
  // when the rig sent the trigger (host clock), and "on_time" or "late".
  std::optional<core::UtcTime> planned_time;
  std::optional<core::UtcTime> sent_time;
  std::optional<std::string> trigger_status;
  std::vector<FrameView> frames;
  bool complete = true;  // every camera delivered an ok frame
  double skew_us = 0;    // spread of the frames' device timestamps
};

}  // namespace fieldrig::recording
