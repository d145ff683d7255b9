#include "fieldrig/traits/plot_report.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "fieldrig/core/durable_file.h"

namespace fieldrig::traits {
namespace {

using Json = nlohmann::ordered_json;

Json numberOrNull(double value, bool valid) {
  return valid && std::isfinite(value) ? Json(value) : Json(nullptr);
}

// The flat properties shared by CSV and GeoJSON, one value per column in a fixed order, taken
// from the traits' JSON (traitsToJson): one mapping, so a row read back from a results file is
// the row that was written.
Json flatFromTraitsJson(const std::string& plot_id, const std::string& time, const Json& t) {
  const Json& q = t.at("quality");
  Json p;
  p["plot_id"] = plot_id;
  p["time"] = time;
  for (const char* key : {"status", "height_m", "width_m", "vvi", "vai", "total_volume_m3",
                          "total_area_m2", "ega_m2"}) {
    p[key] = t.at(key);
  }
  p["slices"] = q.at("slices");
  p["valid_slices"] = t.at("valid_slices");
  for (const char* key :
       {"alpha_margin", "points_in", "points_plants", "icp_fitness_fine", "ground_tilt_deg"}) {
    p[key] = q.at(key);
  }
  return p;
}

Json flatProperties(const PlotRecord& record) {
  return flatFromTraitsJson(record.plot_id, record.time,
                            traitsToJson(record.traits, /*with_slices=*/false));
}

std::string csvField(const Json& value) {
  if (value.is_null())
    return "";
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    if (text.find_first_of(",\"\n\r") == std::string::npos)
      return text;
    std::string quoted = "\"";
    for (char c : text) {
      if (c == '"')
        quoted += '"';
      quoted += c;
    }
    return quoted + "\"";
  }
  return value.dump();
}

}  // namespace

nlohmann::ordered_json traitsToJson(const TraitsResult& r, bool with_slices) {
  const bool hw = r.heightWidthValid();
  const bool vol = r.volumeValid();
  const bool area = vol && r.quality.area_computed;
  Json j;
  j["status"] = statusName(r.status);
  j["message"] = r.message;
  j["height_m"] = numberOrNull(r.height_m, hw);
  j["width_m"] = numberOrNull(r.width_m, hw);
  j["vvi"] = numberOrNull(r.vvi, vol);
  j["vai"] = numberOrNull(r.vai, area);
  j["total_volume_m3"] = numberOrNull(r.total_volume_m3, vol);
  j["total_area_m2"] = numberOrNull(r.total_area_m2, area);
  j["ega_m2"] = numberOrNull(r.ega_m2, vol);
  j["valid_slices"] = r.quality.valid_slices;
  j["box"] = {{"x_min", numberOrNull(r.x_min, hw)}, {"x_max", numberOrNull(r.x_max, hw)},
              {"y_min", numberOrNull(r.y_min, hw)}, {"y_max", numberOrNull(r.y_max, hw)},
              {"z_min", numberOrNull(r.z_min, hw)}, {"z_max", numberOrNull(r.z_max, hw)}};
  const TraitsQuality& q = r.quality;
  j["quality"] = {{"points_in", q.points_in},
                  {"points_non_finite", q.points_non_finite},
                  {"points_far", q.points_far},
                  {"points_background", q.points_background},
                  {"points_after_voxel", q.points_after_voxel},
                  {"points_outliers", q.points_outliers},
                  {"points_small_pieces", q.points_small_pieces},
                  {"points_ground", q.points_ground},
                  {"points_ground_tilted", q.points_ground_tilted},
                  {"points_plants", q.points_plants},
                  {"points_beyond_row", q.points_beyond_row},
                  {"row_coverage", q.row_coverage},
                  {"points_outside_box", q.points_outside_box},
                  {"icp_fitness_coarse", q.icp_fitness_coarse},
                  {"icp_fitness_fine", q.icp_fitness_fine},
                  {"icp_converged", q.icp_converged},
                  {"icp_fell_back", q.icp_fell_back},
                  {"ground_tilt_deg", q.ground_tilt_deg},
                  {"ground_tilt_fitted_deg", q.ground_tilt_fitted_deg},
                  {"ground_tilt_limited", q.ground_tilt_limited},
                  {"icp_ground_shift_m", q.icp_ground_shift_m},
                  {"ground_from_data_pose", q.ground_from_data_pose},
                  {"ground_row_base_shift_m", q.ground_row_base_shift_m},
                  {"base_edge_centre",
                   {q.base_edge_centre.x(), q.base_edge_centre.y(), q.base_edge_centre.z()}},
                  {"slices", q.slices},
                  {"occupied_slices", q.occupied_slices},
                  {"width_slices", q.width_slices},
                  {"valid_slices", q.valid_slices},
                  {"slice_top_spread_m", q.slice_top_spread_m},
                  {"slice_near_spread_m", q.slice_near_spread_m},
                  {"slice_far_spread_m", q.slice_far_spread_m},
                  {"alpha_margin", q.alpha_margin},
                  {"slices_near_alpha", q.slices_near_alpha},
                  {"area_computed", q.area_computed},
                  {"area_cell_m", q.area_cell_m},
                  {"area_fill", q.area_fill}};
  Json slices = Json::array();
  if (with_slices) {
    for (const SliceStats& s : r.slices) {
      slices.push_back({{"y_begin", s.y_begin},
                        {"y_end", s.y_end},
                        {"points", s.points},
                        {"x_max", s.x_max},
                        {"z_min", s.z_min},
                        {"z_max", s.z_max},
                        {"box_points", s.box_points},
                        {"hull_volume_m3", s.hull_volume_m3},
                        {"ratio", s.ratio},
                        {"valid", s.valid}});
    }
  }
  j["slices"] = slices;
  j["timings_ms"] = {{"filter", r.timings.filter_ms}, {"ground", r.timings.ground_ms},
                     {"slices", r.timings.slices_ms}, {"hulls", r.timings.hulls_ms},
                     {"area", r.timings.area_ms},     {"total", r.timings.total_ms}};
  return j;
}

