#include "fieldrig/traits/traits_config.h"

#include <fstream>
#include <functional>
#include <map>

namespace fieldrig::traits {

core::Result<TraitsOptions> traitsOptionsFromJson(const nlohmann::json& json,
                                                  const std::string& origin,
                                                  TraitsOptions options) {
  if (!json.is_object())
    return core::Error{origin + ": expected a JSON object of traits options"};
  using Setter = std::function<bool(const nlohmann::json&)>;
  auto number = [](double& field) {
    return Setter([&field](const nlohmann::json& v) {
      if (!v.is_number())
        return false;
      field = v.get<double>();
      return true;
    });
  };
  auto integer = [](int& field) {
    return Setter([&field](const nlohmann::json& v) {
      if (!v.is_number_integer())
        return false;
      field = v.get<int>();
      return true;
    });
  };
  const std::map<std::string, Setter> setters = {
      {"voxel_leaf_m", number(options.voxel_leaf_m)},
      {"outlier_mean_k", integer(options.outlier_mean_k)},
      {"outlier_stddev_mul", number(options.outlier_stddev_mul)},
      {"outlier_min_neighbours", integer(options.outlier_min_neighbours)},
      {"outlier_method",
       [&](const nlohmann::json& v) {
         if (v == "voxel_neighbours")
           options.outlier_method = OutlierMethod::kVoxelNeighbours;
         else if (v == "statistical")
           options.outlier_method = OutlierMethod::kStatistical;
         else
           return false;
         return true;
       }},
      {"crop_z_max_m", number(options.crop_z_max_m)},
      {"crop_z_min_m", number(options.crop_z_min_m)},
      {"template_strip_m", number(options.template_strip_m)},
      {"template_step_m", number(options.template_step_m)},
      {"icp_coarse_distance_m", number(options.icp_coarse_distance_m)},
      {"icp_fine_distance_m", number(options.icp_fine_distance_m)},
      {"icp_iterations", integer(options.icp_iterations)},
      {"max_ground_tilt_deg", number(options.max_ground_tilt_deg)},
      {"ground_margin_m", number(options.ground_margin_m)},
      {"ground_tilt_deg", number(options.ground_tilt_deg)},
      {"row_length_m", number(options.row_length_m)},
      {"intra_row_spacing_m", number(options.intra_row_spacing_m)},
      {"slices", integer(options.slices)},
      {"alpha", number(options.alpha)},
      {"area_method",
       [&](const nlohmann::json& v) {
         if (v == "depth_map")
           options.area_method = AreaMethod::kDepthMap;
         else if (v == "paper_mls_gpt")
           options.area_method = AreaMethod::kPaperMlsGpt;
         else if (v == "none")
           options.area_method = AreaMethod::kNone;
         else
           return false;
         return true;
       }},
      {"depth_map_cell_m", number(options.depth_map_cell_m)},
      {"camera_to_plot",
       [&](const nlohmann::json& v) {
         if (!v.is_array() || v.size() != 3)
           return false;
         for (int r = 0; r < 3; ++r) {
           const nlohmann::json& row = v[static_cast<std::size_t>(r)];
           if (!row.is_array() || row.size() != 3)
             return false;
           for (int c = 0; c < 3; ++c) {
             if (!row[static_cast<std::size_t>(c)].is_number())
               return false;
             options.camera_to_plot(r, c) = row[static_cast<std::size_t>(c)].get<double>();
           }
         }
         return true;
       }},
  };
  for (const auto& [key, value] : json.items()) {
    const auto setter = setters.find(key);
    if (setter == setters.end())
      return core::Error{origin + ": unknown key '" + key + "'"};
    if (!setter->second(value))
      return core::Error{origin + ": key '" + key + "': unusable value " + value.dump()};
  }
  if (!(options.voxel_leaf_m > 0.0) || !(options.depth_map_cell_m > 0.0))
    return core::Error{origin + ": voxel_leaf_m and depth_map_cell_m must be positive"};
  if (!(options.alpha >= 0.0 && options.alpha < 1.0))
    return core::Error{origin + ": key 'alpha' must be in [0, 1)"};
  return options;
}

core::Result<TraitsOptions> loadTraitsOptions(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    return core::Error{path + ": cannot open the traits config"};
  nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded())
    return core::Error{path + ": not valid JSON"};
  return traitsOptionsFromJson(json, path);
}

}  // namespace fieldrig::traits
