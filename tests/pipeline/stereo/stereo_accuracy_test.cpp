// fieldrig's matcher against plain OpenCV SGBM with default parameters on real ground truth
// (Middlebury Teddy and Cones, GT = disp2.pgm / 4; Aloe, GT in pixels), measured in the same run.
// Margins: measured here (OpenCV 4.6) fieldrig's bad>1 over valid pixels is 0.53×, 0.58× and
// 0.23× the default's, and bad>1 counting invalid pixels as bad is 6.7, 3.3 and 14.3 points lower.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>

#include "fieldrig/stereo/disparity_io.h"
#include "fieldrig/stereo/matcher.h"

namespace fieldrig::stereo {
namespace {

struct Scene {
  cv::Mat left, right, truth;
  int num_disparities;
};

Scene loadScene(const std::string& name) {
  const std::string data = std::string(FIELDRIG_SHARED_DATA_DIR) + "/stereo/";
  Scene scene;
  if (name == "aloe") {
    scene.left = cv::imread(data + "opencv_aloe/aloeL.jpg");
    scene.right = cv::imread(data + "opencv_aloe/aloeR.jpg");
    cv::imread(data + "opencv_aloe/aloeGT.png", cv::IMREAD_GRAYSCALE)
        .convertTo(scene.truth, CV_32F);
    scene.num_disparities = 224;  // GT reaches 211
  } else {
    const std::string dir = data + "middlebury2003/" + name + "/";
    scene.left = cv::imread(dir + "im2.png");
    scene.right = cv::imread(dir + "im6.png");
    cv::imread(dir + "disp2.pgm", cv::IMREAD_GRAYSCALE).convertTo(scene.truth, CV_32F, 0.25);
    scene.num_disparities = 64;
  }
  return scene;
}

class StereoAccuracy : public ::testing::TestWithParam<std::string> {};

TEST_P(StereoAccuracy, BeatsDefaultOpenCvSgbm) {
  const Scene scene = loadScene(GetParam());
  ASSERT_FALSE(scene.left.empty());
  ASSERT_FALSE(scene.truth.empty());
  const DisparityScores baseline = scoreDisparity(
      computeDefaultSgbm(scene.left, scene.right, scene.num_disparities), scene.truth);
  MatcherOptions options;
  options.num_disparities = scene.num_disparities;
  DisparityMatcher matcher(options);
  const DisparityScores ours =
      scoreDisparity(matcher.compute(scene.left, scene.right), scene.truth);
  std::printf(
      "%s: default bad1 %.4f bad1_all %.4f valid %.4f | fieldrig bad1 %.4f bad1_all %.4f "
      "valid %.4f\n",
      GetParam().c_str(), baseline.bad1_valid, baseline.bad1_all, baseline.valid_fraction,
      ours.bad1_valid, ours.bad1_all, ours.valid_fraction);
  EXPECT_LT(ours.bad1_valid, 0.7 * baseline.bad1_valid);
  EXPECT_LT(ours.bad2_valid, 0.7 * baseline.bad2_valid);
  // Not by invalidating: counting invalid pixels as bad it still wins, and it keeps about as
  // many pixels (within 3 points; measured −1.8 on Aloe, +0.6 on Teddy).
  EXPECT_LT(ours.bad1_all, baseline.bad1_all - 0.02);
  EXPECT_LT(ours.bad2_all, baseline.bad2_all - 0.02);
  EXPECT_GT(ours.valid_fraction, baseline.valid_fraction - 0.03);

  // The explicit left–right check removes more wrong matches than SGBM's own.
  options.lr_check = true;
  DisparityMatcher checked(options);
  const DisparityScores lr = scoreDisparity(checked.compute(scene.left, scene.right), scene.truth);
  EXPECT_LT(lr.bad1_valid, ours.bad1_valid);
  EXPECT_LT(lr.valid_fraction, ours.valid_fraction);
}

INSTANTIATE_TEST_SUITE_P(Middlebury, StereoAccuracy, ::testing::Values("teddy", "cones", "aloe"));

}  // namespace
}  // namespace fieldrig::stereo
