// The rendered truth depth as disparity (stereo/truth_depth.h) on a hand-made distorted, rotated
// pair: a wall at one raw-camera depth reprojects (through Q and back by R1) onto that depth at
// every pixel, at the matching resolution; the head pipeline feeds it in place of matching; and
// the score counts what it should.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>

#include "fieldrig/stereo/head.h"
#include "fieldrig/stereo/matcher.h"
#include "fieldrig/stereo/preprocess.h"
#include "fieldrig/stereo/truth_depth.h"

namespace fieldrig::stereo {
namespace {

// A pair like the rig's at 800×600: k1 = −0.12 lenses, the right camera a little rotated and
// 0.12 m along x, so that R1 is not the identity.
StereoCalibration distortedPair() {
  StereoCalibration c;
  c.image_size = cv::Size(800, 600);
  c.M1 = (cv::Mat_<double>(3, 3) << 820, 0, 405, 0, 818, 297, 0, 0, 1);
  c.M2 = (cv::Mat_<double>(3, 3) << 815, 0, 398, 0, 816, 303, 0, 0, 1);
  c.D1 = (cv::Mat_<double>(1, 5) << -0.12, 0.01, 0, 0, 0);
  c.D2 = (cv::Mat_<double>(1, 5) << -0.11, 0.01, 0, 0, 0);
  cv::Mat rvec = (cv::Mat_<double>(3, 1) << 0.01, -0.02, 0.005);
  cv::Rodrigues(rvec, c.R);
  c.T = (cv::Mat_<double>(3, 1) << -0.12, 0.003, 0.002);
  cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, c.image_size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q, 0,
                    0);
  return c;
}

TEST(TruthDepth, AWallAtOneRawDepthReprojectsOntoThatDepthAtMatchingResolution) {
  const StereoCalibration full = distortedPair();
  const double scale = 0.5;
  const StereoCalibration scaled = full.scaled(scale);
  auto truth = TruthDepthRectifier::create(scaled, full.image_size, scale);
  ASSERT_TRUE(truth) << truth.error().message;
  const float wall_z = 1.3f;
  cv::Mat raw_depth(full.image_size, CV_32F, cv::Scalar(wall_z));
  raw_depth(cv::Rect(0, 0, 100, 600)).setTo(0.0f);  // sky on the left: no disparity there
  auto disparity = truth->disparity(raw_depth);
  ASSERT_TRUE(disparity) << disparity.error().message;
  ASSERT_EQ(disparity->size(), scaled.image_size);
  const cv::Matx44d q(scaled.Q);
  const cv::Matx33d r1(scaled.R1);
  std::size_t valid = 0, checked = 0;
  for (int v = 0; v < disparity->rows; v += 7) {
    for (int u = 0; u < disparity->cols; u += 7) {
      const float d = disparity->at<float>(v, u);
      ++checked;
      if (!(d > 0))
        continue;
      ++valid;
      const cv::Vec4d h = q * cv::Vec4d(u, v, d, 1);
      const cv::Vec3d rectified(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
      const cv::Vec3d raw = r1.t() * rectified;  // back into the raw left camera's frame
      ASSERT_NEAR(raw[2], wall_z, 1e-3) << "pixel " << u << "," << v;
    }
  }
  // The sky band (an eighth of the raw width, a little more after rectification) and the
  // rectified border outside the raw image have none; the rest does.
  EXPECT_GT(valid, checked * 6 / 10);
  EXPECT_LT(valid, checked * 9 / 10);
}

TEST(TruthDepth, TheHeadPipelineTakesTruthInPlaceOfMatchingAndRefusesAWrongSize) {
  const StereoCalibration full = distortedPair();
  auto head = HeadPipeline::create(full, HeadOptions{});
  ASSERT_TRUE(head) << head.error().message;
  cv::Mat bgr(full.image_size, CV_8UC3, cv::Scalar(40, 140, 90));
  const cv::Mat raw_left = mosaicBayer(bgr, core::PixelFormat::kBayerRG8);
  const cv::Mat depth(full.image_size, CV_32F, cv::Scalar(1.0f));
  auto out = head->processTruthDepth(raw_left, depth, core::PixelFormat::kBayerRG8, "bottom");
  ASSERT_TRUE(out) << out.error().message;
  EXPECT_EQ(out->left_bgr.size(), cv::Size(400, 300));
  EXPECT_EQ(out->disparity.size(), cv::Size(400, 300));
  // Reprojected with the head's Q, the centre lies 1 m away (the wall is nearly square to the
  // rectified axis there; the pair is rectified without zero disparity, so d is not f·B/z).
  const cv::Matx44d q(head->matchingCalibration().Q);
  const double d = out->disparity.at<float>(150, 200);
  EXPECT_NEAR(q(2, 3) / (q(3, 2) * d + q(3, 3)), 1.0, 0.02);
  const cv::Mat small(cv::Size(400, 300), CV_32F, cv::Scalar(1.0f));
  auto refused = head->processTruthDepth(raw_left, small, core::PixelFormat::kBayerRG8, "bottom");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("bottom: truth depth map is 400x300"), std::string::npos)
      << refused.error().message;
}

TEST(TruthDepth, TheScoreCountsMatchedAndBadPixelsAndTheDepthError) {
  const StereoCalibration full = distortedPair();
  const StereoCalibration scaled = full.scaled(0.5);
  auto truth = TruthDepthRectifier::create(scaled, full.image_size, 0.5);
  ASSERT_TRUE(truth) << truth.error().message;
  const cv::Size size = scaled.image_size;
  const cv::Matx44d q(scaled.Q);
  // Truth: 40 px everywhere. Measured: a quarter unmatched, a quarter 3 px off (bad), half
  // 0.5 px off (good). Mask: everything.
  const cv::Mat truth_disparity(size, CV_32F, cv::Scalar(40.0f));
  cv::Mat measured(size, CV_32F, cv::Scalar(40.5f));
  measured(cv::Rect(0, 0, size.width / 4, size.height)).setTo(kInvalidDisparity);
  measured(cv::Rect(size.width / 4, 0, size.width / 4, size.height)).setTo(43.0f);
  const cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  const DisparityTruthScore score = truth->score(measured, truth_disparity, mask, 0.2, 5.0);
  EXPECT_EQ(score.pixels, static_cast<std::size_t>(size.area()));
  EXPECT_NEAR(score.matched_fraction, 0.75, 0.01);
  EXPECT_NEAR(score.bad_fraction, 1.0 / 3.0, 0.01);
  // The median error is that of the 0.5 px pixels: nearer, by z·0.5/(d + 0.5) with z at d = 40.
  const double z40 = q(2, 3) / (q(3, 2) * 40 + q(3, 3));
  const double z405 = q(2, 3) / (q(3, 2) * 40.5 + q(3, 3));
  EXPECT_NEAR(score.median_depth_error_m, z405 - z40, 1e-4);
  EXPECT_LT(score.median_depth_error_m, 0);
  EXPECT_NEAR(score.median_abs_depth_error_m, z40 - z405, 1e-4);
  // Outside the depth range nothing counts.
  EXPECT_EQ(truth->score(measured, truth_disparity, mask, 0.2, 0.5 * z40).pixels, 0U);
}

TEST(TruthDepth, CloudScoreCountsPointsOffTheSurfaceAndOnSky) {
  const StereoCalibration full = distortedPair();
  const StereoCalibration scaled = full.scaled(0.5);
  auto truth = TruthDepthRectifier::create(scaled, full.image_size, 0.5);
  ASSERT_TRUE(truth) << truth.error().message;
  const cv::Size size = scaled.image_size;
  const cv::Matx44d q(scaled.Q);
  auto depthAt = [&q](double d) { return q(2, 3) / (q(3, 2) * d + q(3, 3)); };
  // Truth: 40 px, except the top quarter of rows, which is sky. Measured: the left quarter of
  // columns unmatched; a disparity 40 px elsewhere, except one column band 6 px nearer, which at
  // this depth is several cm off the surface; the sky quarter got matches (as sky does).
  cv::Mat truth_disparity(size, CV_32F, cv::Scalar(40.0f));
  truth_disparity(cv::Rect(0, 0, size.width, size.height / 4)).setTo(kInvalidDisparity);
  cv::Mat measured(size, CV_32F, cv::Scalar(40.0f));
  measured(cv::Rect(0, 0, size.width / 4, size.height)).setTo(kInvalidDisparity);
  measured(cv::Rect(size.width / 2, 0, size.width / 4, size.height)).setTo(46.0f);
  ASSERT_GT(depthAt(40.0) - depthAt(46.0), 0.03) << "the test's off band must be off";
  const CloudTruthScore score = truth->scoreCloud(measured, truth_disparity, 0.2, 5.0);
  EXPECT_EQ(score.points, static_cast<std::size_t>(size.height) * (size.width - size.width / 4));
  // Of the matched three quarters of columns: the sky rows (a quarter) are off and on sky; of the
  // rest, the band (a third of the matched columns) is off. (The two rows beside the sky see
  // surface on neighbouring rays: a few pixels' worth, inside the tolerance.)
  EXPECT_NEAR(score.on_sky_fraction, 0.25, 0.01);
  EXPECT_NEAR(score.off_surface_fraction, 0.25 + 0.75 / 3.0, 0.01);
  // The band is nearer than its surface; the sky has no side; nothing lies behind a surface.
  EXPECT_NEAR(score.off_nearer_fraction, 0.75 / 3.0, 0.01);
  EXPECT_EQ(score.off_farther_fraction, 0.0);
  EXPECT_EQ(score.from_beyond_crop_fraction, 0.0);
  // With the crop between the band's depth and the surface's, the surface is beyond it: only the
  // band's points are left, those below the sky each a background matched into the crop.
  const double between = 0.5 * (depthAt(40.0) + depthAt(46.0));
  const CloudTruthScore pulled_in = truth->scoreCloud(measured, truth_disparity, 0.2, between);
  EXPECT_EQ(pulled_in.points, static_cast<std::size_t>(size.height) * (size.width / 4));
  EXPECT_NEAR(pulled_in.off_nearer_fraction, 0.75, 0.01);
  EXPECT_EQ(pulled_in.from_beyond_crop_fraction, pulled_in.off_nearer_fraction);
  // A band pushed back 6 px is farther than its surface.
  cv::Mat pushed_back = measured.clone();
  pushed_back(
      cv::Rect(size.width / 2, size.height / 4, size.width / 4, size.height - size.height / 4))
      .setTo(34.0f);
  const CloudTruthScore behind = truth->scoreCloud(pushed_back, truth_disparity, 0.2, 5.0);
  EXPECT_NEAR(behind.off_farther_fraction, 0.75 / 3.0, 0.01);
  EXPECT_EQ(behind.off_nearer_fraction, 0.0);
  // A point a pixel beside a surface edge is on it: the last sky row next to the surface.
  cv::Mat one_point(size, CV_32F, cv::Scalar(kInvalidDisparity));
  one_point.at<float>(size.height / 4 - 1, size.width / 4) = 40.0f;
  const CloudTruthScore rim = truth->scoreCloud(one_point, truth_disparity, 0.2, 5.0);
  ASSERT_EQ(rim.points, 1U);
  EXPECT_EQ(rim.off_surface_fraction, 0.0);
  EXPECT_EQ(rim.on_sky_fraction, 0.0);
  one_point.at<float>(size.height / 4 - 1, size.width / 4) = kInvalidDisparity;
  one_point.at<float>(size.height / 4 - 3, size.width / 4) = 40.0f;  // three rows into the sky
  EXPECT_EQ(truth->scoreCloud(one_point, truth_disparity, 0.2, 5.0).on_sky_fraction, 1.0);
  // A tolerance wider than the band's error takes it back onto the surface.
  EXPECT_NEAR(truth->scoreCloud(measured, truth_disparity, 0.2, 5.0, 1.0).off_surface_fraction,
              0.25, 0.01);
}

}  // namespace
}  // namespace fieldrig::stereo
