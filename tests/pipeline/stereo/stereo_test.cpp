// The stereo library's parts on hand-made fixtures: debayering against a hand mosaic, the
// left–right check, scoring, PFM round trip, and the head pipeline's answers to bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldrig/stereo/disparity_io.h"
#include "fieldrig/stereo/head.h"
#include "fieldrig/stereo/matcher.h"
#include "fieldrig/stereo/preprocess.h"
#include "support/temp_dir.h"

namespace fieldrig::stereo {
namespace {

using core::PixelFormat;

class Debayer : public ::testing::TestWithParam<PixelFormat> {};

// A flat colour mosaicked by hand and debayered by OpenCV comes back as that colour: the
// GenICam names map to the right OpenCV codes.
TEST_P(Debayer, FlatColourSurvivesMosaicAndDebayer) {
  const cv::Mat bgr(64, 64, CV_8UC3, cv::Scalar(30, 120, 220));
  const cv::Mat raw = mosaicBayer(bgr, GetParam());
  ASSERT_EQ(raw.type(), CV_8UC1);
  auto back = debayerAndScale(raw, GetParam(), 0.5);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->size(), cv::Size(32, 32));
  const cv::Vec3b centre = back->at<cv::Vec3b>(16, 16);
  EXPECT_NEAR(centre[0], 30, 2);
  EXPECT_NEAR(centre[1], 120, 2);
  EXPECT_NEAR(centre[2], 220, 2);
}

INSTANTIATE_TEST_SUITE_P(AllPatterns, Debayer,
                         ::testing::Values(PixelFormat::kBayerRG8, PixelFormat::kBayerGR8,
                                           PixelFormat::kBayerGB8, PixelFormat::kBayerBG8));

TEST(Preprocess, BadFramesAreErrors) {
  EXPECT_FALSE(debayerAndScale(cv::Mat(), PixelFormat::kBayerRG8, 0.5));
  EXPECT_FALSE(debayerAndScale(cv::Mat(10, 11, CV_8UC1), PixelFormat::kBayerRG8, 0.5));
  EXPECT_FALSE(debayerAndScale(cv::Mat(10, 10, CV_16UC1), PixelFormat::kBayerRG8, 0.5));
  EXPECT_FALSE(debayerAndScale(cv::Mat(10, 10, CV_8UC1), PixelFormat::kBayerRG8, 2.0));
}

TEST(LeftRightCheck, KeepsConsistentAndDropsInconsistentPixels) {
  cv::Mat left(1, 6, CV_32F, cv::Scalar(kInvalidDisparity));
  cv::Mat right(1, 6, CV_32F, cv::Scalar(kInvalidDisparity));
  left.at<float>(0, 4) = 2.0f;   // matches right x=2
  right.at<float>(0, 2) = 2.5f;  // within 1 px: kept
  left.at<float>(0, 5) = 2.0f;   // matches right x=3
  right.at<float>(0, 3) = 4.0f;  // 2 px off: dropped
  left.at<float>(0, 1) = 3.0f;   // would match x = -2: outside, dropped
  leftRightCheck(left, right, 1.0f);
  EXPECT_FLOAT_EQ(left.at<float>(0, 4), 2.0f);
  EXPECT_FLOAT_EQ(left.at<float>(0, 5), kInvalidDisparity);
  EXPECT_FLOAT_EQ(left.at<float>(0, 1), kInvalidDisparity);
}

// Two pieces of the ambiguous map fill the confident map's holes: the one the confident map
// agrees with somewhere is added, the one it never confirms (a mismatched blob) is not; where
// the confident map has a disparity, it stays.
TEST(GrowConfirmedPieces, AddsOnlyPiecesTheConfidentMapConfirms) {
  cv::Mat confident(2, 8, CV_32F, cv::Scalar(kInvalidDisparity));
  cv::Mat ambiguous(2, 8, CV_32F, cv::Scalar(kInvalidDisparity));
  // Piece A, columns 0-3 of both rows, a slope of 10..11.5: confirmed at (0, 0) only.
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      ambiguous.at<float>(y, x) = 10.0f + 0.5f * static_cast<float>(x);
  confident.at<float>(0, 0) = 10.4f;
  confident.at<float>(1, 1) = 20.0f;  // disagrees: keeps its own value
  // Piece B, columns 5-7: 40 px, a jump of 28 from A's end; the confident map is 3 px off it.
  for (int y = 0; y < 2; ++y)
    for (int x = 5; x < 8; ++x)
      ambiguous.at<float>(y, x) = 40.0f;
  confident.at<float>(0, 6) = 43.0f;

  const cv::Mat grown = growConfirmedPieces(confident, ambiguous, 2.0f, 0.0);
  EXPECT_FLOAT_EQ(grown.at<float>(0, 0), 10.4f);
  EXPECT_FLOAT_EQ(grown.at<float>(1, 1), 20.0f);
  EXPECT_FLOAT_EQ(grown.at<float>(0, 3), 11.5f);
  EXPECT_FLOAT_EQ(grown.at<float>(1, 2), 11.0f);
  EXPECT_FLOAT_EQ(grown.at<float>(0, 4), kInvalidDisparity);  // in neither map
  EXPECT_FLOAT_EQ(grown.at<float>(0, 6), 43.0f);
  EXPECT_FLOAT_EQ(grown.at<float>(1, 5), kInvalidDisparity);  // piece B: never confirmed

  // One confirmed pixel of A's eight is not more than half of them.
  const cv::Mat strict = growConfirmedPieces(confident, ambiguous, 2.0f, 0.5);
  EXPECT_FLOAT_EQ(strict.at<float>(0, 3), kInvalidDisparity);
  EXPECT_FLOAT_EQ(strict.at<float>(0, 0), 10.4f);
}

TEST(Scoring, CountsHandMadeFixture) {
  // Truth: 4 known pixels, one unknown (0). Estimates: exact, 1.5 off, 3 off, invalid.
  const cv::Mat truth = (cv::Mat_<float>(1, 5) << 10, 10, 10, 10, 0);
  const cv::Mat estimate = (cv::Mat_<float>(1, 5) << 10, 11.5f, 13, -1, 50);
  const DisparityScores s = scoreDisparity(estimate, truth);
  EXPECT_DOUBLE_EQ(s.known_pixels, 4);
  EXPECT_DOUBLE_EQ(s.valid_fraction, 0.75);
  EXPECT_DOUBLE_EQ(s.bad1_valid, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.bad2_valid, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.bad1_all, 3.0 / 4.0);
  EXPECT_DOUBLE_EQ(s.bad2_all, 2.0 / 4.0);
}

TEST(Pfm, RoundTripKeepsFloatsAndOrientation) {
  testing_support::ScopedTempDir dir("stereo_pfm");
  cv::Mat disparity(7, 5, CV_32F);
  for (int y = 0; y < 7; ++y) {
    for (int x = 0; x < 5; ++x)
      disparity.at<float>(y, x) = 10.25f * y + 0.5f * x - 3.0f;
  }
  ASSERT_TRUE(writePfm(dir / "d.pfm", disparity));
  auto back = readPfm(dir / "d.pfm");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(cv::norm(*back, disparity, cv::NORM_INF), 0.0);
  EXPECT_FALSE(readPfm(dir / "absent.pfm"));
  EXPECT_FALSE(writePfm(dir / "x.pfm", cv::Mat(3, 3, CV_8UC1)));
}

TEST(Pfm, AFullDiskAndADamagedHeaderAreErrorsNamingTheFile) {
  testing_support::ScopedTempDir dir("stereo_pfm_damage");
  const cv::Mat disparity(64, 48, CV_32F, cv::Scalar(2.5f));
  // /dev/full refuses every byte (ENOSPC), as a full disk does.
  auto full = writePfm("/dev/full", disparity);
  ASSERT_FALSE(full);
  EXPECT_EQ(full.error().message.rfind("/dev/full: cannot write", 0), 0u) << full.error().message;

  ASSERT_TRUE(writePfm(dir / "whole.pfm", disparity));
  const auto size = std::filesystem::file_size(dir / "whole.pfm");
  std::filesystem::copy_file(dir / "whole.pfm", dir / "cut.pfm");
  std::filesystem::resize_file(dir / "cut.pfm", size / 2);
  auto cut = readPfm(dir / "cut.pfm");
  ASSERT_FALSE(cut);
  EXPECT_NE(cut.error().message.find((dir / "cut.pfm").string() + ": PFM header says 48 x 64"),
            std::string::npos)
      << cut.error().message;
  // A small file whose header asks for gigabytes is refused before anything is allocated.
  {
    std::ofstream huge(dir / "huge.pfm", std::ios::binary);
    huge << "Pf\n30000 30000\n-1\n" << std::string(1000, '\0');
  }
  auto refused = readPfm(dir / "huge.pfm");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("more than the file holds"), std::string::npos)
      << refused.error().message;
  {
    std::ofstream text(dir / "text.pfm");
    text << "not an image";
  }
  auto not_pfm = readPfm(dir / "text.pfm");
  ASSERT_FALSE(not_pfm);
  EXPECT_NE(not_pfm.error().message.find("not a PFM file"), std::string::npos);
}

