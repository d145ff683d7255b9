// fieldrig's matcher against plain OpenCV SGBM with default parameters on real ground truth
// (Middlebury Teddy and Cones, GT = disp2.pgm / 4; Aloe, GT in pixels), measured in the same run.
// Margins: measured here (OpenCV 4.6) fieldrig's bad>1 over valid pixels is 0.53×, 0.58× and
// 0.23× the default's, and bad>1 counting invalid pixels as bad is 6.7, 3.3 and 14.3 points lower.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
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
  // Issue 11's bar, counting invalid pixels as bad, for the matching itself: full-width matching
  // gives the band SGBM leaves empty its disparities (measured 0.55×, 0.63× and 0.41× the
  // default's bad>2 with min_texture 0). The shipped min_texture (2, against sky in the field)
  // leaves Teddy's flat walls without depth by design: 0.87× there, 0.68× and 0.51× elsewhere.
  MatcherOptions all_texture = options;
  all_texture.min_texture = 0.0;
  const DisparityScores matched =
      scoreDisparity(DisparityMatcher(all_texture).compute(scene.left, scene.right), scene.truth);
  EXPECT_LT(matched.bad2_all, 0.8 * baseline.bad2_all);

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

namespace fieldrig::stereo {
namespace {

// A fronto-parallel textured plane at `disparity` pixels: the right view is the left shifted, cut
// from a texture wide enough that every right pixel sees texture.
struct ShiftedPair {
  cv::Mat left, right;
};
ShiftedPair shiftedPair(cv::Size size, int disparity) {
  cv::Mat texture(size.height, size.width + disparity, CV_8U);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  // Left pixel x sees texture column x; the right camera sees it at column x - disparity, so the
  // left's first `disparity` columns are outside the right image.
  return {texture(cv::Rect(0, 0, size.width, size.height)).clone(),
          texture(cv::Rect(disparity, 0, size.width, size.height)).clone()};
}

TEST(FullWidth, MatchesTheBandSgbmLeavesEmptyAndNothingOutsideTheRightImage) {
  constexpr int kDisparity = 20;
  const ShiftedPair pair = shiftedPair({320, 120}, kDisparity);
  MatcherOptions options;
  options.num_disparities = 64;
  options.full_width = false;
  const cv::Mat banded = DisparityMatcher(options).compute(pair.left, pair.right);
  options.full_width = true;
  const cv::Mat full = DisparityMatcher(options).compute(pair.left, pair.right);
  ASSERT_EQ(full.size(), pair.left.size());
  int band_valid_before = 0, band_correct = 0, band_pixels = 0, outside_valid = 0;
  for (int y = 10; y < full.rows - 10; ++y) {
    for (int x = 0; x < options.num_disparities; ++x) {
      if (x < kDisparity) {
        outside_valid += full.at<float>(y, x) >= 0 ? 1 : 0;  // its match is left of the image
        continue;
      }
      ++band_pixels;
      band_valid_before += banded.at<float>(y, x) >= 0 ? 1 : 0;
      band_correct += std::abs(full.at<float>(y, x) - kDisparity) <= 1.0f ? 1 : 0;
    }
  }
  EXPECT_EQ(band_valid_before, 0) << "SGBM's band: nothing matched there without padding";
  EXPECT_GT(band_correct, 0.95 * band_pixels) << "the band's pixels that the right camera sees";
  EXPECT_EQ(outside_valid, 0) << "a match in the padding is no match";
}

TEST(MinTexture, FlatRegionsGiveNoDisparityTexturedOnesKeepTheirs) {
  constexpr int kDisparity = 12;
  ShiftedPair pair = shiftedPair({320, 120}, kDisparity);
  // A flat bright patch (sky, a saturated highlight) on the same plane, seen by both cameras.
  const cv::Rect flat_left(150, 30, 80, 60);
  pair.left(flat_left).setTo(250);
  pair.right(flat_left - cv::Point(kDisparity, 0)).setTo(250);
  MatcherOptions options;
  options.num_disparities = 32;
  options.min_texture = 0.0;
  const cv::Mat kept = DisparityMatcher(options).compute(pair.left, pair.right);
  options.min_texture = 2.0;
  const cv::Mat masked = DisparityMatcher(options).compute(pair.left, pair.right);
  const cv::Rect inner(flat_left.x + 5, flat_left.y + 5, flat_left.width - 10,
                       flat_left.height - 10);
  const auto validIn = [](const cv::Mat& disparity, const cv::Rect& area) {
    return cv::countNonZero(disparity(area) >= 0);
  };
  EXPECT_GT(validIn(kept, inner), inner.area() / 2)
      << "SGBM fills a flat patch from its surroundings: what min_texture is for";
  EXPECT_EQ(validIn(masked, inner), 0);
  const cv::Rect textured(60, 30, 60, 60);
  EXPECT_EQ(validIn(masked, textured), validIn(kept, textured));
}

TEST(MinTexture, OutOfRangeIsAnErrorNamingIt) {
  MatcherOptions options;
  options.min_texture = std::numeric_limits<double>::quiet_NaN();
  const auto nan = validate(options);
  ASSERT_FALSE(nan);
  EXPECT_NE(nan.error().message.find("min_texture"), std::string::npos);
  options.min_texture = 200;
  EXPECT_FALSE(validate(options));
}

}  // namespace
}  // namespace fieldrig::stereo

