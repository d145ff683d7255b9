// The trait math on tiny hand-made geometry: weighted median, slice count, areas of surfaces of
// known size, outliers and small pieces on the voxel grid, the options file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "fieldrig/traits/plot_report.h"
#include "fieldrig/traits/plot_traits.h"
#include "support/temp_dir.h"

namespace fieldrig::traits {
namespace {

using Points = std::vector<Eigen::Vector3f>;

// A dense, jittered sampling of a parametric patch, step metres apart.
template <typename Fn>
Points samplePatch(Fn fn, double u_len, double v_len, double step, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(0.0, step);
  Points points;
  for (double u = 0.0; u < u_len; u += step)
    for (double v = 0.0; v < v_len; v += step)
      points.push_back(fn(std::min(u + jitter(rng), u_len), std::min(v + jitter(rng), v_len)));
  return points;
}

TEST(WeightedMedian, IsTheFirstSortedValueReachingHalfTheWeight) {
  // Sorted: 1 (0.2), 2 (0.2), 3 (0.2), 10 (0.4): cumulative 0.2, 0.4, 0.6 -> 3.
  EXPECT_DOUBLE_EQ(weightedMedian({{10.0, 0.4}, {2.0, 0.2}, {1.0, 0.2}, {3.0, 0.2}}), 3.0);
  // Exactly half reached by the first value.
  EXPECT_DOUBLE_EQ(weightedMedian({{1.0, 1.0}, {2.0, 1.0}}), 1.0);
  EXPECT_DOUBLE_EQ(weightedMedian({}), 0.0);
  EXPECT_DOUBLE_EQ(weightedMedian({{5.0, 0.0}, {7.0, 2.0}}), 7.0);  // zero weight ignored
}

TEST(WeightedMedian, IgnoresASingleTallSlice) {
  std::vector<std::pair<double, double>> slices;
  for (int i = 0; i < 19; ++i)
    slices.emplace_back(2.0 + 0.01 * i, 100.0);
  slices.emplace_back(3.5, 150.0);  // one abnormal tall plant, even with more points
  const double median = weightedMedian(slices);
  EXPECT_GE(median, 2.0);
  EXPECT_LE(median, 2.19);
}

// A 1 m tall, 1 m long, 0.2 m deep block of plant points 1.0-1.2 m from the camera, with in every
// slice a few mismatch-like voxels 10 cm nearer and a few 30 cm above the top.
Points blockWithStrayVoxels() {
  Points points;
  const float step = 0.02F;
  for (int i = 0; i <= 50; ++i)
    for (int j = 0; j <= 50; ++j)
      for (int k = 0; k <= 10; ++k)
        points.emplace_back(i * step, -0.5F + j * step, 1.0F + k * step);
  for (int j = 0; j < 50; j += 2) {
    for (int k = 0; k < 3; ++k) {
      points.emplace_back(0.5F, -0.49F + j * step, 0.9F + k * 0.01F);  // near the camera
      points.emplace_back(1.3F - k * 0.01F, -0.49F + j * step, 1.1F);  // above the top
    }
  }
  return points;
}

TEST(SliceExtent, TheExtremePointLetsAFewStrayVoxelsSetTheWidth) {
  const TraitsResult result = traitsFromPlantPoints(blockWithStrayVoxels(), 0.0, TraitsOptions{});
  ASSERT_TRUE(result.heightWidthValid()) << result.message;
  EXPECT_NEAR(result.width_m, 0.30, 1e-3);  // 0.9 to 1.2
  EXPECT_NEAR(result.height_m, 1.30, 1e-3);
}

TEST(SliceExtent, AWidthQuantileIgnoresTheStrayVoxelsAndLeavesTheTop) {
  TraitsOptions options;
  options.slice_width_quantile = 0.02;
  const TraitsResult result = traitsFromPlantPoints(blockWithStrayVoxels(), 0.0, options);
  ASSERT_TRUE(result.heightWidthValid()) << result.message;
  // The block's own depth, less at most one 2 cm layer on either side.
  EXPECT_NEAR(result.width_m, 0.20, 0.021);
  EXPECT_LE(result.width_m, 0.20 + 1e-6);
  for (const SliceStats& slice : result.slices) {
    EXPECT_GE(slice.z_min, 1.0 - 1e-6);
    EXPECT_LE(slice.z_max, 1.2 + 1e-6);
  }
  EXPECT_NEAR(result.height_m, 1.30, 1e-3);  // the top is still the slices' highest point
}

// A 2 m long row of plant points 0.6-1.2 m from the camera, 1 m tall, whose near side a side-view
// camera sees only around the plot's location: beyond |y| = 0.2 m the nearest point seen moves
// back 0.8 m for each metre along the row, as at the edge of a camera's view (none seen beyond
// |y| = 0.94 m).
Points rowSeenNearOnlyInTheMiddle() {
  Points points;
  const float step = 0.02F;
  for (int j = 0; j <= 100; ++j) {
    const float y = -1.0F + j * step;
    const float near_seen = 0.6F + 0.8F * std::max(0.0F, std::abs(y) - 0.2F);
    for (int i = 0; i <= 50; ++i)
      for (int k = 0; k <= 30; ++k) {
        const float z = 0.6F + k * step;
        if (z >= near_seen - 1e-4F)
          points.emplace_back(i * step, y, z);
      }
  }
  return points;
}

TEST(SliceExtent, AWidthBandTakesTheEdgesWhereTheNearSideIsInView) {
  const TraitsResult all = traitsFromPlantPoints(rowSeenNearOnlyInTheMiddle(), 0.0, {});
  ASSERT_TRUE(all.heightWidthValid()) << all.message;
  // Every slice: the slices toward the ends, where the view cut the near side, carry the median.
  EXPECT_LT(all.width_m, 0.55);
  EXPECT_EQ(all.quality.width_slices, all.quality.occupied_slices);

  TraitsOptions options;
  options.width_band_m = 0.4;
  const TraitsResult band = traitsFromPlantPoints(rowSeenNearOnlyInTheMiddle(), 0.0, options);
  ASSERT_TRUE(band.heightWidthValid()) << band.message;
  EXPECT_NEAR(band.width_m, 0.6, 0.021);
  EXPECT_NEAR(band.height_m, all.height_m, 1e-9);  // the height still comes from every slice
  // 20 slices of 9.4 cm: the four whose middle lies within 0.2 m of the location.
  EXPECT_EQ(band.quality.width_slices, 4);
  EXPECT_EQ(traitsToJson(band).at("quality").at("width_slices").get<int>(), 4);
}

// Plants beside the location only (a plot at the end of the view): no slice in the band, so every
// slice gives the width rather than none.
TEST(SliceExtent, AWidthBandWithoutSlicesInItUsesEverySlice) {
  Points points;
  for (const Eigen::Vector3f& p : rowSeenNearOnlyInTheMiddle()) {
    if (p.y() > 0.5F)
      points.push_back(p);
  }
  TraitsOptions options;
  options.width_band_m = 0.4;
  const TraitsResult band = traitsFromPlantPoints(points, 0.0, options);
  const TraitsResult all = traitsFromPlantPoints(points, 0.0, {});
  ASSERT_TRUE(band.heightWidthValid()) << band.message;
  EXPECT_DOUBLE_EQ(band.width_m, all.width_m);
  EXPECT_EQ(band.quality.width_slices, band.quality.occupied_slices);
}

TEST(WeightedQuantile, IsTheFirstSortedValueReachingThatShareOfTheWeight) {
  // Sorted: 1 (0.2), 2 (0.2), 3 (0.2), 10 (0.4): cumulative 0.2, 0.4, 0.6, 1.0.
  const std::vector<std::pair<double, double>> values{
      {10.0, 0.4}, {2.0, 0.2}, {1.0, 0.2}, {3.0, 0.2}};
  EXPECT_DOUBLE_EQ(weightedQuantile(values, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(weightedQuantile(values, 0.25), 2.0);
  EXPECT_DOUBLE_EQ(weightedQuantile(values, 0.5), weightedMedian(values));
  EXPECT_DOUBLE_EQ(weightedQuantile(values, 0.75), 10.0);
  EXPECT_DOUBLE_EQ(weightedQuantile(values, 1.0), 10.0);
  EXPECT_DOUBLE_EQ(weightedQuantile({}, 0.25), 0.0);
}

// A 1 m long row of plant points 1.0-1.2 m from the camera, 1 m tall, or 1.3 m tall along the
// half of the row at y > 0 (an off-type tall plant there).
Points rowBlock(bool taller_half) {
  Points points;
  const float step = 0.02F;
  for (int j = 0; j <= 50; ++j) {
    const float y = -0.5F + j * step;
    const int top = taller_half && y > 0.0F ? 65 : 50;
    for (int i = 0; i <= top; ++i)
      for (int k = 0; k <= 10; ++k)
        points.emplace_back(i * step, y, 1.0F + k * step);
  }
  return points;
}

TEST(SliceSpread, IsSmallWhereTheSlicesAgreeAndShowsARowSplitInTwoLevels) {
  const TraitsResult even = traitsFromPlantPoints(rowBlock(false), 0.0, TraitsOptions{});
  ASSERT_TRUE(even.heightWidthValid()) << even.message;
  EXPECT_LT(even.quality.slice_top_spread_m, 0.005);
  EXPECT_LT(even.quality.slice_near_spread_m, 0.005);
  EXPECT_LT(even.quality.slice_far_spread_m, 0.005);

  const TraitsResult split = traitsFromPlantPoints(rowBlock(true), 0.0, TraitsOptions{});
  ASSERT_TRUE(split.heightWidthValid()) << split.message;
  // The height is one of the two levels; the spread says the slices disagree by the 30 cm step.
  EXPECT_NEAR(split.quality.slice_top_spread_m, 0.30, 0.005);
  EXPECT_LT(split.quality.slice_near_spread_m, 0.005);
  EXPECT_LT(split.quality.slice_far_spread_m, 0.005);
  const auto quality = traitsToJson(split).at("quality");
  EXPECT_NEAR(quality.at("slice_top_spread_m").get<double>(), split.quality.slice_top_spread_m,
              1e-12);
  EXPECT_TRUE(quality.contains("slice_near_spread_m"));
  EXPECT_TRUE(quality.contains("slice_far_spread_m"));
}

TEST(SliceCount, FollowsEquation15) {
  TraitsOptions options;
  EXPECT_EQ(sliceCount(options), 20);  // 1.5 m plots, 0.15 m spacing: the paper's 20
  options.row_length_m = 3.0;
  options.intra_row_spacing_m = 0.2;
  EXPECT_EQ(sliceCount(options), 30);
  options.slices = 7;
  EXPECT_EQ(sliceCount(options), 7);
}

// The cell-centre estimate is unbiased over the grid's phase (a rim cell is half covered on
// average), not for one placement: the area tests average four placements a quarter cell apart.
template <typename AreaFn>
double meanOverGridPhase(const Points& points, AreaFn area) {
  double sum = 0.0;
  for (float f : {0.0F, 0.25F, 0.5F, 0.75F}) {
    Points shifted = points;
    for (Eigen::Vector3f& p : shifted)
      p += Eigen::Vector3f(f * 0.01F, f * 0.01F, 0.0F);
    sum += area(shifted);
  }
  return sum / 4.0;
}

TEST(DepthMapArea, MeasuresAFacingRectangle) {
  const Points plane = samplePatch([](double u, double v) { return Eigen::Vector3f(u, v, 1.0F); },
                                   0.5, 0.3, 0.003, 1);
  const double area =
      meanOverGridPhase(plane, [](const Points& p) { return depthMapArea(p, 0.01, 0.025); });
  EXPECT_NEAR(area, 0.15, 0.15 * 0.02);
  // One placement is off by at most one cell width along each edge.
  EXPECT_NEAR(depthMapArea(plane, 0.01, 0.025), 0.15, 0.01 * (0.5 + 0.3));
}

TEST(DepthMapArea, MeasuresASlopedRectangleInItsOwnPlane) {
  // 40 degrees to the view: the projected area is cos(40) of the true one.
  const double a = 40.0 * std::numbers::pi / 180.0;
  const Points plane = samplePatch(
      [&](double u, double v) {
        return Eigen::Vector3f(u * std::cos(a), v, 1.0 + u * std::sin(a));
      },
      0.4, 0.3, 0.003, 2);
  const double area =
      meanOverGridPhase(plane, [](const Points& p) { return depthMapArea(p, 0.01, 0.025); });
  EXPECT_NEAR(area, 0.12, 0.12 * 0.03);
}

TEST(MultiViewDepthMapArea, CountsSurfacesSeenEdgeOn) {
  // A half cylinder facing the camera (radius 5 cm, 40 cm long): its area is pi r l; a single
  // depth map along z loses the flanks, the multi-view one keeps them.
  const double r = 0.05;
  const Points half = samplePatch(
      [&](double s, double x) {
        const double angle = s / r;  // arc length to angle
        return Eigen::Vector3f(x, r * std::cos(angle), 1.0 - r * std::sin(angle));
      },
      std::numbers::pi * r, 0.4, 0.002, 3);
  const double truth = std::numbers::pi * r * 0.4;
  const SurfaceArea multi = multiViewDepthMapArea(half, 0.01, 0.025);
  EXPECT_NEAR(multi.area_m2, truth, truth * 0.08);
  EXPECT_LT(depthMapArea(half, 0.01, 0.025), multi.area_m2 * 0.92);
  EXPECT_GT(multi.fill, 0.7);
}

TEST(MultiViewDepthMapArea, KeepsLayersApart) {
  // Two parallel 30x30 cm sheets 10 cm apart (a leaf behind a leaf, each seen by some head).
  Points sheets = samplePatch([](double u, double v) { return Eigen::Vector3f(u, v, 1.0F); }, 0.3,
                              0.3, 0.003, 4);
  const Points back = samplePatch([](double u, double v) { return Eigen::Vector3f(u, v, 1.1F); },
                                  0.3, 0.3, 0.003, 5);
  sheets.insert(sheets.end(), back.begin(), back.end());
  const double area = meanOverGridPhase(
      sheets, [](const Points& p) { return multiViewDepthMapArea(p, 0.01, 0.025).area_m2; });
  EXPECT_NEAR(area, 0.18, 0.18 * 0.03);
}

TEST(SparseOutliers, DropIsolatedVoxelsOnly) {
  Points cloud = samplePatch([](double u, double v) { return Eigen::Vector3f(u, v, 1.0F); }, 0.2,
                             0.2, 0.01, 6);
  const std::size_t surface = cloud.size();
  cloud.emplace_back(0.5F, 0.5F, 0.5F);
  cloud.emplace_back(-0.4F, 0.1F, 1.3F);
  std::size_t removed = 0;
  const Points kept = removeSparseOutliers(cloud, 0.01, 2, removed);
  EXPECT_EQ(removed, 2U);
  EXPECT_EQ(kept.size(), surface);
}

TEST(SmallPieces, DropBlobsApartFromTheSurfaceAndKeepWhatTouchesIt) {
  // A 30 x 30 cell surface at cell centres, a 3 x 3 x 2 blob 10 cm in front of it (dense enough
  // to pass the neighbour count) and a 40-cell diagonal strand joined to the surface only through
  // the corners of its cells (a thin leaf seen edge-on).
  const float cell = 0.01F;
  auto centre = [&](int i, int j, int k) {
    return Eigen::Vector3f((i + 0.5F) * cell, (j + 0.5F) * cell, (k + 0.5F) * cell);
  };
  Points cloud;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j)
      cloud.push_back(centre(i, j, 100));
  const std::size_t surface = cloud.size();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 2; ++k)
        cloud.push_back(centre(10 + i, 10 + j, 90 + k));
  for (int step = 1; step <= 40; ++step)
    cloud.push_back(centre(29 + step, 29 + step, 100 - step));
  std::size_t removed = 0;
  const Points kept = removeSmallPieces(cloud, cell, 20, removed);
  EXPECT_EQ(removed, 18U);  // the blob, all of it
  EXPECT_EQ(kept.size(), surface + 40);
  for (const Eigen::Vector3f& p : kept)
    EXPECT_FALSE(p.z() < 0.95F && p.z() > 0.89F && p.x() < 0.14F) << p.transpose();
  // 0 or 1 keeps everything; a piece exactly at the limit stays.
  EXPECT_EQ(removeSmallPieces(cloud, cell, 0, removed).size(), cloud.size());
  EXPECT_EQ(removed, 0U);
  EXPECT_EQ(removeSmallPieces(cloud, cell, 18, removed).size(), cloud.size());
  EXPECT_EQ(removeSmallPieces(cloud, cell, 19, removed).size(), surface + 40);
}

TEST(VoxelDownsample, ShiftedGridKeepsTheGeometry) {
  const Points plane = samplePatch([](double u, double v) { return Eigen::Vector3f(u, v, 1.0F); },
                                   0.3, 0.3, 0.002, 7);
  const Points a = voxelDownsample(plane, 0.01, Eigen::Vector3f::Zero());
  const Points b = voxelDownsample(plane, 0.01, Eigen::Vector3f::Constant(0.005F));
  EXPECT_NEAR(static_cast<double>(a.size()), 900.0, 70.0);
  EXPECT_NEAR(static_cast<double>(b.size()), 900.0, 70.0);
  for (const Eigen::Vector3f& p : b)
    EXPECT_NEAR(p.z(), 1.0F, 1e-5F);
}

// The traits options file is read by config::loadTraitsOptions: tests/config/config_test.cpp.

}  // namespace
}  // namespace fieldrig::traits
