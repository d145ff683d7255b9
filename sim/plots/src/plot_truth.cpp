#include "fieldrig/sim/plot_truth.h"

#include <vector>

namespace fieldrig::sim {

PlotTruthTraits plotTruth(const PlotCloud& plot, traits::TraitsOptions options,
                          const Eigen::Vector3f& grid_offset) {
  std::vector<Eigen::Vector3f> clean;
  clean.reserve(plot.truth.visible_plant_samples.size());
  // The definitions include the crop of whatever lies beyond the row by depth.
  auto inCrop = [&](const Eigen::Vector3f& p) {
    return p.z() >= options.crop_z_min_m && p.z() <= options.crop_z_max_m;
  };
  for (const PlotSample& s : plot.truth.visible_plant_samples) {
    if (inCrop(s.position))
      clean.push_back(s.position);
  }
  options.area_method = traits::AreaMethod::kNone;
  PlotTruthTraits truth;
  truth.definitions = traits::traitsFromPlantPoints(
      traits::voxelDownsample(clean, options.voxel_leaf_m, grid_offset), plot.truth.ground_x_m,
      options);
  const traits::TraitsResult& d = truth.definitions;
  for (const PlotSample& s : plot.truth.visible_plant_samples) {
    const Eigen::Vector3f& p = s.position;
    if (inCrop(p) && p.x() >= d.x_min && p.x() <= d.x_max && p.z() >= d.z_min && p.z() <= d.z_max)
      truth.visible_area_m2 += s.area_m2;
  }
  truth.vai = d.ega_m2 > 0.0 ? truth.visible_area_m2 / d.ega_m2 : 0.0;
  return truth;
}

nlohmann::ordered_json plotTruthJson(const PlotCloud& plot, const traits::TraitsOptions& options) {
  const PlotTruthTraits truth_traits = plotTruth(plot, options);
  const traits::TraitsResult& d = truth_traits.definitions;
  nlohmann::ordered_json truth;
  truth["status"] = traits::statusName(d.status);
  truth["height_m"] = d.height_m;
  truth["width_m"] = d.width_m;
  truth["vvi"] = d.vvi;
  truth["ega_m2"] = d.ega_m2;
  truth["total_volume_m3"] = d.total_volume_m3;
  truth["visible_area_in_box_m2"] = truth_traits.visible_area_m2;
  truth["vai"] = truth_traits.vai;
  truth["ground_x_m"] = plot.truth.ground_x_m;
  truth["base_depth_m"] = plot.truth.base_depth_m;
  truth["visible_plant_area_m2"] = plot.truth.visible_plant_area_m2;
  truth["total_plant_area_m2"] = plot.truth.total_plant_area_m2;
  truth["plant_y_m"] = plot.truth.plant_y_m;
  truth["plant_height_m"] = plot.truth.plant_height_m;
  return truth;
}

std::vector<Eigen::Vector3f> observedPoints(const PlotCloud& plot, traits::InputFrame frame,
                                            const traits::TraitsOptions& options) {
  if (frame == traits::InputFrame::kPlot)
    return plot.points;
  // camera_to_plot is a rotation: its transpose takes the plot frame back to the camera's.
  const Eigen::Matrix3f plot_to_camera = options.camera_to_plot.transpose().cast<float>();
  std::vector<Eigen::Vector3f> points;
  points.reserve(plot.points.size());
  for (const Eigen::Vector3f& p : plot.points)
    points.push_back(plot_to_camera * p);
  return points;
}

}  // namespace fieldrig::sim