namespace fieldrig::stereo {
namespace {

// grow_uniqueness_ratio on real pairs with ground truth: every pixel the shipped matcher gives
// keeps its disparity, more pixels get one, and the pixels it adds are right at least as often
// as those that simply lowering uniqueness_ratio adds (its point: the ambiguous matches kept
// are those in pieces the confident ones confirm).
class GrowAccuracy : public ::testing::TestWithParam<std::string> {};

TEST_P(GrowAccuracy, KeepsTheConfidentMatchesAndAddsBetterOnesThanLowerUniqueness) {
  const Scene scene = loadScene(GetParam());
  ASSERT_FALSE(scene.left.empty());
  MatcherOptions options;
  options.num_disparities = scene.num_disparities;
  const cv::Mat shipped = DisparityMatcher(options).compute(scene.left, scene.right);
  MatcherOptions grow_options = options;
  grow_options.grow_uniqueness_ratio = 0;
  const cv::Mat grown = DisparityMatcher(grow_options).compute(scene.left, scene.right);
  MatcherOptions low_options = options;
  low_options.uniqueness_ratio = 0;
  const cv::Mat low = DisparityMatcher(low_options).compute(scene.left, scene.right);
  int changed = 0;
  int added_grow = 0, bad_grow = 0, added_low = 0, bad_low = 0;
  for (int y = 0; y < shipped.rows; ++y) {
    for (int x = 0; x < shipped.cols; ++x) {
      const float s = shipped.at<float>(y, x);
      const float truth = scene.truth.at<float>(y, x);
      if (s >= 0) {
        changed += grown.at<float>(y, x) != s ? 1 : 0;
        continue;
      }
      if (truth <= 0)
        continue;
      if (grown.at<float>(y, x) >= 0) {
        ++added_grow;
        bad_grow += std::abs(grown.at<float>(y, x) - truth) > 2.0f ? 1 : 0;
      }
      if (low.at<float>(y, x) >= 0) {
        ++added_low;
        bad_low += std::abs(low.at<float>(y, x) - truth) > 2.0f ? 1 : 0;
      }
    }
  }
  std::printf("%s: grow adds %d (bad-2 %.3f), uniqueness 0 adds %d (bad-2 %.3f)\n",
              GetParam().c_str(), added_grow, added_grow ? 1.0 * bad_grow / added_grow : 0.0,
              added_low, added_low ? 1.0 * bad_low / added_low : 0.0);
  EXPECT_EQ(changed, 0);
  EXPECT_GT(added_grow, 0);
  ASSERT_GT(added_low, 0);
  EXPECT_LE(1.0 * bad_grow / added_grow, 1.0 * bad_low / added_low);
}

INSTANTIATE_TEST_SUITE_P(Scenes, GrowAccuracy, ::testing::Values("teddy", "cones", "aloe"));

}  // namespace
}  // namespace fieldrig::stereo
