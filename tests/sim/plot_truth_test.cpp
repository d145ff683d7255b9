// sim/plots' truth as `fieldrig traits synth` hands it out: the truth JSON says what plotTruth and
// the generator say, and the observed points come in the frame the traits pipeline is told.
#include <gtest/gtest.h>

#include <algorithm>

#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/sim/plot_truth.h"

namespace fieldrig::sim {
namespace {

PlotSpec lightSpec(std::uint32_t seed) {
  PlotSpec spec;
  spec.plant_height_m = 1.4;
  spec.seed = seed;
  spec.sample_spacing_m = 0.006;  // coarse: the test checks bookkeeping, not accuracy
  return spec;
}

TEST(PlotTruthJson, CarriesTheDefinitionsAndTheGeneratorsTruth) {
  const PlotCloud plot = generatePlot(lightSpec(41));
  const traits::TraitsOptions options;
  const PlotTruthTraits truth = plotTruth(plot, options);
  const nlohmann::ordered_json json = plotTruthJson(plot, options);
  EXPECT_EQ(json.at("status"), traits::statusName(truth.definitions.status));
  EXPECT_DOUBLE_EQ(json.at("height_m").get<double>(), truth.definitions.height_m);
  EXPECT_DOUBLE_EQ(json.at("width_m").get<double>(), truth.definitions.width_m);
  EXPECT_DOUBLE_EQ(json.at("vvi").get<double>(), truth.definitions.vvi);
  EXPECT_DOUBLE_EQ(json.at("visible_area_in_box_m2").get<double>(), truth.visible_area_m2);
  EXPECT_DOUBLE_EQ(json.at("vai").get<double>(), truth.vai);
  EXPECT_DOUBLE_EQ(json.at("ground_x_m").get<double>(), plot.truth.ground_x_m);
  EXPECT_EQ(json.at("plant_y_m").size(), plot.truth.plant_y_m.size());
  EXPECT_EQ(json.at("plant_height_m").get<std::vector<double>>(), plot.truth.plant_height_m);
  EXPECT_GT(json.at("height_m").get<double>(), 1.0);
}

TEST(ObservedPoints, PlotFrameIsAsGeneratedAndCameraFrameTurnsBack) {
  const PlotCloud plot = generatePlot(lightSpec(42));
  const traits::TraitsOptions options;
  EXPECT_EQ(observedPoints(plot, traits::InputFrame::kPlot, options), plot.points);
  const std::vector<Eigen::Vector3f> camera =
      observedPoints(plot, traits::InputFrame::kCamera, options);
  ASSERT_EQ(camera.size(), plot.points.size());
  const Eigen::Matrix3f camera_to_plot = options.camera_to_plot.cast<float>();
  for (std::size_t i = 0; i < camera.size(); i += 97)
    EXPECT_TRUE((camera_to_plot * camera[i]).isApprox(plot.points[i], 1e-6F)) << i;
  // Plot x is up; the camera's y points down: a plant's top is the camera's most negative y.
  const std::size_t top = static_cast<std::size_t>(
      std::max_element(plot.points.begin(), plot.points.end(),
                       [](const auto& a, const auto& b) { return a.x() < b.x(); }) -
      plot.points.begin());
  EXPECT_FLOAT_EQ(camera[top].y(), -plot.points[top].x());
}

}  // namespace
}  // namespace fieldrig::sim
