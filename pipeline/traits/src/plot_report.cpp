#include "fieldrig/traits/plot_report.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace fieldrig::traits {
namespace {

using Json = nlohmann::ordered_json;

Json numberOrNull(double value, bool valid) {
  return valid && std::isfinite(value) ? Json(value) : Json(nullptr);
}

// The flat properties shared by CSV and GeoJSON: one value per column, in a fixed order.
Json flatProperties(const PlotRecord& record) {
  const TraitsResult& r = record.traits;
  const bool hw = r.heightWidthValid();
  const bool vol = r.volumeValid();
  Json p;
  p["plot_id"] = record.plot_id;
  p["time"] = record.time;
  p["status"] = statusName(r.status);
  p["height_m"] = numberOrNull(r.height_m, hw);
  p["width_m"] = numberOrNull(r.width_m, hw);
  p["vvi"] = numberOrNull(r.vvi, vol);
  p["vai"] = numberOrNull(r.vai, vol && r.quality.area_computed);
  p["total_volume_m3"] = numberOrNull(r.total_volume_m3, vol);
  p["total_area_m2"] = numberOrNull(r.total_area_m2, vol && r.quality.area_computed);
  p["ega_m2"] = numberOrNull(r.ega_m2, vol);
  p["slices"] = r.quality.slices;
  p["valid_slices"] = r.quality.valid_slices;
  p["alpha_margin"] = r.quality.alpha_margin;
  p["points_in"] = r.quality.points_in;
  p["points_plants"] = r.quality.points_plants;
  p["icp_fitness_fine"] = r.quality.icp_fitness_fine;
  p["ground_tilt_deg"] = r.quality.ground_tilt_deg;
  return p;
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
                  {"points_ground", q.points_ground},
                  {"points_ground_tilted", q.points_ground_tilted},
                  {"points_plants", q.points_plants},
                  {"points_outside_box", q.points_outside_box},
                  {"icp_fitness_coarse", q.icp_fitness_coarse},
                  {"icp_fitness_fine", q.icp_fitness_fine},
                  {"icp_converged", q.icp_converged},
                  {"icp_fell_back", q.icp_fell_back},
                  {"ground_tilt_deg", q.ground_tilt_deg},
                  {"base_edge_centre",
                   {q.base_edge_centre.x(), q.base_edge_centre.y(), q.base_edge_centre.z()}},
                  {"slices", q.slices},
                  {"occupied_slices", q.occupied_slices},
                  {"valid_slices", q.valid_slices},
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

std::string formatCsv(const std::vector<PlotRecord>& records) {
  std::ostringstream out;
  out << std::setprecision(10);
  const Json header = flatProperties(PlotRecord{});
  out << "plot_id,lat,lon";
  for (const auto& [key, value] : header.items()) {
    if (key != "plot_id")
      out << ',' << key;
  }
  out << '\n';
  for (const PlotRecord& record : records) {
    const Json p = flatProperties(record);
    out << csvField(p["plot_id"]) << ',' << Json(record.lat_deg).dump() << ','
        << Json(record.lon_deg).dump();
    for (const auto& [key, value] : p.items()) {
      if (key != "plot_id")
        out << ',' << csvField(value);
    }
    out << '\n';
  }
  return out.str();
}

std::string formatGeoJson(const std::vector<PlotRecord>& records) {
  Json collection;
  collection["type"] = "FeatureCollection";
  Json features = Json::array();
  for (const PlotRecord& record : records) {
    Json feature;
    feature["type"] = "Feature";
    feature["id"] = record.plot_id;
    // RFC 7946 section 3.1.1: longitude first.
    feature["geometry"] = {{"type", "Point"}, {"coordinates", {record.lon_deg, record.lat_deg}}};
    feature["properties"] = flatProperties(record);
    features.push_back(std::move(feature));
  }
  collection["features"] = std::move(features);
  return collection.dump(1) + "\n";
}

core::Result<bool> writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out)
    return core::Error{path + ": cannot open for writing"};
  out << text;
  out.close();
  if (!out)
    return core::Error{path + ": write failed"};
  return true;
}

}  // namespace fieldrig::traits
