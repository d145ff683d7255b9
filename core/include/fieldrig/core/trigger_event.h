// A camera trigger decided by the GPS chain: which imaging location, when, and how sure.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fieldrig/core/gps_fix.h"
#include "fieldrig/core/time.h"

namespace fieldrig::core {

enum class TriggerStatus {
  kOnTime,  // fired at the predicted crossing
  kLate,    // the crossing was noticed after it happened (gap in fixes, rate limit)
};

inline std::string_view toString(TriggerStatus status) {
  return status == TriggerStatus::kOnTime ? "on_time" : "late";
}

struct TriggerEvent {
  std::uint64_t trigger_id = 0;  // increasing, unique within a run
  std::string location_id;       // the imaging-location map's id
  UtcTime time{};                // GPS time at which the trigger fires
  UtcTime planned_time{};        // the predicted crossing (equals `time` unless late)
  TriggerStatus status = TriggerStatus::kOnTime;
  double speed_mps = 0;      // estimated ground speed when planned
  double course_deg = 0;     // estimated course over ground when planned
  double cross_track_m = 0;  // signed lateral offset of the location (+ = right of travel)
  // The planner's own 1-sigma uncertainty of the crossing it predicted: in time, and as the
  // along-track distance of the antenna from the location when the trigger fires.
  double timing_sigma_s = 0;
  double along_track_sigma_m = 0;
  UtcTime last_fix_time{};    // the latest fix the plan used (always before `time`)
  std::optional<GpsFix> fix;  // that fix itself: where the tractor was, as the receiver said
  // Host clock when the rig sent the trigger to the cameras (set by the rig; zero for triggers
  // that never reached one).
  UtcTime sent_time{};
};

}  // namespace fieldrig::core
