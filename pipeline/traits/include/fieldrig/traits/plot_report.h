// Per-plot results of a session as JSON, CSV and GeoJSON (RFC 7946: one Point feature per plot at
// [lon, lat], the traits and quality fields as properties) so that QGIS opens them directly.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {

struct PlotRecord {
  std::string plot_id;
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  std::string time;  // ISO 8601, as recorded
  TraitsResult traits;
};

// One result as a JSON object: the traits (null where the status makes them meaningless), the
// status, the quality fields, the slices and the timings.
nlohmann::ordered_json traitsToJson(const TraitsResult& result, bool with_slices = true);

std::string formatCsv(const std::vector<PlotRecord>& records);
std::string formatGeoJson(const std::vector<PlotRecord>& records);

// Write the text to `path`; the error names the file.
core::Result<bool> writeText(const std::string& path, const std::string& text);

}  // namespace fieldrig::traits
