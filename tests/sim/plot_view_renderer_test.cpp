// The plot renderer must give a stereo pair a matcher can read: the same surface shows the same
// texture in both views, shifted by the disparity its depth implies.
#include "fieldrig/sim/plot_view_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace fieldrig::sim {
namespace {

constexpr double kFocalPx = 1350.0;
constexpr double kBaselineM = 0.12;

struct Pair {
  cv::Mat left, right;
};

Pair renderPair(const PlotCloud& plot, double camera_height_m) {
  PinholeView view;
  view.focal_px = kFocalPx;
  view.position = Eigen::Vector3d(camera_height_m, 0.0, 0.0);
  Pair pair;
  pair.left = renderPlotView(plot, view);
  view.position.y() += kBaselineM;  // the right camera: one baseline along the row
  pair.right = renderPlotView(plot, view);
  if (const char* dump = std::getenv("FIELDRIG_DUMP_RENDER")) {
    cv::imwrite(std::string(dump) + "_left.png", pair.left);
    cv::imwrite(std::string(dump) + "_right.png", pair.right);
  }
  return pair;
}

// Median of the valid disparities (px) in `roi` of a half-resolution SGBM run.
double medianDisparity(const Pair& pair, const cv::Rect& roi) {
  cv::Mat left, right;
  cv::resize(pair.left, left, {}, 0.5, 0.5, cv::INTER_AREA);
  cv::resize(pair.right, right, {}, 0.5, 0.5, cv::INTER_AREA);
  auto sgbm = cv::StereoSGBM::create(0, 128, 5, 8 * 3 * 25, 32 * 3 * 25, 1, 63, 10, 100, 2,
                                     cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat disparity16;
  sgbm->compute(left, right, disparity16);
  std::vector<float> values;
  const cv::Rect half(roi.x / 2, roi.y / 2, roi.width / 2, roi.height / 2);
  for (int y = half.y; y < half.y + half.height; ++y) {
    for (int x = half.x; x < half.x + half.width; ++x) {
      const short d = disparity16.at<short>(y, x);
      if (d > 0)
        values.push_back(d / 16.0F);
    }
  }
  if (values.size() < 100)
    return 0.0;
  std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() / 2),
                   values.end());
  return 2.0 * values[values.size() / 2];  // back to full-resolution pixels
}

TEST(PlotViewRenderer, SoilInFrontOfTheRowMatchesAtItsDepth) {
  PlotSpec spec;
  spec.plants = false;  // soil only: its depth at each image row is known
  spec.soil_roughness_m = 0;
  spec.depth_noise_m = 0;
  spec.outlier_fraction = 0;
  const PlotCloud plot = generatePlot(spec);
  const double camera_height = 0.55;
  const Pair pair = renderPair(plot, camera_height);
  // An image row below the centre sees flat soil at depth z = f·h / (v − cy).
  const int row = 1000;
  const double depth = kFocalPx * camera_height / (row - (1224 - 1) / 2.0);
  const double expected = kFocalPx * kBaselineM / depth;
  const double measured = medianDisparity(pair, cv::Rect(400, row - 8, 800, 16));
  EXPECT_NEAR(measured, expected, 0.02 * expected) << "soil at depth " << depth << " m";
}

TEST(PlotViewRenderer, PlantRowMatchesAtTheRowDepth) {
  PlotSpec spec;
  spec.depth_noise_m = 0;
  spec.outlier_fraction = 0;
  spec.camera_heads = 6;
  const PlotCloud plot = generatePlot(spec);
  const Pair pair = renderPair(plot, 1.2);
  // Around the image centre the view is full of stems and leaves about row_depth_m away (leaves
  // arch toward the camera, so the median comes a little nearer than the stems).
  const double stems = kFocalPx * kBaselineM / spec.row_depth_m;
  const double measured = medianDisparity(pair, cv::Rect(500, 400, 600, 400));
  EXPECT_GT(measured, stems * 0.97);
  EXPECT_LT(measured, stems * 1.25);
}

TEST(PlotViewRenderer, BackdropIsBeyondAnyCrop) {
  PlotSpec spec;
  spec.plants = false;
  spec.soil = false;
  const PlotCloud plot = generatePlot(spec);
  PinholeView view;
  const cv::Mat image = renderPlotView(plot, view);
  ASSERT_EQ(image.size(), view.size);
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  EXPECT_GT(stddev[1], 10.0) << "the backdrop must carry texture";
}

}  // namespace
}  // namespace fieldrig::sim
