// A GPS fix as the rest of fieldrig sees it, whatever NMEA sentence(s) it came from.
#pragma once

#include <optional>
#include <string>

#include "fieldrig/core/time.h"

namespace fieldrig::core {

// GGA fix quality indicator (NMEA 0183).
enum class FixQuality : int {
  kInvalid = 0,
  kGps = 1,
  kDgps = 2,
  kPps = 3,
  kRtkFixed = 4,
  kRtkFloat = 5,
  kDeadReckoning = 6,
  kManual = 7,
  kSimulation = 8,
};

struct GpsFix {
  UtcTime time{};         // when the position was valid (receiver UTC)
  bool has_date = false;  // false: date borrowed (GGA alone carries only the time of day)
  double latitude_deg = 0;
  double longitude_deg = 0;
  bool valid = false;  // RMC status A and/or GGA quality > 0
  std::optional<double> speed_mps;
  std::optional<double> course_deg;  // degrees true
  std::optional<double> altitude_m;  // above mean sea level
  std::optional<double> hdop;
  std::optional<FixQuality> quality;  // from GGA when seen
  std::optional<int> satellites;
  std::string talker;  // "GP", "GN", …
  ReceptionStamp received{};
};

}  // namespace fieldrig::core
