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

// A plot as the tables show it: its position and its flat properties (plot_id, time, status, the
// traits, the quality fields), one value per CSV column in a fixed order. Rows can be kept and
// read back as JSON, which is how the results files are appended to across runs.
struct PlotRow {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  nlohmann::ordered_json properties;
};

PlotRow toPlotRow(const PlotRecord& record);
// The row of a plot whose traits are known only as traitsToJson wrote them (a results file).
core::Result<PlotRow> plotRowFromJson(const std::string& plot_id, const std::string& time,
                                      double lat_deg, double lon_deg,
                                      const nlohmann::ordered_json& traits_json);

std::string formatCsv(const std::vector<PlotRow>& rows);
std::string formatGeoJson(const std::vector<PlotRow>& rows);
std::string formatCsv(const std::vector<PlotRecord>& records);
std::string formatGeoJson(const std::vector<PlotRecord>& records);

// Write the text to `path`; the error names the file.
core::Result<void> writeText(const std::string& path, const std::string& text);

}  // namespace fieldrig::traits
