// `fieldrig stem`: the command contract, run as the built binary on a rendered pair written as
// image files with its calibration (OpenCV stereo_calib layout).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>

#include "support/cli_run.h"
#include "support/stem_campaign.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

using testing_support::CliRun;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;

class StemCli : public ::testing::Test {
 protected:
  void SetUp() override {
    c_ = testing_support::makeStemCases({18}, {1.2}, 21).front();
    c_.geometry.distorted = true;
    c_.geometry.right_rotation = cv::Vec3d(0.002, -0.008, 0.001);
    const sim::RenderedStereoPair pair = sim::renderCylinderPair(c_.geometry, c_.scene);
    ASSERT_TRUE(cv::imwrite((dir_ / "left.png").string(), pair.left));
    ASSERT_TRUE(cv::imwrite((dir_ / "right.png").string(), pair.right));
    ASSERT_TRUE(stereo::saveStereoCalibration(pair.calibration, dir_.path()).ok());
    std::mt19937_64 rng(4);
    const stem::Points4 clicks = testing_support::jitteredClicks(c_, 0.7, rng);
    std::ostringstream text;
    text.precision(10);
    for (std::size_t i = 0; i < 4; ++i)
      text << (i ? "," : "") << clicks[i].x << "," << clicks[i].y;
    points_ = text.str();
  }

  std::vector<std::string> args(const std::string& points) const {
    return {"stem",
            "--left",
            (dir_ / "left.png").string(),
            "--right",
            (dir_ / "right.png").string(),
            "--intrinsics",
            (dir_ / "intrinsics.yml").string(),
            "--extrinsics",
            (dir_ / "extrinsics.yml").string(),
            "--points",
            points,
            "--json"};
  }

  ScopedTempDir dir_{"stem_cli"};
  testing_support::StemCase c_;
  std::string points_;
};

TEST_F(StemCli, PrintsTheDiameterDisparityAndNccAsOneJsonObject) {
  const CliRun run = runFieldrig(args(points_), dir_.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1u);
  const auto json = nlohmann::json::parse(run.out_lines[0]);
  EXPECT_EQ(json["status"], "ok");
  EXPECT_NEAR(json["diameter_mm"].get<double>(), 18.0, 0.5);
  // Disparity of a surface 1.2 m away with f·b = 1350 px · 0.12 m, near side of the stem.
  EXPECT_NEAR(json["disparity_px"].get<double>(), 1350.0 * 0.12 / 1.2, 2.0);
  EXPECT_GT(json["ncc"].get<double>(), 0.9);
  EXPECT_TRUE(json["edges_refined"].get<bool>());
  EXPECT_EQ(json["right_patch_raw"].size(), 4u);
}

TEST_F(StemCli, BadInputIsRefusedWithExitCode2AndAMessage) {
  const CliRun six = runFieldrig(args("1,2,3,4,5,6"), dir_.path());
  EXPECT_EQ(six.exit_code, 2);
  EXPECT_NE(six.err.find("--points"), std::string::npos) << six.err;
  const CliRun word = runFieldrig(args("1,2,3,4,5,6,7,x"), dir_.path());
  EXPECT_EQ(word.exit_code, 2);
  EXPECT_NE(word.err.find("'x' is not a number"), std::string::npos) << word.err;
  const CliRun crossed = runFieldrig(args("800,500,800,600,830,550,805,550"), dir_.path());
  EXPECT_EQ(crossed.exit_code, 2);
  EXPECT_NE(crossed.err.find("convex"), std::string::npos) << crossed.err;
  std::vector<std::string> missing = args(points_);
  missing[2] = (dir_ / "absent.png").string();
  const CliRun absent = runFieldrig(missing, dir_.path());
  EXPECT_EQ(absent.exit_code, 2);
  EXPECT_NE(absent.err.find("absent.png"), std::string::npos) << absent.err;
  std::vector<std::string> bad_calibration = args(points_);
  bad_calibration[6] = (dir_ / "left.png").string();
  const CliRun calibration = runFieldrig(bad_calibration, dir_.path());
  EXPECT_EQ(calibration.exit_code, 2);
  EXPECT_FALSE(calibration.err.empty());
}

// A copy with its own pixels: cv::Mat copies share them, and assigning a matrix expression to a
// shared Mat writes into the original too.
stereo::StereoCalibration deepCopy(const stereo::StereoCalibration& c) {
  stereo::StereoCalibration out = c;
  for (cv::Mat* m : {&out.M1, &out.D1, &out.M2, &out.D2, &out.R, &out.T, &out.R1, &out.R2, &out.P1,
                     &out.P2, &out.Q})
    *m = m->clone();
  return out;
}

// A singular calibration used to load and the measurement then blamed the clicks; now the file
// and the field are named before any image is read.
TEST_F(StemCli, AnUnusableCalibrationIsNamedNotTheClicks) {
  auto calibration = stereo::loadStereoCalibration(dir_.path());
  ASSERT_TRUE(calibration) << calibration.error().message;
  stereo::StereoCalibration zero_camera = deepCopy(*calibration);
  zero_camera.M2 = cv::Mat::zeros(3, 3, CV_64F);
  ASSERT_TRUE(stereo::saveStereoCalibration(zero_camera, dir_.path()));
  const CliRun singular = runFieldrig(args(points_), dir_.path());
  EXPECT_EQ(singular.exit_code, 2);
  EXPECT_NE(singular.err.find((dir_ / "intrinsics.yml").string() +
                              ": field 'M2': singular camera matrix (fx = 0)"),
            std::string::npos)
      << singular.err;

  stereo::StereoCalibration zero_rotation = deepCopy(*calibration);
  zero_rotation.R = cv::Mat::zeros(3, 3, CV_64F);
  ASSERT_TRUE(stereo::saveStereoCalibration(zero_rotation, dir_.path()));
  const CliRun not_rotation = runFieldrig(args(points_), dir_.path());
  EXPECT_EQ(not_rotation.exit_code, 2);
  EXPECT_NE(not_rotation.err.find((dir_ / "extrinsics.yml").string() +
                                  ": field 'R': not a rotation: not orthonormal"),
            std::string::npos)
      << not_rotation.err;
}

TEST_F(StemCli, AWeakMatchExitsWith3AndSaysSo) {
  cv::Mat noise(1224, 1624, CV_8UC1);
  cv::RNG(5).fill(noise, cv::RNG::UNIFORM, 0, 256);
  ASSERT_TRUE(cv::imwrite((dir_ / "right.png").string(), noise));
  const CliRun run = runFieldrig(args(points_), dir_.path());
  EXPECT_EQ(run.exit_code, 3) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1u);
  const auto json = nlohmann::json::parse(run.out_lines[0]);
  EXPECT_EQ(json["status"], "weak_match");
  EXPECT_TRUE(json["diameter_mm"].is_null());
  EXPECT_NE(run.err.find("NCC"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace fieldrig
