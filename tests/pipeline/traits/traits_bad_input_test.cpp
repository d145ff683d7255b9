// Bad input never crashes and never yields a NaN trait: each case ends in a clear status.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/traits/plot_report.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {
namespace {

void expectFiniteNumbers(const nlohmann::ordered_json& j) {
  if (j.is_number_float()) {
    EXPECT_TRUE(std::isfinite(j.get<double>()));
  } else if (j.is_structured()) {
    for (const auto& item : j)
      expectFiniteNumbers(item);
  }
}

void expectNoNaN(const TraitsResult& r) {
  for (double v : {r.height_m, r.width_m, r.vvi, r.vai, r.total_volume_m3, r.total_area_m2,
                   r.ega_m2, r.x_min, r.x_max, r.y_min, r.y_max, r.z_min, r.z_max,
                   r.quality.alpha_margin, r.quality.ground_tilt_deg})
    EXPECT_TRUE(std::isfinite(v));
  for (const SliceStats& s : r.slices)
    EXPECT_TRUE(std::isfinite(s.x_max) && std::isfinite(s.z_min) && std::isfinite(s.z_max) &&
                std::isfinite(s.ratio));
  // The JSON says null for traits the status makes meaningless; every number in it is finite.
  expectFiniteNumbers(traitsToJson(r));
}

sim::PlotSpec lightSpec(std::uint32_t seed) {
  sim::PlotSpec spec;
  spec.plant_height_m = 1.5;
  spec.sample_spacing_m = 0.005;
  spec.seed = seed;
  return spec;
}

TEST(TraitsBadInput, EmptyCloud) {
  const TraitsResult r = computeTraits({}, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kEmptyCloud);
  EXPECT_FALSE(r.message.empty());
  expectNoNaN(r);
}

TEST(TraitsBadInput, OnlyNaNs) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Eigen::Vector3f> cloud(100, Eigen::Vector3f(nan, 1.0F, nan));
  const TraitsResult r = computeTraits(cloud, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kNoFinitePoints);
  EXPECT_EQ(r.quality.points_non_finite, 100U);
  expectNoNaN(r);
}

TEST(TraitsBadInput, SomeNaNsAreCountedAndSkipped) {
  sim::PlotCloud plot = sim::generatePlot(lightSpec(31));
  const std::size_t valid = plot.points.size();
  for (int i = 0; i < 500; ++i)
    plot.points.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.0F,
                             std::numeric_limits<float>::infinity());
  const TraitsResult r = computeTraits(plot.points, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kOk) << r.message;
  EXPECT_EQ(r.quality.points_non_finite, 500U);
  EXPECT_EQ(r.quality.points_in, valid + 500);
  expectNoNaN(r);
}

TEST(TraitsBadInput, GroundOnly) {
  sim::PlotSpec spec = lightSpec(32);
  spec.plants = false;
  const TraitsResult r =
      computeTraits(sim::generatePlot(spec).points, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kNoPlants) << r.message;
  expectNoNaN(r);
}

TEST(TraitsBadInput, NoPlantsInTheRowOnlyTheBackgroundRow) {
  sim::PlotSpec spec = lightSpec(33);
  spec.missing_plants = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  const TraitsResult r =
      computeTraits(sim::generatePlot(spec).points, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kNoPlants) << r.message;
  EXPECT_GT(r.quality.points_background, 0U);
  expectNoNaN(r);
}

TEST(TraitsBadInput, OneSliceOnly) {
  // The cloud cut to a 4 cm strip of the row: the plants in it span less than one slice needs.
  const sim::PlotCloud plot = sim::generatePlot(lightSpec(34));
  std::vector<Eigen::Vector3f> strip;
  for (const Eigen::Vector3f& p : plot.points) {
    if (std::abs(p.y()) < 0.02F)
      strip.push_back(p);
  }
  const TraitsResult r = computeTraits(strip, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kSingleSlice) << r.message;
  expectNoNaN(r);
}

TEST(TraitsBadInput, HugeCoordinatesAreRefusedClearly) {
  sim::PlotCloud plot = sim::generatePlot(lightSpec(35));
  for (Eigen::Vector3f& p : plot.points)
    p += Eigen::Vector3f(0.0F, 4.6e6F, 5.0e5F);  // UTM-like northing and easting
  const TraitsResult r = computeTraits(plot.points, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kHugeCoordinates);
  EXPECT_NE(r.message.find("local frame"), std::string::npos);
  expectNoNaN(r);
}

TEST(TraitsBadInput, AFewAbsurdPointsAreDroppedAndCounted) {
  sim::PlotCloud plot = sim::generatePlot(lightSpec(36));
  plot.points.emplace_back(1e30F, -1e30F, 1e30F);
  plot.points.emplace_back(3e8F, 0.0F, 1.0F);
  const TraitsResult r = computeTraits(plot.points, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kOk) << r.message;
  EXPECT_EQ(r.quality.points_far, 2U);
  expectNoNaN(r);
}

TEST(TraitsBadInput, AFewScatteredPointsAreNotAPlot) {
  std::vector<Eigen::Vector3f> cloud;
  for (int i = 0; i < 30; ++i)
    cloud.emplace_back(0.1F * static_cast<float>(i % 5), 0.2F * static_cast<float>(i % 7),
                       1.0F + 0.01F * static_cast<float>(i));
  const TraitsResult r = computeTraits(cloud, InputFrame::kPlot, TraitsOptions{});
  EXPECT_EQ(r.status, TraitsStatus::kNoPlants) << r.message;
  expectNoNaN(r);
}

}  // namespace
}  // namespace fieldrig::traits

namespace fieldrig::traits {
namespace {

TEST(TraitsBadInput, NoSlicePassesAlphaKeepsHeightAndWidth) {
  TraitsOptions strict;
  strict.alpha = 0.99;  // no convex hull fills 99 % of its slice box
  const TraitsResult r =
      computeTraits(sim::generatePlot(lightSpec(37)).points, InputFrame::kPlot, strict);
  EXPECT_EQ(r.status, TraitsStatus::kNoValidSlices) << r.message;
  EXPECT_GT(r.height_m, 1.0);
  EXPECT_GT(r.width_m, 0.1);
  const nlohmann::ordered_json j = traitsToJson(r);
  EXPECT_TRUE(j.at("height_m").is_number());
  EXPECT_TRUE(j.at("vvi").is_null());
  EXPECT_TRUE(j.at("vai").is_null());
  expectNoNaN(r);
}

}  // namespace
}  // namespace fieldrig::traits
