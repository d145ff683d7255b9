// Synthetic side-view row plots of tall sorghum-like plants with known truth.
//
// The scene is built in the plot frame (x up, y along the row, z away from the camera; metres)
// from explicit surfaces (stems, arching leaves, whorls, soil, a background row), sampled densely
// with an area weight per sample. Visibility is decided by a z-buffer per stereo head (pinhole
// cameras stacked vertically at z = 0 looking along +z), so the truth "visible surface area" is
// the area of the samples that some head sees. The observed cloud is the visible samples with
// depth noise along the viewing ray plus outliers. Thread-compatible; deterministic per seed.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fieldrig::sim {

struct PlotSpec {
  double row_length_m = 1.5;              // imaged length of the row along y
  double plant_spacing_m = 0.15;          // intra-row spacing
  double plant_height_m = 2.0;            // top of the whorl of a normal plant above the soil
  double row_depth_m = 1.2;               // z of the stems; the cameras sit at z = 0
  double background_row_offset_m = 2.29;  // the next row behind (90-inch spacing)
  int leaves_per_plant = 8;
  double leaf_length_m = 0.65;
  double leaf_width_m = 0.07;
  double stem_radius_m = 0.012;
  std::vector<int> missing_plants;  // indices along the row left empty (non-emergent plants)
  int tall_plant = -1;              // index of one abnormal tall plant, -1 for none
  double tall_plant_factor = 1.35;
  double soil_roughness_m = 0.004;  // amplitude of smooth soil undulation
  double ground_tilt_deg = 0.0;     // soil slope about the row axis (y)
  double depth_noise_m = 0.003;     // sigma along the viewing ray
  double outlier_fraction = 0.003;  // uniform outliers in the scene's box
  double sample_spacing_m = 0.003;  // surface sampling step before visibility
  double pixel_at_row_m = 0.006;    // footprint of one z-buffer pixel at row_depth_m
  int camera_heads = 3;             // stacked over the plant height
  bool soil = true;
  bool plants = true;
  std::uint32_t seed = 1;
};

enum class SurfaceLabel : std::uint8_t { kSoil, kStem, kLeaf, kWhorl, kBackground, kOutlier };

struct PlotSample {
  Eigen::Vector3f position;  // noise-free, plot frame
  float area_m2 = 0.0F;      // the surface area this sample stands for
  SurfaceLabel label = SurfaceLabel::kSoil;
};

struct PlotTruth {
  double ground_x_m = 0.0;  // soil level at the stem bases (x of the base-ground edge)
  double base_depth_m = 0.0;
  std::vector<double> plant_y_m;       // stem positions along the row (present plants)
  std::vector<double> plant_height_m;  // per present plant, top above the soil
  double visible_plant_area_m2 = 0.0;  // all visible stem, leaf and whorl area of this row
  double total_plant_area_m2 = 0.0;    // visible or not
  // Visible, noise-free samples of this row's plants: the geometry the trait definitions run on.
  std::vector<PlotSample> visible_plant_samples;
};

struct PlotCloud {
  std::vector<Eigen::Vector3f> points;  // observed: visible samples + noise + outliers
  std::vector<std::array<std::uint8_t, 3>> colors;
  std::vector<SurfaceLabel> labels;
  PlotTruth truth;
};

// Builds one plot. The spec is not validated beyond clamping counts to sane ranges.
PlotCloud generatePlot(const PlotSpec& spec);

// Randomly keeps `count` points (all of them when the cloud is smaller), reproducibly.
void subsamplePlot(PlotCloud& cloud, std::size_t count, std::uint32_t seed);

}  // namespace fieldrig::sim