StereoCalibration smallCalibration(cv::Size size) {
  StereoCalibration c;
  c.image_size = size;
  c.M1 = (cv::Mat_<double>(3, 3) << 400, 0, size.width / 2.0, 0, 400, size.height / 2.0, 0, 0, 1);
  c.M2 = c.M1.clone();
  c.D1 = cv::Mat::zeros(1, 5, CV_64F);
  c.D2 = c.D1.clone();
  c.R = cv::Mat::eye(3, 3, CV_64F);
  c.T = (cv::Mat_<double>(3, 1) << -0.12, 0, 0);
  cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                    cv::CALIB_ZERO_DISPARITY, 0);
  return c;
}

TEST(HeadPipeline, BadInputIsAnErrorNamingHeadAndImage) {
  HeadOptions options;
  options.matcher.num_disparities = 16;
  auto head = HeadPipeline::create(smallCalibration({160, 120}), options);
  ASSERT_TRUE(head) << head.error().message;
  cv::Mat textured(120, 160, CV_8UC1);
  cv::randu(textured, 0, 255);
  const cv::Mat black = cv::Mat::zeros(120, 160, CV_8UC1);

  auto wrong_size = head->process(textured, cv::Mat(100, 160, CV_8UC1, cv::Scalar(90)),
                                  PixelFormat::kBayerRG8, "middle");
  ASSERT_FALSE(wrong_size);
  EXPECT_EQ(wrong_size.error().message,
            "middle: right image is 160x100 but the calibration is for 160x120");

  auto blank = head->process(black, textured, PixelFormat::kBayerRG8, "top");
  ASSERT_FALSE(blank);
  EXPECT_EQ(blank.error().message, "top: left image is blank (brightest pixel 0)");

  auto missing = head->process(textured, cv::Mat(), PixelFormat::kBayerRG8, "bottom");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "bottom: right image is missing");

  auto fine = head->process(textured, textured, PixelFormat::kBayerRG8, "bottom");
  ASSERT_TRUE(fine) << fine.error().message;
  EXPECT_EQ(fine->disparity.size(), cv::Size(80, 60));
  EXPECT_EQ(fine->left_bgr.type(), CV_8UC3);
}

