// Scores triggers against a simulated drive's true trajectory. Pure; thread-compatible.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "fieldrig/core/trigger_event.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/sim/drive_simulator.h"

namespace fieldrig::sim {

struct TriggerAccuracy {
  std::size_t locations = 0;
  std::size_t fired_once = 0;
  std::size_t never_fired = 0;
  std::size_t fired_more_than_once = 0;
  std::size_t unknown_location = 0;          // a trigger naming an id not in the map
  std::vector<double> along_track_errors_m;  // signed, one per trigger of a known location
  double mean_abs_m = 0;
  double p95_abs_m = 0;
  double max_abs_m = 0;
  double mean_signed_m = 0;  // bias: + = fired past the location
};

TriggerAccuracy scoreTriggers(const DriveSimulator& drive, const gps::LocationMap& map,
                              const std::vector<core::TriggerEvent>& triggers);

}  // namespace fieldrig::sim
