// The paper's traits pipeline, which the benches time ours against: SOR with 50 neighbours, a 1 cm
// plate registered by one ICP stage with the 0.3 m correspondence distance, MLS + greedy
// projection triangulation for the area.
#pragma once

#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::bench {

inline traits::TraitsOptions paperPipelineOptions(traits::TraitsOptions options) {
  options.outlier_method = traits::OutlierMethod::kStatistical;
  options.outlier_mean_k = 50;
  options.template_step_m = 0.01;
  options.icp_target_leaf_m = 0.0;
  options.icp_fine_distance_m = 0.0;
  options.icp_iterations = 30;
  options.max_ground_tilt_deg = 90.0;
  options.area_method = traits::AreaMethod::kPaperMlsGpt;
  return options;
}

}  // namespace fieldrig::bench
