// `fieldrig calibrate` and `fieldrig disparity` as the built binary: OpenCV's sample set to
// calibration files that load back and rectify its pairs, disparity PFM against Middlebury
// ground truth, and clear errors for unusable input.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/disparity_io.h"
#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig::stereo {
namespace {

using testing_support::readWholeFile;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;
using Json = nlohmann::json;
namespace fs = std::filesystem;

const std::string kData = std::string(FIELDRIG_SHARED_DATA_DIR) + "/stereo/";

TEST(StereoCli, CalibrateSampleSetThenDisparityWithIt) {
  ScopedTempDir dir("stereo_cli_calibrate");
  const auto calib = dir / "head";
  const auto run = runFieldrig({"calibrate", "--left", kData + "opencv_calib/left*.jpg", "--right",
                                kData + "opencv_calib/right*.jpg", "--board", "9x6", "--square",
                                "0.025", "--out", calib.string()},
                               dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1u);
  const Json out = Json::parse(run.out_lines[0]);
  // OpenCV's stereo_calib sample: RMS 0.634, epipolar 0.445 px on this set.
  EXPECT_LE(out["rms"].get<double>(), 0.634);
  EXPECT_LE(out["epipolar_error_px"].get<double>(), 0.445);
  EXPECT_EQ(out["pairs_given"], 13);
  EXPECT_EQ(out["views"].size(), 13u);
  int used = 0;
  for (const Json& view : out["views"]) {
    used += view["used"].get<bool>() ? 1 : 0;
    if (!view["used"].get<bool>()) {
      EXPECT_TRUE(view.contains("dropped"));
    }
  }
  EXPECT_EQ(out["pairs_used"], used);

  auto loaded = loadStereoCalibration(calib);
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->image_size, cv::Size(640, 480));
  EXPECT_NEAR(loaded->baseline(), out["baseline_m"].get<double>(), 1e-9);

  const auto pfm = dir / "d.pfm";
  const auto disparity = runFieldrig(
      {"disparity", "--left", kData + "opencv_calib/left01.jpg", "--right",
       kData + "opencv_calib/right01.jpg", "--intrinsics", (calib / "intrinsics.yml").string(),
       "--extrinsics", (calib / "extrinsics.yml").string(), "--out", pfm.string()},
      dir.path());
  ASSERT_EQ(disparity.exit_code, 0) << disparity.err;
  auto map = readPfm(pfm);
  ASSERT_TRUE(map) << map.error().message;
  EXPECT_EQ(map->size(), cv::Size(640, 480));
}

