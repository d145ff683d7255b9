// The trait math on tiny hand-made geometry: weighted median, slice count, areas of surfaces of
// known size, outliers on the voxel grid, the options file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

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
