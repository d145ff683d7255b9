// Calibration of one head on OpenCV's own sample set (13 pairs, 9×6, 25 mm) against the figures
// OpenCV's stereo_calib sample reaches on it, and the head-to-head transform recovered from
// boards projected through two known heads.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "fieldrig/stereo/calibrate.h"

namespace fieldrig::stereo {
namespace {

const std::string kCalibDir = std::string(FIELDRIG_SHARED_DATA_DIR) + "/stereo/opencv_calib/";

std::vector<PairCorners> samplePairs(const BoardSpec& board, cv::Size& size) {
  std::vector<PairCorners> pairs;
  for (int i : {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14}) {
    // append, not "0" + std::string: GCC 12 -O3 gives a false-positive -Wrestrict.
    const std::string number = std::string(i < 10 ? "0" : "").append(std::to_string(i));
    PairCorners pair;
    pair.name = number;
    const cv::Mat left = cv::imread(kCalibDir + "left" + number + ".jpg", cv::IMREAD_GRAYSCALE);
    const cv::Mat right = cv::imread(kCalibDir + "right" + number + ".jpg", cv::IMREAD_GRAYSCALE);
    size = left.size();
    if (auto corners = findBoardCorners(left, board))
      pair.left = *corners;
    if (auto corners = findBoardCorners(right, board))
      pair.right = *corners;
    pairs.push_back(pair);
  }
  return pairs;
}

TEST(StereoCalibrate, OpenCvSampleSetAtLeastAsGoodAsStereoCalibSample) {
  const BoardSpec board{{9, 6}, 0.025};
  cv::Size size;
  const std::vector<PairCorners> pairs = samplePairs(board, size);
  int found = 0;
  for (const PairCorners& pair : pairs)
    found += pair.found() ? 1 : 0;
  EXPECT_EQ(found, 13);
  auto report = calibrateHead(pairs, board, size);
  ASSERT_TRUE(report) << report.error().message;
  // OpenCV's stereo_calib sample on this set (shared/data/stereo/README): RMS 0.634, epipolar
  // error 0.445 px.
  EXPECT_LE(report->rms, 0.634);
  EXPECT_LE(report->epipolar_error_px, 0.445);
  EXPECT_GE(report->pairs_used, 10);
  // The baseline is 3.343 squares of 25 mm in the reference run.
  EXPECT_NEAR(report->calibration.baseline(), 3.343 * 0.025, 0.002);
  // Single-camera calibration of the left images: fx ≈ 536 (left_intrinsics.yml: 535.9).
  EXPECT_NEAR(report->calibration.M1.at<double>(0, 0), 536.0, 6.0);
  EXPECT_EQ(report->calibration.image_size, size);
  // With every view kept, the fit cannot be better than with the outliers dropped.
  CalibrateOptions keep_all;
  keep_all.drop_factor = 0;
  auto all = calibrateHead(pairs, board, size, keep_all);
  ASSERT_TRUE(all);
  EXPECT_EQ(all->pairs_used, 13);
  EXPECT_GE(all->rms + 1e-9, report->rms);
  std::printf("calibration: rms %.4f epipolar %.4f px pairs %d (all 13: rms %.4f epipolar %.4f)\n",
              report->rms, report->epipolar_error_px, report->pairs_used, all->rms,
              all->epipolar_error_px);
}

TEST(StereoCalibrate, TooFewBoardsIsAnError) {
  const BoardSpec board{{9, 6}, 0.025};
  std::vector<PairCorners> pairs(5);  // no corners anywhere
  auto report = calibrateHead(pairs, board, cv::Size(640, 480));
  ASSERT_FALSE(report);
  EXPECT_NE(report.error().message.find("found in both images of 0 pairs"), std::string::npos);
}

// The same views with a square given 100 times too small: the fit is as good, but its 0.8 mm
// baseline is one that loadStereoCalibration refuses. It is refused here, naming the field, so
// that `fieldrig calibrate` never writes a calibration a later command trips over.
TEST(StereoCalibrate, ACalibrationTheLoaderWouldRefuseIsAnError) {
  const BoardSpec board{{9, 6}, 0.00025};
  cv::Size size;
  const std::vector<PairCorners> pairs = samplePairs(board, size);
  auto report = calibrateHead(pairs, board, size);
  ASSERT_FALSE(report) << "accepted a baseline of " << report->calibration.baseline() << " m";
  EXPECT_NE(report.error().message.find("not usable: field 'T'"), std::string::npos)
      << report.error().message;
}

// A synthetic head: ideal pinhole cameras 0.12 m apart, rectified by stereoRectify.
StereoCalibration syntheticHead(double f, cv::Size size, const cv::Mat& D) {
  StereoCalibration c;
  c.image_size = size;
  c.M1 = (cv::Mat_<double>(3, 3) << f, 0, size.width / 2.0, 0, f, size.height / 2.0, 0, 0, 1);
  c.M2 = c.M1.clone();
  c.D1 = D.clone();
  c.D2 = D.clone();
  c.R = cv::Mat::eye(3, 3, CV_64F);
  c.T = (cv::Mat_<double>(3, 1) << -0.12, 0, 0);
  cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                    cv::CALIB_ZERO_DISPARITY, 0);
  return c;
}

TEST(StereoCalibrate, HeadToHeadRecoversKnownTransform) {
  const BoardSpec board{{9, 6}, 0.05};
  const cv::Size size(1624, 1224);
  const cv::Mat distortion = (cv::Mat_<double>(1, 5) << -0.1, 0.05, 0, 0, 0);
  StereoCalibration bottom = syntheticHead(1350, size, distortion);
  StereoCalibration middle = syntheticHead(1340, size, distortion);
  // The middle head's left camera: 0.45 m above the bottom one, tilted down 10° about x.
  const cv::Vec3d tilt(10.0 * CV_PI / 180.0, 0, 0);
  cv::Mat R_mid_from_bottom;
  cv::Rodrigues(tilt, R_mid_from_bottom);
  const cv::Mat centre_in_bottom = (cv::Mat_<double>(3, 1) << 0.02, -0.45, 0.0);
  const cv::Mat t_mid_from_bottom = -R_mid_from_bottom * centre_in_bottom;

  const std::vector<cv::Point3f> object = boardPoints(board);
  std::vector<std::vector<cv::Point2f>> corners_bottom, corners_middle;
  cv::RNG rng(7);
  for (int view = 0; view < 8; ++view) {
    // Board poses between the two heads, 1.0–1.4 m away, turned a little each view.
    cv::Mat rvec = (cv::Mat_<double>(3, 1) << rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3),
                    rng.uniform(-0.2, 0.2));
    cv::Mat tvec = (cv::Mat_<double>(3, 1) << rng.uniform(-0.3, 0.1), rng.uniform(-0.45, -0.05),
                    rng.uniform(1.0, 1.4));
    cv::Mat R_board;
    cv::Rodrigues(rvec, R_board);
    cv::Mat rvec_mid;
    cv::Rodrigues(R_mid_from_bottom * R_board, rvec_mid);
    cv::Mat tvec_mid = R_mid_from_bottom * tvec + t_mid_from_bottom;
    std::vector<cv::Point2f> in_bottom, in_middle;
    cv::projectPoints(object, rvec, tvec, bottom.M1, bottom.D1, in_bottom);
    cv::projectPoints(object, rvec_mid, tvec_mid, middle.M1, middle.D1, in_middle);
    // Corner detection noise of a few hundredths of a pixel.
    for (auto& p : in_bottom)
      p += cv::Point2f(rng.gaussian(0.05), rng.gaussian(0.05));
    for (auto& p : in_middle)
      p += cv::Point2f(rng.gaussian(0.05), rng.gaussian(0.05));
    corners_bottom.push_back(in_bottom);
    corners_middle.push_back(in_middle);
  }
  double rms = 0;
  auto transform = calibrateHeadToHead(bottom, middle, corners_bottom, corners_middle, board, &rms);
  ASSERT_TRUE(transform) << transform.error().message;
  EXPECT_LT(rms, 0.2);
  // A point in the middle head's frame (its rectified left camera) maps to the bottom head's.
  cv::Mat p_mid_rect = (cv::Mat_<double>(3, 1) << 0.1, 0.2, 1.2);
  cv::Mat p_mid_camera = middle.R1.t() * p_mid_rect;
  cv::Mat p_bottom_camera = R_mid_from_bottom.t() * (p_mid_camera - t_mid_from_bottom);
  cv::Mat expected = bottom.R1 * p_bottom_camera;
  const cv::Vec4d got = *transform * cv::Vec4d(0.1, 0.2, 1.2, 1.0);
  EXPECT_NEAR(got[0], expected.at<double>(0), 0.002);
  EXPECT_NEAR(got[1], expected.at<double>(1), 0.002);
  EXPECT_NEAR(got[2], expected.at<double>(2), 0.002);
}

TEST(StereoCalibrate, HeadToHeadRejectsMismatchedViews) {
  StereoCalibration head = syntheticHead(1350, {1624, 1224}, cv::Mat::zeros(1, 5, CV_64F));
  std::vector<std::vector<cv::Point2f>> two(2), three(3);
  auto result = calibrateHeadToHead(head, head, two, three, BoardSpec{});
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("got 2 and 3"), std::string::npos);
}

}  // namespace
}  // namespace fieldrig::stereo