TEST(StereoCli, DisparityOfTeddyMatchesGroundTruth) {
  ScopedTempDir dir("stereo_cli_teddy");
  const auto pfm = dir / "teddy.pfm";
  const auto run = runFieldrig(
      {"disparity", "--left", kData + "middlebury2003/teddy/im2.png", "--right",
       kData + "middlebury2003/teddy/im6.png", "--num-disparities", "64", "--out", pfm.string()},
      dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  auto map = readPfm(pfm);
  ASSERT_TRUE(map);
  cv::Mat truth;
  cv::imread(kData + "middlebury2003/teddy/disp2.pgm", cv::IMREAD_GRAYSCALE)
      .convertTo(truth, CV_32F, 0.25);
  const DisparityScores scores = scoreDisparity(*map, truth);
  // The library reaches 8.6 % on Teddy (stereo_accuracy_test); the CLI must give the same map.
  EXPECT_LT(scores.bad1_valid, 0.09);
  EXPECT_GT(scores.valid_fraction, 0.78);
  EXPECT_NEAR(Json::parse(run.out_lines.at(0))["valid_fraction"].get<double>(),
              static_cast<double>(cv::countNonZero(*map >= 0)) / static_cast<double>(map->total()),
              1e-9);

  // The flag reaches the matcher: growing from a second matching leaves more pixels matched.
  const auto grown =
      runFieldrig({"disparity", "--left", kData + "middlebury2003/teddy/im2.png", "--right",
                   kData + "middlebury2003/teddy/im6.png", "--num-disparities", "64",
                   "--grow-uniqueness-ratio", "0", "--out", (dir / "grown.pfm").string()},
                  dir.path());
  ASSERT_EQ(grown.exit_code, 0) << grown.err;
  EXPECT_GT(Json::parse(grown.out_lines.at(0))["valid_fraction"].get<double>(),
            Json::parse(run.out_lines.at(0))["valid_fraction"].get<double>());
}

TEST(StereoCli, BadInputIsAClearError) {
  ScopedTempDir dir("stereo_cli_bad");
  const std::string teddy_left = kData + "middlebury2003/teddy/im2.png";
  const std::string calib_left = kData + "opencv_calib/left01.jpg";
  const std::string calib_right = kData + "opencv_calib/right01.jpg";

  auto sizes = runFieldrig({"disparity", "--left", teddy_left, "--right", calib_right, "--out",
                            (dir / "x.pfm").string()},
                           dir.path());
  EXPECT_EQ(sizes.exit_code, 2);
  EXPECT_NE(sizes.err.find(calib_right + ": image is 640x480 but the left image is 450x375"),
            std::string::npos)
      << sizes.err;

  // The sample's own (old) calibration has no image size; ours does: write one, then use it on
  // images of another size.
  auto calibrated =
      runFieldrig({"calibrate", "--left", kData + "opencv_calib/left0*.jpg", "--right",
                   kData + "opencv_calib/right0*.jpg", "--out", (dir / "head").string()},
                  dir.path());
  ASSERT_EQ(calibrated.exit_code, 0) << calibrated.err;
  auto mismatched = runFieldrig(
      {"disparity", "--left", teddy_left, "--right", kData + "middlebury2003/teddy/im6.png",
       "--intrinsics", (dir / "head" / "intrinsics.yml").string(), "--extrinsics",
       (dir / "head" / "extrinsics.yml").string(), "--out", (dir / "x.pfm").string()},
      dir.path());
  EXPECT_EQ(mismatched.exit_code, 2);
  EXPECT_NE(
      mismatched.err.find("calibration is for 640x480 images but " + teddy_left + " is 450x375"),
      std::string::npos)
      << mismatched.err;

  // --out naming an input would overwrite that image with the PFM.
  const fs::path own_left = dir / "left.png";
  fs::copy_file(teddy_left, own_left);
  const std::string left_before = readWholeFile(own_left);
  auto onto_input =
      runFieldrig({"disparity", "--left", own_left.string(), "--right",
                   kData + "middlebury2003/teddy/im6.png", "--out", own_left.string()},
                  dir.path());
  EXPECT_EQ(onto_input.exit_code, 2);
  EXPECT_NE(
      onto_input.err.find("--out " + own_left.string() + " is the input " + own_left.string()),
      std::string::npos)
      << onto_input.err;
  EXPECT_EQ(readWholeFile(own_left), left_before);

  auto missing = runFieldrig({"disparity", "--left", (dir / "absent.png").string(), "--right",
                              calib_right, "--out", (dir / "x.pfm").string()},
                             dir.path());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("absent.png: cannot read the image"), std::string::npos);

  auto no_extrinsics =
      runFieldrig({"disparity", "--left", calib_left, "--right", calib_right, "--intrinsics",
                   (dir / "head" / "intrinsics.yml").string(), "--extrinsics",
                   (dir / "head" / "absent.yml").string(), "--out", (dir / "x.pfm").string()},
                  dir.path());
  EXPECT_EQ(no_extrinsics.exit_code, 2);
  EXPECT_NE(no_extrinsics.err.find("absent.yml: cannot open"), std::string::npos)
      << no_extrinsics.err;

  auto unpaired = runFieldrig({"calibrate", "--left", kData + "opencv_calib/left*.jpg", "--right",
                               kData + "opencv_calib/right0*.jpg", "--out", (dir / "h2").string()},
                              dir.path());
  EXPECT_EQ(unpaired.exit_code, 2);
  EXPECT_NE(unpaired.err.find("--left matches 13 files but --right matches 9"), std::string::npos)
      << unpaired.err;

  auto no_board = runFieldrig(
      {"calibrate", "--left", teddy_left, "--right", teddy_left, "--out", (dir / "h3").string()},
      dir.path());
  EXPECT_EQ(no_board.exit_code, 2);
  EXPECT_NE(no_board.err.find("found in both images of 0 pairs"), std::string::npos)
      << no_board.err;

  auto bad_board = runFieldrig({"calibrate", "--left", calib_left, "--right", calib_right,
                                "--board", "9by6", "--out", (dir / "h4").string()},
                               dir.path());
  EXPECT_EQ(bad_board.exit_code, 2);
  EXPECT_NE(bad_board.err.find("--board '9by6' is not COLSxROWS"), std::string::npos);
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

// A calibration that loaded before and made `disparity` match garbage: now refused, naming the
// file and the field. Out-of-range matcher options name the flag and its range (before: a
// cv::Exception abort for --num-disparities 100000, hours of matching for --block-size 9999).
TEST(StereoCli, UnusableCalibrationAndOptionsNameTheCulprit) {
  ScopedTempDir dir("stereo_cli_unusable");
  const std::string left = kData + "opencv_calib/left01.jpg";
  const std::string right = kData + "opencv_calib/right01.jpg";
  const auto disparityWith = [&](const StereoCalibration& calibration,
                                 std::vector<std::string> extra = {}) {
    EXPECT_TRUE(saveStereoCalibration(calibration, dir.path()));
    std::vector<std::string> args{"disparity",
                                  "--left",
                                  left,
                                  "--right",
                                  right,
                                  "--intrinsics",
                                  (dir / "intrinsics.yml").string(),
                                  "--extrinsics",
                                  (dir / "extrinsics.yml").string(),
                                  "--out",
                                  (dir / "d.pfm").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return runFieldrig(args, dir.path());
  };
  const StereoCalibration good = idealStereoCalibration(530, cv::Size(640, 480), 0.08);
  ASSERT_EQ(disparityWith(good).exit_code, 0);

  StereoCalibration zero_camera = deepCopy(good);
  zero_camera.M1 = cv::Mat::zeros(3, 3, CV_64F);
  const auto singular = disparityWith(zero_camera);
  EXPECT_EQ(singular.exit_code, 2);
  EXPECT_NE(singular.err.find((dir / "intrinsics.yml").string() +
                              ": field 'M1': singular camera matrix (fx = 0)"),
            std::string::npos)
      << singular.err;

  StereoCalibration zero_rotation = deepCopy(good);
  zero_rotation.R1 = cv::Mat::zeros(3, 3, CV_64F);
  const auto not_rotation = disparityWith(zero_rotation);
  EXPECT_EQ(not_rotation.exit_code, 2);
  EXPECT_NE(not_rotation.err.find((dir / "extrinsics.yml").string() +
                                  ": field 'R1': not a rotation: not orthonormal"),
            std::string::npos)
      << not_rotation.err;

  StereoCalibration in_millimetres = deepCopy(good);
  in_millimetres.T *= 1000;
  const auto millimetres = disparityWith(in_millimetres);
  EXPECT_EQ(millimetres.exit_code, 2);
  EXPECT_NE(millimetres.err.find((dir / "extrinsics.yml").string() +
                                 ": field 'T': baseline 80 m is implausible"),
            std::string::npos)
      << millimetres.err;

  const std::pair<std::vector<std::string>, std::string> options[] = {
      {{"--num-disparities", "100000"},
       "--num-disparities 100000 is outside the allowed range [16, 1024] (a multiple of 16)"},
      {{"--num-disparities", "0"},
       "--num-disparities 0 is outside the allowed range [16, 1024] (a multiple of 16)"},
      {{"--block-size", "9999"}, "--block-size 9999 is outside the allowed range [1, 31] (odd)"},
      {{"--block-size", "4"}, "--block-size 4 is outside the allowed range [1, 31] (odd)"},
      {{"--grow-uniqueness-ratio", "-2"},
       "--grow-uniqueness-ratio -2 is outside the allowed range [-1, 100] (-1 disables it)"},
      // 640-pixel-wide images: SGBM aborted on an empty buffer.
      {{"--num-disparities", "640"},
       "--num-disparities 640 leaves no column of the 640-pixel-wide images to match: at most 624"},
  };
  for (const auto& [extra, message] : options) {
    const auto run = disparityWith(good, extra);
    EXPECT_EQ(run.exit_code, 2) << extra[0] << " " << extra[1];
    EXPECT_EQ(run.err, "fieldrig disparity: " + message + "\n");
  }
}

// Ideal pinhole head (1624×1224, f = `focal`, 0.12 m), rectified by stereoRectify.
StereoCalibration idealHead(double focal) {
  StereoCalibration c;
  c.image_size = cv::Size(1624, 1224);
  c.M1 = (cv::Mat_<double>(3, 3) << focal, 0, 811.5, 0, focal, 611.5, 0, 0, 1);
  c.M2 = c.M1.clone();
  c.D1 = cv::Mat::zeros(1, 5, CV_64F);
  c.D2 = c.D1.clone();
  c.R = cv::Mat::eye(3, 3, CV_64F);
  c.T = (cv::Mat_<double>(3, 1) << -0.12, 0, 0);
  cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, c.image_size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                    cv::CALIB_ZERO_DISPARITY, 0);
  return c;
}

// A 9×6-inner-corner board (10×7 squares of `square` m, white margin) seen by camera M with
// pose (rvec, tvec), drawn square by square from projected corners.
cv::Mat renderBoard(const cv::Mat& M, const cv::Mat& rvec, const cv::Mat& tvec, double square) {
  cv::Mat image(1224, 1624, CV_8UC1, cv::Scalar(90));
  auto project = [&](const std::vector<cv::Point3f>& points) {
    std::vector<cv::Point2f> pixels;
    cv::projectPoints(points, rvec, tvec, M, cv::noArray(), pixels);
    std::vector<cv::Point> out;
    for (const auto& p : pixels)
      out.emplace_back(cvRound(p.x * 16), cvRound(p.y * 16));
    return out;
  };
  const auto s = static_cast<float>(square);
  // Inner corner (0, 0) is at board (0, 0): squares span [-1, 9] × [-1, 6] squares.
  cv::fillConvexPoly(
      image,
      project({{-2 * s, -2 * s, 0}, {10 * s, -2 * s, 0}, {10 * s, 7 * s, 0}, {-2 * s, 7 * s, 0}}),
      cv::Scalar(235), cv::LINE_AA, 4);
  for (int row = -1; row < 6; ++row) {
    for (int col = -1; col < 9; ++col) {
      if ((row + col) % 2 != 0)
        continue;
      const float x = static_cast<float>(col) * s, y = static_cast<float>(row) * s;
      cv::fillConvexPoly(image,
                         project({{x, y, 0}, {x + s, y, 0}, {x + s, y + s, 0}, {x, y + s, 0}}),
                         cv::Scalar(20), cv::LINE_AA, 4);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

TEST(StereoCli, HeadPairFromBoardsSeenByTwoHeads) {
  ScopedTempDir dir("stereo_cli_head_pair");
  const StereoCalibration bottom = idealHead(1350);
  const StereoCalibration middle = idealHead(1340);
  ASSERT_TRUE(saveStereoCalibration(bottom, dir / "bottom"));
  ASSERT_TRUE(saveStereoCalibration(middle, dir / "middle"));
  // Middle head's left camera 0.45 m above the bottom one, tilted down 12°.
  cv::Mat R_mid;
  cv::Rodrigues(cv::Vec3d(12.0 * CV_PI / 180.0, 0, 0), R_mid);
  const cv::Mat centre = (cv::Mat_<double>(3, 1) << 0.0, -0.45, 0.0);
  const cv::Mat t_mid = -R_mid * centre;
  const double square = 0.04;
  cv::RNG rng(3);
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "b");
  for (int view = 0; view < 6; ++view) {
    const cv::Mat rvec = (cv::Mat_<double>(3, 1) << rng.uniform(-0.25, 0.25),
                          rng.uniform(-0.25, 0.25), rng.uniform(-0.1, 0.1));
    const cv::Mat tvec = (cv::Mat_<double>(3, 1) << rng.uniform(-0.25, 0.0),
                          rng.uniform(-0.35, -0.15), rng.uniform(1.1, 1.4));
    cv::Mat R_board;
    cv::Rodrigues(rvec, R_board);
    cv::Mat rvec_mid;
    cv::Rodrigues(R_mid * R_board, rvec_mid);
    const cv::Mat tvec_mid = R_mid * tvec + t_mid;
    const std::string name = "view" + std::to_string(view) + ".png";
    ASSERT_TRUE(
        cv::imwrite((dir / "a" / name).string(), renderBoard(bottom.M1, rvec, tvec, square)));
    ASSERT_TRUE(cv::imwrite((dir / "b" / name).string(),
                            renderBoard(middle.M1, rvec_mid, tvec_mid, square)));
  }
  const auto run = runFieldrig(
      {"calibrate", "--head-pair", "--left", (dir / "a" / "view*.png").string(), "--right",
       (dir / "b" / "view*.png").string(), "--calib-a", (dir / "bottom").string(), "--calib-b",
       (dir / "middle").string(), "--board", "9x6", "--square", std::to_string(square), "--out",
       (dir / "b_to_a.yml").string()},
      dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json out = Json::parse(run.out_lines.at(0));
  EXPECT_EQ(out["pairs_used"], 6);
  EXPECT_LT(out["rms"].get<double>(), 0.5);
  // Head frames are the rectified left cameras; with these ideal heads R1 = I, so b_to_a maps
  // a middle-head point p to R_mid^T (p - t_mid).
  const cv::Mat p = (cv::Mat_<double>(3, 1) << 0.1, 0.1, 1.2);
  const cv::Mat expected = bottom.R1 * (R_mid.t() * (middle.R1.t() * p - t_mid));
  const Json& m = out["b_to_a"];
  for (int r = 0; r < 3; ++r) {
    const double got = m[r][0].get<double>() * 0.1 + m[r][1].get<double>() * 0.1 +
                       m[r][2].get<double>() * 1.2 + m[r][3].get<double>();
    EXPECT_NEAR(got, expected.at<double>(r), 0.003) << "row " << r;
  }
  cv::FileStorage written((dir / "b_to_a.yml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(written.isOpened());
  cv::Mat stored;
  written["b_to_a"] >> stored;
  EXPECT_EQ(stored.size(), cv::Size(4, 4));
}

}  // namespace
}  // namespace fieldrig::stereo