PlotRow toPlotRow(const PlotRecord& record) {
  return PlotRow{record.lat_deg, record.lon_deg, flatProperties(record)};
}

core::Result<PlotRow> plotRowFromJson(const std::string& plot_id, const std::string& time,
                                      double lat_deg, double lon_deg,
                                      const nlohmann::ordered_json& traits_json) {
  try {
    Json flat = flatFromTraitsJson(plot_id, time, traits_json);
    // The tables take the values as they are: a word where a number belongs would reach the
    // season's CSV as a trait.
    for (const auto& [key, value] : flat.items()) {
      const bool text = key == "plot_id" || key == "time" || key == "status";
      if (text ? !value.is_string() : !(value.is_number() || value.is_null()))
        return core::Error{"traits: '" + key + "' is " + value.dump() + ", not " +
                           (text ? "a string" : "a number")};
    }
    return PlotRow{lat_deg, lon_deg, std::move(flat)};
  } catch (const nlohmann::json::exception& error) {
    return core::Error{std::string("traits: ") + error.what()};
  }
}

std::string formatCsv(const std::vector<PlotRow>& rows) {
  std::ostringstream out;
  out << std::setprecision(10);
  const Json header = flatProperties(PlotRecord{});
  out << "plot_id,lat,lon";
  for (const auto& [key, value] : header.items()) {
    if (key != "plot_id")
      out << ',' << key;
  }
  out << '\n';
  for (const PlotRow& row : rows) {
    const Json& p = row.properties;
    out << csvField(p.value("plot_id", Json(""))) << ',' << Json(row.lat_deg).dump() << ','
        << Json(row.lon_deg).dump();
    for (const auto& [key, value] : header.items()) {
      if (key != "plot_id")
        out << ',' << csvField(p.contains(key) ? p.at(key) : Json(nullptr));
    }
    out << '\n';
  }
  return out.str();
}

std::string formatGeoJson(const std::vector<PlotRow>& rows) {
  Json collection;
  collection["type"] = "FeatureCollection";
  Json features = Json::array();
  for (const PlotRow& row : rows) {
    Json feature;
    feature["type"] = "Feature";
    feature["id"] = row.properties.value("plot_id", Json(""));
    // RFC 7946 section 3.1.1: longitude first.
    feature["geometry"] = {{"type", "Point"}, {"coordinates", {row.lon_deg, row.lat_deg}}};
    feature["properties"] = row.properties;
    features.push_back(std::move(feature));
  }
  collection["features"] = std::move(features);
  return collection.dump(1) + "\n";
}

namespace {
std::vector<PlotRow> toRows(const std::vector<PlotRecord>& records) {
  std::vector<PlotRow> rows;
  rows.reserve(records.size());
  for (const PlotRecord& record : records)
    rows.push_back(toPlotRow(record));
  return rows;
}
}  // namespace

std::string formatCsv(const std::vector<PlotRecord>& records) {
  return formatCsv(toRows(records));
}

std::string formatGeoJson(const std::vector<PlotRecord>& records) {
  return formatGeoJson(toRows(records));
}

core::Result<void> writeText(const std::string& path, const std::string& text) {
  // Through a temporary file and a rename: a kill or a full disk leaves the old file, never half
  // of the new one.
  if (std::string error = core::replaceFileAtomically(path, text); !error.empty())
    return core::Error{error};
  return {};
}

}  // namespace fieldrig::traits
