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

}  // namespace fieldrig::sim
