#include "fieldrig/config/traits_config.h"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "traits_reader.h"
#include "yaml_reader.h"

namespace fieldrig::config {
namespace detail {

// The traits keys: the field names, as the JSON loader of earlier versions read them, so that
// their traits files still load.
void readTraits(const Value& section, traits::TraitsOptions& o) {
  const Entries entries = readMap(
      section,
      {
          {"camera_to_plot",
           [&](const Value& v) {
             const std::vector<Value> rows = v.list();
             if (rows.size() != 3)
               v.fail("expected 3 rows of 3 numbers, got " + std::to_string(rows.size()) + " rows");
             for (int r = 0; r < 3; ++r) {
               const Value& row = rows[static_cast<std::size_t>(r)];
               const std::vector<Value> cells = row.list();
               if (cells.size() != 3)
                 row.fail("expected 3 numbers, got " + std::to_string(cells.size()));
               for (int c = 0; c < 3; ++c)
                 o.camera_to_plot(r, c) = cells[static_cast<std::size_t>(c)].number();
             }
           }},
          {"voxel_leaf_m", positive(o.voxel_leaf_m)},
          {"outlier_method",
           choice(o.outlier_method,
                  Names<traits::OutlierMethod>{
                      {"statistical", traits::OutlierMethod::kStatistical},
                      {"voxel_neighbours", traits::OutlierMethod::kVoxelNeighbours},
                  })},
          {"outlier_mean_k", integer(o.outlier_mean_k, 1)},
          {"outlier_stddev_mul", nonNegative(o.outlier_stddev_mul)},
          {"outlier_min_neighbours", integer(o.outlier_min_neighbours, 0, 26)},
          {"min_piece_voxels", integer(o.min_piece_voxels, 0, 1000000)},
          {"crop_z_max_m", positive(o.crop_z_max_m)},
          {"crop_z_min_m", nonNegative(o.crop_z_min_m)},
          {"max_abs_coordinate_m", positive(o.max_abs_coordinate_m)},
          {"template_strip_m", positive(o.template_strip_m)},
          {"template_step_m", positive(o.template_step_m)},
          {"icp_target_leaf_m", positive(o.icp_target_leaf_m)},
          {"icp_coarse_distance_m", positive(o.icp_coarse_distance_m)},
          {"icp_fine_distance_m", nonNegative(o.icp_fine_distance_m)},
          {"icp_iterations", integer(o.icp_iterations, 1)},
          {"max_ground_tilt_deg", numberIn(o.max_ground_tilt_deg, 0, 90)},
          {"ground_tilt_limit_deg", numberIn(o.ground_tilt_limit_deg, 0, 90)},
          {"max_ground_shift_m", numberIn(o.max_ground_shift_m, 0, 10)},
          {"ground_margin_m", nonNegative(o.ground_margin_m)},
          {"row_base_band_m", numberIn(o.row_base_band_m, 0, 1)},
          {"ground_tilt_deg", numberIn(o.ground_tilt_deg, 0, 90, true)},
          {"row_length_m", positive(o.row_length_m)},
          {"crop_to_row_length", flag(o.crop_to_row_length)},
          {"intra_row_spacing_m", positive(o.intra_row_spacing_m)},
          {"slices", integer(o.slices, 0)},
          {"slice_width_quantile", numberIn(o.slice_width_quantile, 0, 0.25)},
          {"width_band_m", numberIn(o.width_band_m, 0, 100)},
          {"min_row_extent_m", nonNegative(o.min_row_extent_m)},
          {"min_plant_points",
           [&](const Value& v) {
             o.min_plant_points = static_cast<std::size_t>(
                 readIntegerIn(v, 0, std::numeric_limits<std::int64_t>::max()));
           }},
          {"alpha", numberIn(o.alpha, 0, 1, true)},
          {"alpha_near_margin", nonNegative(o.alpha_near_margin)},
          // "paper_mls_gpt" is the name earlier JSON files use.
          {"area_method",
           choice(o.area_method,
                  Names<traits::AreaMethod>{
                      {"depth_map", traits::AreaMethod::kDepthMap},
                      {"paper", traits::AreaMethod::kPaperMlsGpt},
                      {"paper_mls_gpt", traits::AreaMethod::kPaperMlsGpt},
                      {"none", traits::AreaMethod::kNone},
                  })},
          {"depth_map_cell_m", positive(o.depth_map_cell_m)},
          {"depth_map_max_step_m", positive(o.depth_map_max_step_m)},
          {"depth_map_min_fill", numberIn(o.depth_map_min_fill, 0, 1)},
          {"mls_radius_m", positive(o.mls_radius_m)},
          {"gpt_radius_m", positive(o.gpt_radius_m)},
          {"gpt_mu", positive(o.gpt_mu)},
          {"gpt_max_neighbors", integer(o.gpt_max_neighbors, 1)},
      });
  if (!(o.crop_z_min_m < o.crop_z_max_m)) {
    const Value& at = entries.contains("crop_z_min_m") ? entries.at("crop_z_min_m")
                                                       : entryOr(entries, "crop_z_max_m", section);
    at.fail("the depth crop must satisfy crop_z_min_m (" + formatNumber(o.crop_z_min_m) +
            ") < crop_z_max_m (" + formatNumber(o.crop_z_max_m) + ")");
  }
  // The ranges the traits steps are meant for live with the options (TraitsOptions::validate):
  // the same for this file, the JSON of earlier versions and any program that fills them.
  if (const auto problem = o.validate()) {
    if (const auto it = entries.find(problem->key); it != entries.end())
      it->second.fail(problem->message);
    section.fail(problem->key + ": " + problem->message);
  }
}

}  // namespace detail

core::Result<traits::TraitsOptions> loadTraitsOptions(const std::filesystem::path& file) {
  core::Result<std::string> text = detail::readFile(file);
  if (!text)
    return text.error();
  const detail::Source source{file.string(), detail::folderOf(file)};
  return detail::guarded<traits::TraitsOptions>(source.origin, [&] {
    traits::TraitsOptions options;
    detail::readTraits(detail::rootValue(source, detail::parseDocument(source, *text)), options);
    return options;
  });
}

}  // namespace fieldrig::config
