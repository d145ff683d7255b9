// Truth for a synthetic plot: the trait definitions (slices, weighted medians, hulls) run on the
// generator's noise-free visible plant geometry with the true ground level, after the same
// voxel grid as the pipeline (optionally shifted, to see how much the truth itself moves); the
// true area is the visible plant surface inside the truth's refined box.
#pragma once

#include <Eigen/Core>

#include <vector>

#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::testing_support {

struct PlotTruthTraits {
  traits::TraitsResult definitions;  // height, width, VVI, EGA, box on noise-free geometry
  double visible_area_m2 = 0.0;      // visible plant area inside the refined box
  double vai = 0.0;
};

inline PlotTruthTraits plotTruth(const sim::PlotCloud& plot, traits::TraitsOptions options,
                                 const Eigen::Vector3f& grid_offset = Eigen::Vector3f::Zero()) {
  std::vector<Eigen::Vector3f> clean;
  clean.reserve(plot.truth.visible_plant_samples.size());
  // The definitions include the crop of whatever lies beyond the row by depth.
  auto inCrop = [&](const Eigen::Vector3f& p) {
    return p.z() >= options.crop_z_min_m && p.z() <= options.crop_z_max_m;
  };
  for (const sim::PlotSample& s : plot.truth.visible_plant_samples) {
    if (inCrop(s.position))
      clean.push_back(s.position);
  }
  options.area_method = traits::AreaMethod::kNone;
  PlotTruthTraits truth;
  truth.definitions = traits::traitsFromPlantPoints(
      traits::voxelDownsample(clean, options.voxel_leaf_m, grid_offset), plot.truth.ground_x_m,
      options);
  const traits::TraitsResult& d = truth.definitions;
  for (const sim::PlotSample& s : plot.truth.visible_plant_samples) {
    const Eigen::Vector3f& p = s.position;
    if (inCrop(p) && p.x() >= d.x_min && p.x() <= d.x_max && p.z() >= d.z_min && p.z() <= d.z_max)
      truth.visible_area_m2 += s.area_m2;
  }
  truth.vai = d.ega_m2 > 0.0 ? truth.visible_area_m2 / d.ega_m2 : 0.0;
  return truth;
}

}  // namespace fieldrig::testing_support
