// Renders a synthetic row plot (sim/plots) into the images a calibrated pinhole camera would
// take, so that the whole pipeline — raw frames, debayering, stereo matching, fusion, traits —
// runs end to end on a scene with known truth.
//
// Each surface sample is splatted with a z-buffer over the pixels its footprint covers, in the
// colour the generator gave it. Texture comes from the 3D position of what a pixel sees (value
// noise on a 4 mm lattice, evaluated at the back-projected point), so both cameras of a head see
// the same pattern on the same surface, as they would on real leaves. What no sample covers
// shows a far textured backdrop (10 m), beyond any crop depth.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldrig/sim/plot_generator.h"

namespace fieldrig::sim {

struct PinholeView {
  double focal_px = 1350.0;
  cv::Size size{1624, 1224};  // principal point at the centre
  // Camera frame (x right, y down, z forward) → plot frame (x up, y along the row, z away).
  Eigen::Matrix3d plot_from_camera = (Eigen::Matrix3d() << 0, -1, 0, 1, 0, 0, 0, 0, 1).finished();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // camera centre in the plot frame
};

struct RenderOptions {
  double plant_sample_spacing_m = 0.003;  // the generator's sample_spacing_m
  double soil_sample_spacing_m = 0.02;    // the generator samples soil on a coarser grid
  double texture_cell_m = 0.004;
  double backdrop_depth_m = 10.0;
};

// BGR image (CV_8UC3) of `plot` as seen from `view`.
cv::Mat renderPlotView(const PlotCloud& plot, const PinholeView& view,
                       const RenderOptions& options = {});

}  // namespace fieldrig::sim
