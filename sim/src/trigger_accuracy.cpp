#include "fieldrig/sim/trigger_accuracy.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace fieldrig::sim {

TriggerAccuracy scoreTriggers(const DriveSimulator& drive, const gps::LocationMap& map,
                              const std::vector<core::TriggerEvent>& triggers) {
  TriggerAccuracy result;
  result.locations = map.size();
  std::unordered_map<std::string, std::size_t> fired;
  for (const core::TriggerEvent& event : triggers) {
    const gps::ImagingLocation* location = map.find(event.location_id);
    if (location == nullptr) {
      ++result.unknown_location;
      continue;
    }
    ++fired[event.location_id];
    result.along_track_errors_m.push_back(
        drive.alongTrackError(event.time, location->latitude_deg, location->longitude_deg));
  }
  for (const gps::ImagingLocation& location : map.locations()) {
    const auto it = fired.find(location.id);
    const std::size_t count = it == fired.end() ? 0 : it->second;
    if (count == 0)
      ++result.never_fired;
    if (count == 1)
      ++result.fired_once;
    if (count > 1)
      ++result.fired_more_than_once;
  }
  std::vector<double> magnitudes;
  for (double e : result.along_track_errors_m) {
    magnitudes.push_back(std::abs(e));
    result.mean_signed_m += e;
  }
  if (!magnitudes.empty()) {
    const double n = static_cast<double>(magnitudes.size());
    result.mean_signed_m /= n;
    std::sort(magnitudes.begin(), magnitudes.end());
    double sum = 0;
    for (double m : magnitudes)
      sum += m;
    result.mean_abs_m = sum / n;
    // Nearest-rank 95th percentile.
    const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * n));
    result.p95_abs_m = magnitudes[std::max<std::size_t>(rank, 1) - 1];
    result.max_abs_m = magnitudes.back();
  }
  return result;
}

}  // namespace fieldrig::sim
