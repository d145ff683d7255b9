// Merges the RMC and GGA sentences of one receiver epoch into a core::GpsFix.
// Thread-compatible; pure (reception times are passed in).
//
// RMC carries date, speed and course; GGA carries fix quality, satellites, HDOP and altitude.
// Receivers send both for each epoch, in either order; each sentence yields an updated fix for
// its epoch at once (no waiting for the partner, which may never come), so consumers should
// treat a second fix with the same time as a refinement, not a new position.
#pragma once

#include <chrono>
#include <optional>

#include "fieldrig/core/gps_fix.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::gps {

class FixAssembler {
 public:
  // GGA carries no date: until an RMC gives one, `fallback_date` is used and the fix says
  // has_date = false.
  explicit FixAssembler(std::chrono::sys_days fallback_date = std::chrono::sys_days{});

  // A fix for an intact RMC or GGA sentence with a time; nullopt for anything else.
  std::optional<core::GpsFix> add(const Sentence& sentence, const core::ReceptionStamp& received);

 private:
  std::optional<core::UtcTime> dateTimeFor(core::Nanoseconds time_of_day);

  std::chrono::sys_days fallback_date_;
  std::optional<core::UtcTime> last_rmc_time_;       // date source for GGA
  std::optional<core::UtcTime> last_dateless_time_;  // GGA time before any RMC: day rollover
  std::optional<core::GpsFix> epoch_;                // the epoch being assembled
  bool epoch_has_rmc_ = false;
  bool epoch_has_gga_ = false;
  bool rmc_valid_ = false;
  bool gga_valid_ = false;
};

}  // namespace fieldrig::gps
