// Truth for a synthetic plot: the trait definitions (slices, weighted medians, hulls) run on the
// generator's noise-free visible plant geometry with the true ground level, after the same depth
// crop and voxel grid as the pipeline (optionally shifted, to see how much the truth itself
// moves); the true area is the visible plant surface inside the truth's refined box. Used by the
// traits tests and bench, `fieldrig traits synth` and `fieldrig sim plots`.
#pragma once

#include <Eigen/Core>

#include <nlohmann/json.hpp>
#include <vector>

#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::sim {

struct PlotTruthTraits {
  traits::TraitsResult definitions;  // height, width, VVI, EGA, box on noise-free geometry
  double visible_area_m2 = 0.0;      // visible plant area inside the refined box
  double vai = 0.0;
};

PlotTruthTraits plotTruth(const PlotCloud& plot, traits::TraitsOptions options,
                          const Eigen::Vector3f& grid_offset = Eigen::Vector3f::Zero());

// The truth as one JSON object (`fieldrig traits synth --truth`): plotTruth's definitions, its
// visible area and VAI, then the generator's own truth (ground, base depth, areas, plants).
nlohmann::ordered_json plotTruthJson(const PlotCloud& plot, const traits::TraitsOptions& options);

// The observed points as computeTraits takes them in `frame`: the plot frame as generated, or the
// camera frame that `options.camera_to_plot` turns into the plot frame.
std::vector<Eigen::Vector3f> observedPoints(const PlotCloud& plot, traits::InputFrame frame,
                                            const traits::TraitsOptions& options);

}  // namespace fieldrig::sim
