// The whole pipeline on synthetic plots against the truth of the definitions (noise-free
// visible geometry) and the generator's visible surface area, and the paper's two claims.
#include <gtest/gtest.h>

#include <cmath>

#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/sim/plot_truth.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {
namespace {

using sim::plotTruth;

sim::PlotSpec testSpec(double height, double noise, std::uint32_t seed) {
  sim::PlotSpec spec;
  spec.plant_height_m = height;
  spec.depth_noise_m = noise;
  spec.seed = seed;
  spec.sample_spacing_m = 0.004;  // lighter than the bench's 3 mm, still dense at 1 cm
  return spec;
}

void expectMatchesTruth(const sim::PlotSpec& spec) {
  const sim::PlotCloud plot = sim::generatePlot(spec);
  const TraitsOptions options;
  const auto truth = plotTruth(plot, options);
  ASSERT_EQ(truth.definitions.status, TraitsStatus::kOk);
  const TraitsResult r = computeTraits(plot.points, InputFrame::kPlot, options);
  ASSERT_EQ(r.status, TraitsStatus::kOk) << r.message;
  EXPECT_NEAR(r.height_m, truth.definitions.height_m, 0.03);
  EXPECT_NEAR(r.width_m, truth.definitions.width_m, 0.03);
  EXPECT_NEAR(r.vvi, truth.definitions.vvi, 0.15 * truth.definitions.vvi);
  EXPECT_NEAR(r.total_area_m2, truth.visible_area_m2, 0.15 * truth.visible_area_m2);
  EXPECT_NEAR(r.vai, truth.vai, 0.20 * truth.vai);
  // Quality fields say what happened.
  EXPECT_GT(r.quality.points_ground, 0U);
  EXPECT_GT(r.quality.points_background, 0U);
  EXPECT_GT(r.quality.points_outliers, 0U);
  EXPECT_TRUE(r.quality.icp_converged);
  EXPECT_LT(r.quality.ground_tilt_deg, 5.0);
  EXPECT_NEAR(r.quality.base_edge_centre.x(), plot.truth.ground_x_m, 0.02);
}

TEST(TraitsTruth, ShortPlotWithTwoMillimetreNoise) {
  expectMatchesTruth(testSpec(1.2, 0.002, 21));
}

TEST(TraitsTruth, TallPlotWithFourMillimetreNoise) {
  expectMatchesTruth(testSpec(2.6, 0.004, 22));
}

TEST(TraitsTruth, CameraFrameInputGivesThePlotFrameResult) {
  const sim::PlotCloud plot = sim::generatePlot(testSpec(1.5, 0.003, 23));
  const TraitsOptions options;
  std::vector<Eigen::Vector3f> camera;
  const Eigen::Matrix3f plot_to_camera = options.camera_to_plot.transpose().cast<float>();
  for (const Eigen::Vector3f& p : plot.points)
    camera.push_back(plot_to_camera * p);
  const TraitsResult in_plot = computeTraits(plot.points, InputFrame::kPlot, options);
  const TraitsResult in_camera = computeTraits(camera, InputFrame::kCamera, options);
  ASSERT_EQ(in_camera.status, TraitsStatus::kOk) << in_camera.message;
  EXPECT_NEAR(in_camera.height_m, in_plot.height_m, 1e-3);
  EXPECT_NEAR(in_camera.width_m, in_plot.width_m, 1e-3);
  EXPECT_NEAR(in_camera.vvi, in_plot.vvi, 1e-3);
}

TEST(TraitsTruth, RowCoverageSaysHowMuchOfThePlotWasSeen) {
  const sim::PlotCloud plot = sim::generatePlot(testSpec(1.5, 0.003, 25));
  const TraitsOptions options;  // row_length_m 1.5, as the generator's row
  const TraitsResult whole = computeTraits(plot.points, InputFrame::kPlot, options);
  ASSERT_EQ(whole.status, TraitsStatus::kOk) << whole.message;
  EXPECT_GT(whole.quality.row_coverage, 0.95);
  EXPECT_LT(whole.quality.row_coverage, 1.3) << "leaves reach a little beyond the ends";
  // Cameras that saw only the first half of the row: the plants' points span half of it.
  std::vector<Eigen::Vector3f> first_half;
  for (const Eigen::Vector3f& p : plot.points) {
    if (p.y() < 0.0F)
      first_half.push_back(p);
  }
  const TraitsResult half = computeTraits(first_half, InputFrame::kPlot, options);
  ASSERT_EQ(half.status, TraitsStatus::kOk) << half.message;
  EXPECT_NEAR(half.quality.row_coverage, 0.5 + (whole.quality.row_coverage - 1.0) / 2.0, 0.05);
}

TEST(TraitsTruth, TiltedGroundIsFoundByTheRegistration) {
  sim::PlotSpec spec = testSpec(1.5, 0.003, 24);
  spec.ground_tilt_deg = 4.0;
  const sim::PlotCloud plot = sim::generatePlot(spec);
  const TraitsResult r = computeTraits(plot.points, InputFrame::kPlot, TraitsOptions{});
  ASSERT_EQ(r.status, TraitsStatus::kOk) << r.message;
  EXPECT_NEAR(r.quality.ground_tilt_deg, 4.0, 1.5);
  EXPECT_NEAR(r.height_m, plotTruth(plot, TraitsOptions{}).definitions.height_m, 0.03);
}

// Ground steeper than the limit (a furrow's pull, on the field) is turned back to the limit and
// says so; without a limit the registration's own tilt stands. Soil tilted by 8 degrees.
TEST(TraitsTruth, GroundTiltBeyondTheLimitIsTurnedBackAndReported) {
  sim::PlotSpec spec = testSpec(1.5, 0.003, 24);
  spec.ground_tilt_deg = 8.0;
  const sim::PlotCloud plot = sim::generatePlot(spec);
  TraitsOptions free;
  free.ground_tilt_limit_deg = 0.0;
  free.row_base_band_m = 0.0;  // the plate's own ground: the edge positions below compare it
  const TraitsResult unlimited = computeTraits(plot.points, InputFrame::kPlot, free);
  ASSERT_EQ(unlimited.status, TraitsStatus::kOk) << unlimited.message;
  EXPECT_FALSE(unlimited.quality.ground_tilt_limited);
  EXPECT_NEAR(unlimited.quality.ground_tilt_deg, 8.0, 1.5);
  EXPECT_DOUBLE_EQ(unlimited.quality.ground_tilt_fitted_deg, unlimited.quality.ground_tilt_deg);

  TraitsOptions limited_options;
  limited_options.ground_tilt_limit_deg = 4.0;
  limited_options.row_base_band_m = 0.0;
  const TraitsResult limited = computeTraits(plot.points, InputFrame::kPlot, limited_options);
  ASSERT_EQ(limited.status, TraitsStatus::kOk) << limited.message;
  EXPECT_TRUE(limited.quality.ground_tilt_limited);
  EXPECT_DOUBLE_EQ(limited.quality.ground_tilt_deg, 4.0);
  EXPECT_DOUBLE_EQ(limited.quality.ground_tilt_fitted_deg, unlimited.quality.ground_tilt_deg);
  // The edge stays where the registration put it; the ground under the row moves, so which points
  // are plant does too.
  EXPECT_LT((limited.quality.base_edge_centre - unlimited.quality.base_edge_centre).norm(), 1e-6);
  EXPECT_NE(limited.quality.points_ground, unlimited.quality.points_ground);
}

// A plate registration that moves the ground level beyond max_ground_shift_m is not used: the
// data's densest low layer is the ground, and the result says so. With the guard at 0 any shift
// trips it; with the default the registration's small correction stands.
TEST(TraitsTruth, ARegistrationMovingTheGroundTooFarGivesWayToTheDataLayer) {
  const sim::PlotCloud plot = sim::generatePlot(testSpec(1.5, 0.003, 25));
  TraitsOptions plate_only;  // the registration's ground as it is, not moved to the row's base
  plate_only.row_base_band_m = 0.0;
  const TraitsResult registered = computeTraits(plot.points, InputFrame::kPlot, plate_only);
  ASSERT_EQ(registered.status, TraitsStatus::kOk) << registered.message;
  EXPECT_FALSE(registered.quality.ground_from_data_pose);
  EXPECT_LT(std::abs(registered.quality.icp_ground_shift_m), TraitsOptions{}.max_ground_shift_m);
  ASSERT_NE(registered.quality.icp_ground_shift_m, 0.0) << "nothing for the guard to refuse";
  TraitsOptions strict = plate_only;
  strict.max_ground_shift_m = 0.0;
  const TraitsResult from_data = computeTraits(plot.points, InputFrame::kPlot, strict);
  ASSERT_EQ(from_data.status, TraitsStatus::kOk) << from_data.message;
  EXPECT_TRUE(from_data.quality.ground_from_data_pose);
  EXPECT_NEAR(from_data.quality.base_edge_centre.x(),
              registered.quality.base_edge_centre.x() - registered.quality.icp_ground_shift_m,
              1e-6);
  // The data's layer is a 1 cm histogram bin: the ground within about a centimetre either way.
  EXPECT_NEAR(from_data.quality.base_edge_centre.x(), plot.truth.ground_x_m, 0.015);
}

// A planting ridge: the row stands on soil raised by `ridge_m` at the stems, a strip about 12 cm
// wide. The plants are lifted with it, so their heights above the soil at their stems are
// those of the flat plot.
sim::PlotCloud withPlantingRidge(sim::PlotCloud plot, double ridge_m) {
  const double base = plot.truth.base_depth_m;
  for (std::size_t i = 0; i < plot.points.size(); ++i) {
    Eigen::Vector3f& p = plot.points[i];
    switch (plot.labels[i]) {
      case sim::SurfaceLabel::kSoil:
        p.x() += static_cast<float>(ridge_m * std::exp(-std::pow((p.z() - base) / 0.06, 2.0)));
        break;
      case sim::SurfaceLabel::kStem:
      case sim::SurfaceLabel::kLeaf:
      case sim::SurfaceLabel::kWhorl:
        p.x() += static_cast<float>(ridge_m);
        break;
      default:
        break;
    }
  }
  for (sim::PlotSample& s : plot.truth.visible_plant_samples)
    s.position.x() += static_cast<float>(ridge_m);
  plot.truth.ground_x_m += ridge_m;
  return plot;
}

// The plate's soil strip reaches 30 cm in front of the row, over the ridge's flank: its ground
// settles below the soil the stems stand in, and every height comes out that much too tall (4 cm
// on the rendered field's 4 cm ridges). The densest layer at the row's base puts it back.
TEST(TraitsTruth, OnAPlantingRidgeTheGroundIsTheSoilAtTheStems) {
  const double ridge = 0.05;
  const sim::PlotCloud flat = sim::generatePlot(testSpec(1.2, 0.002, 26));
  const sim::PlotCloud ridged = withPlantingRidge(flat, ridge);
  const double truth_height = plotTruth(ridged, TraitsOptions{}).definitions.height_m;

  TraitsOptions plate_only;
  plate_only.row_base_band_m = 0.0;
  const TraitsResult plate = computeTraits(ridged.points, InputFrame::kPlot, plate_only);
  ASSERT_EQ(plate.status, TraitsStatus::kOk) << plate.message;
  EXPECT_LT(plate.quality.base_edge_centre.x(), ridged.truth.ground_x_m - 0.015)
      << "the plate alone finds the ridge top: nothing for the option to correct";
  EXPECT_DOUBLE_EQ(plate.quality.ground_row_base_shift_m, 0.0);

  const TraitsResult at_stems = computeTraits(ridged.points, InputFrame::kPlot, TraitsOptions{});
  ASSERT_EQ(at_stems.status, TraitsStatus::kOk) << at_stems.message;
  EXPECT_NEAR(at_stems.quality.base_edge_centre.x(), ridged.truth.ground_x_m, 0.01);
  EXPECT_GT(at_stems.quality.ground_row_base_shift_m, 0.015);
  EXPECT_NEAR(at_stems.height_m, truth_height, 0.015);
  EXPECT_GT(plate.height_m - truth_height, at_stems.height_m - truth_height + 0.01);

  // Flat soil: the layer at the stems is the plate's own ground, and it stays.
  const TraitsResult on_flat = computeTraits(flat.points, InputFrame::kPlot, TraitsOptions{});
  ASSERT_EQ(on_flat.status, TraitsStatus::kOk) << on_flat.message;
  EXPECT_LT(std::abs(on_flat.quality.ground_row_base_shift_m), 0.01);
  EXPECT_NEAR(on_flat.quality.base_edge_centre.x(), flat.truth.ground_x_m, 0.01);
}

// Paper claim 1: the weighted median of per-slice maxima ignores a single abnormal tall plant.
TEST(TraitsTruth, WeightedMedianIgnoresASingleTallPlant) {
  sim::PlotSpec spec = testSpec(1.8, 0.003, 25);
  const TraitsResult normal =
      computeTraits(sim::generatePlot(spec).points, InputFrame::kPlot, TraitsOptions{});
  spec.tall_plant = 4;
  spec.tall_plant_factor = 1.4;
  const sim::PlotCloud tall_plot = sim::generatePlot(spec);
  const TraitsResult tall = computeTraits(tall_plot.points, InputFrame::kPlot, TraitsOptions{});
  ASSERT_EQ(tall.status, TraitsStatus::kOk);
  double highest = 0.0;
  for (const SliceStats& s : tall.slices)
    highest = std::max(highest, s.x_max - tall.x_min);
  EXPECT_GT(highest, normal.height_m + 0.4);  // the tall plant is in the cloud...
  // ...but hardly in the plot's height: its leaves arch over the neighbouring slices and lift
  // them a little (the truth of the definitions moves the same way), its top does not count.
  EXPECT_LT(tall.height_m - normal.height_m, 0.2 * (highest - normal.height_m));
  EXPECT_NEAR(tall.height_m, plotTruth(tall_plot, TraitsOptions{}).definitions.height_m, 0.03);
}

// Paper claim 2: empty space (missing plants) does not lower VVI: invalid slices leave EGA.
TEST(TraitsTruth, EmptySpaceDoesNotLowerVvi) {
  sim::PlotSpec spec = testSpec(1.8, 0.003, 26);
  const TraitsResult full =
      computeTraits(sim::generatePlot(spec).points, InputFrame::kPlot, TraitsOptions{});
  spec.missing_plants = {3, 4, 5};
  const TraitsResult gappy =
      computeTraits(sim::generatePlot(spec).points, InputFrame::kPlot, TraitsOptions{});
  ASSERT_EQ(full.status, TraitsStatus::kOk);
  ASSERT_EQ(gappy.status, TraitsStatus::kOk);
  EXPECT_LT(gappy.quality.valid_slices, full.quality.valid_slices);
  EXPECT_LT(gappy.ega_m2, full.ega_m2);
  EXPECT_GT(gappy.vvi, 0.9 * full.vvi);
  // Without the validity test (alpha = 0) the gap would count as plot: VVI drops.
  TraitsOptions all_slices;
  all_slices.alpha = 0.0;
  sim::PlotSpec same = spec;
  const TraitsResult naive =
      computeTraits(sim::generatePlot(same).points, InputFrame::kPlot, all_slices);
  EXPECT_LT(naive.vvi, gappy.vvi);
}

// How much the truth itself moves when the voxel grid is shifted by a fraction of a cell: the
// accuracy figures of the bench are read against this.
TEST(TraitsTruth, TruthIsStableUnderVoxelGridShifts) {
  const sim::PlotCloud plot = sim::generatePlot(testSpec(2.0, 0.0, 27));
  const TraitsOptions options;
  const auto base = plotTruth(plot, options);
  for (float f : {0.25F, 0.5F, 0.75F}) {
    const auto shifted = plotTruth(plot, options, Eigen::Vector3f::Constant(f * 0.01F));
    EXPECT_NEAR(shifted.definitions.height_m, base.definitions.height_m, 0.02);
    EXPECT_NEAR(shifted.definitions.width_m, base.definitions.width_m, 0.03);
    EXPECT_NEAR(shifted.definitions.vvi, base.definitions.vvi, 0.05 * base.definitions.vvi);
  }
}

}  // namespace
}  // namespace fieldrig::traits