TEST(HeadPipeline, CalibrationWithoutImageSizeIsRefused) {
  StereoCalibration c = smallCalibration({160, 120});
  c.image_size = cv::Size();
  auto head = HeadPipeline::create(c, HeadOptions{});
  ASSERT_FALSE(head);
  EXPECT_NE(head.error().message.find("no image size"), std::string::npos);
}

TEST(Calibration, ScaledHalvesFocalAndKeepsDepth) {
  StereoCalibration full = smallCalibration({160, 120});
  // A pair rectified without CALIB_ZERO_DISPARITY: principal points 6 px apart, so Q's constant
  // term (cx - cx')/Tx is not zero.
  full.Q.at<double>(3, 3) = 6.0 / full.T.at<double>(0);
  const StereoCalibration half = full.scaled(0.5);
  const double full_focal = full.rectifiedFocalPx();
  const StereoCalibration half_again = full.scaled(0.5);
  // Scaling leaves the original untouched (it once rescaled it in place through shared buffers).
  EXPECT_EQ(full.rectifiedFocalPx(), full_focal);
  EXPECT_NEAR(half_again.rectifiedFocalPx(), full_focal / 2, 1e-9);
  EXPECT_NEAR(half.rectifiedFocalPx(), full_focal / 2, 1e-9);
  EXPECT_EQ(half.image_size, cv::Size(80, 60));
  // The same point seen at half resolution has half the disparity and the same depth.
  const cv::Vec4d full_point = cv::Matx44d(full.Q) * cv::Vec4d(100, 70, 40, 1);
  const cv::Vec4d half_point = cv::Matx44d(half.Q) * cv::Vec4d(50, 35, 20, 1);
  EXPECT_NEAR(full_point[2] / full_point[3], half_point[2] / half_point[3], 1e-9);
  EXPECT_NEAR(full_point[0] / full_point[3], half_point[0] / half_point[3], 1e-9);
}

}  // namespace
}  // namespace fieldrig::stereo
