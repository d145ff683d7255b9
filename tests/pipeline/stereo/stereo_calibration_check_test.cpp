// Calibrations are checked when loaded: each kind of unusable value (singular or implausible camera
// matrix, non-rotation, zero or implausible baseline, broken projections, bad image size) is
// refused with the file and the field named; what OpenCV's tools and ours write still loads.
// The matcher options' ranges, shared by the configuration, the cloud options and the CLI.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/head.h"
#include "fieldrig/stereo/matcher.h"
#include "fieldrig/stereo/pair_disparity.h"
#include "support/temp_dir.h"

namespace fieldrig::stereo {
namespace {

using testing_support::ScopedTempDir;

StereoCalibration goodCalibration() {
  return idealStereoCalibration(1350.0, cv::Size(1624, 1224), 0.12);
}

// Saves `calibration` changed by `change` and loads it back.
core::Result<StereoCalibration> saveChangedAndLoad(
    const ScopedTempDir& dir, const std::function<void(StereoCalibration&)>& change) {
  StereoCalibration calibration = goodCalibration();
  change(calibration);
  EXPECT_TRUE(saveStereoCalibration(calibration, dir.path()));
  return loadStereoCalibration(dir.path());
}

// The load fails with "FILE: field 'FIELD': …" where FILE is intrinsics.yml or extrinsics.yml.
void expectRefused(const core::Result<StereoCalibration>& loaded, const ScopedTempDir& dir,
                   const std::string& file, const std::string& field, const std::string& what) {
  ASSERT_FALSE(loaded) << "accepted; expected " << field << ": " << what;
  const std::string prefix = (dir.path() / file).string() + ": field '" + field + "'";
  EXPECT_EQ(loaded.error().message.rfind(prefix, 0), 0u) << loaded.error().message;
  EXPECT_NE(loaded.error().message.find(what), std::string::npos) << loaded.error().message;
}

TEST(CalibrationCheck, WhatTheLibraryWritesLoads) {
  ScopedTempDir dir("calib_check_good");
  auto loaded = saveChangedAndLoad(dir, [](StereoCalibration&) {});
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_TRUE(checkIntrinsics(*loaded));
  EXPECT_TRUE(checkExtrinsics(*loaded));
  // Scaled to the matching resolution it is still plausible.
  EXPECT_TRUE(checkIntrinsics(loaded->scaled(0.5)));
  EXPECT_TRUE(checkExtrinsics(loaded->scaled(0.5)));
}

TEST(CalibrationCheck, OpenCvsShippedIntrinsicsLoad) {
  // OpenCV's stereo_calib output for its sample set: no image size, principal point ~(335, 241).
  ScopedTempDir dir("calib_check_opencv");
  ASSERT_TRUE(saveStereoCalibration(goodCalibration(), dir.path()));
  auto loaded = loadStereoCalibration(
      std::string(FIELDRIG_SHARED_DATA_DIR) + "/stereo/opencv_calib/intrinsics.yml",
      dir / "extrinsics.yml");
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_TRUE(loaded->image_size.empty());
}

// What cv::FileStorage did with damaged files, before the loaders checked them first: a declared
// size was allocated before its data was read (16 GiB for "cols: 2147483647"), control bytes could
// hang open(), std::length_error and cv::Exception escaped.
TEST(CalibrationCheck, DamagedFilesAreRefusedBeforeOpenCvTrustsThem) {
  ScopedTempDir dir("calib_check_damaged");
  ASSERT_TRUE(saveStereoCalibration(goodCalibration(), dir.path()));
  const auto withIntrinsics = [&](const std::string& text) {
    std::ofstream(dir / "intrinsics.yml", std::ios::binary | std::ios::trunc) << text;
    return loadStereoCalibration(dir.path());
  };
  const std::string file = (dir / "intrinsics.yml").string();
  const auto expectMessage = [&](const core::Result<StereoCalibration>& loaded,
                                 const std::string& what) {
    ASSERT_FALSE(loaded) << "accepted; expected " << what;
    EXPECT_EQ(loaded.error().message.rfind(file + ":", 0), 0u) << loaded.error().message;
    EXPECT_NE(loaded.error().message.find(what), std::string::npos) << loaded.error().message;
  };
  const std::string huge =
      "%YAML:1.0\nM1: !!opencv-matrix\n  rows: 2147483647\n  cols: 2147483647\n  dt: d\n"
      "  data: [ 1 ]\n";
  expectMessage(withIntrinsics(huge), "field 'M1' is not a matrix of 1 to 16 rows and columns");
  expectMessage(withIntrinsics("%YAML:1.0\nM1: !!opencv-nd-matrix\n  sizes: [ 3, 3, 3 ]\n"
                               "  dt: d\n  data: [ 1 ]\n"),
                "field 'M1' is not a matrix (rows, cols, dt, data)");
  expectMessage(withIntrinsics("%YAML:1.0\nM1: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
                               "  data: [ 1, 0, 0 ]\n"),
                "field 'M1' does not hold its 3x3 values");
  expectMessage(withIntrinsics(std::string("---  dt: d\n d\x05\0\0x\n", 18)),
                ":2: control character 0x05");
  expectMessage(withIntrinsics("%YAML:1.0\n- x\n- y\n"), "not a map of fields");
  expectMessage(withIntrinsics("- x\n- y\n"), "not a map of fields");
  expectMessage(withIntrinsics("%YAML:1.0\n:1.0\n"), "not a map of fields");
  // Both made cv::FileStorage::open loop for ever (found by the calibration_yaml fuzzer).
  expectMessage(withIntrinsics("%YAML:1.0\n---e:as\nhd\n   - b\n"), "not a map of fields");
  expectMessage(withIntrinsics("%YAML:1.0\n---e:as\nhd\n   - b\ntom: !!ormat: B\n"),
                "intrinsics.yml:5: not readable as YAML (illegal map value)");
  expectMessage(withIntrinsics(std::string(kMaxCalibrationFileBytes + 1, ' ')),
                "more than a calibration file holds");
}

// OpenCV's own sample calibrations have no image size: saved again they leave the keys out
// rather than write 0, which the loader refuses.
TEST(CalibrationCheck, ACalibrationWithoutImageSizeRoundTrips) {
  ScopedTempDir dir("calib_check_no_size");
  StereoCalibration calibration = goodCalibration();
  calibration.image_size = cv::Size();
  ASSERT_TRUE(saveStereoCalibration(calibration, dir.path()));
  const auto loaded = loadStereoCalibration(dir.path());
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_TRUE(loaded->image_size.empty());
  EXPECT_EQ(cv::norm(loaded->M1, calibration.M1), 0.0);
}

TEST(CalibrationCheck, SingularCameraMatrix) {
  ScopedTempDir dir("calib_check_zero_m1");
  expectRefused(
      saveChangedAndLoad(dir, [](StereoCalibration& c) { c.M1 = cv::Mat::zeros(3, 3, CV_64F); }),
      dir, "intrinsics.yml", "M1", "singular camera matrix (fx = 0)");
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.M2.at<double>(1, 1) = 0; }),
                dir, "intrinsics.yml", "M2", "singular camera matrix (fy = 0)");
}

TEST(CalibrationCheck, NegativeFocalLength) {
  ScopedTempDir dir("calib_check_negative_f");
  expectRefused(
      saveChangedAndLoad(dir, [](StereoCalibration& c) { c.M2.at<double>(1, 1) = -1350; }), dir,
      "intrinsics.yml", "M2", "fy = -1350 is not a focal length");
}

TEST(CalibrationCheck, FocalAspectImplausible) {
  ScopedTempDir dir("calib_check_aspect");
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.M1.at<double>(1, 1) = 135; }),
                dir, "intrinsics.yml", "M1", "fx / fy = 1350 / 135 is implausible");
}

TEST(CalibrationCheck, PrincipalPointOutsideTheImage) {
  ScopedTempDir dir("calib_check_principal");
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.M1.at<double>(0, 2) = 8115; }),
                dir, "intrinsics.yml", "M1",
                "principal point (8115, 611.5) lies outside the 1624x1224");
  // Near the image (within 10 % of its size) is tolerated: decentred lenses exist.
  auto near = saveChangedAndLoad(dir, [](StereoCalibration& c) { c.M1.at<double>(1, 2) = 1300; });
  EXPECT_TRUE(near) << near.error().message;
}

TEST(CalibrationCheck, NotACameraMatrix) {
  ScopedTempDir dir("calib_check_bottom_row");
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.M1.at<double>(2, 2) = 0; }),
                dir, "intrinsics.yml", "M1", "is not a camera matrix [fx s cx; 0 fy cy; 0 0 1]");
}

TEST(CalibrationCheck, NonFiniteDistortion) {
  ScopedTempDir dir("calib_check_nan_d");
  expectRefused(saveChangedAndLoad(dir,
                                   [](StereoCalibration& c) {
                                     c.D2.at<double>(0, 1) =
                                         std::numeric_limits<double>::quiet_NaN();
                                   }),
                dir, "intrinsics.yml", "D2", "NaN or infinite");
}

TEST(CalibrationCheck, ZeroRotation) {
  ScopedTempDir dir("calib_check_zero_r");
  expectRefused(
      saveChangedAndLoad(dir, [](StereoCalibration& c) { c.R = cv::Mat::zeros(3, 3, CV_64F); }),
      dir, "extrinsics.yml", "R", "not orthonormal");
  expectRefused(
      saveChangedAndLoad(dir, [](StereoCalibration& c) { c.R1 = cv::Mat::zeros(3, 3, CV_64F); }),
      dir, "extrinsics.yml", "R1", "not orthonormal");
}

TEST(CalibrationCheck, ReflectionIsNotARotation) {
  ScopedTempDir dir("calib_check_reflection");
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.R2.row(2) *= -1; }), dir,
                "extrinsics.yml", "R2", "a reflection (det = -1)");
}

TEST(CalibrationCheck, RotationToleranceIs1e3) {
  ScopedTempDir dir("calib_check_rotation_tolerance");
  // A rotation copied with 4 significant digits stays within the tolerance ...
  auto rounded = saveChangedAndLoad(dir, [](StereoCalibration& c) {
    cv::Rodrigues(cv::Vec3d(0.0123, -0.0456, 0.0789), c.R);
    for (double& v : cv::Mat_<double>(c.R))
      v = std::round(v * 1e4) / 1e4;
  });
  EXPECT_TRUE(rounded) << rounded.error().message;
  // ... one element off by 1e-2 is not.
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.R.at<double>(0, 1) = 1e-2; }),
                dir, "extrinsics.yml", "R", "not orthonormal");
}

TEST(CalibrationCheck, ZeroBaseline) {
  ScopedTempDir dir("calib_check_zero_t");
  expectRefused(
      saveChangedAndLoad(dir, [](StereoCalibration& c) { c.T = cv::Mat::zeros(3, 1, CV_64F); }),
      dir, "extrinsics.yml", "T", "zero baseline");
}

TEST(CalibrationCheck, BaselineInMillimetresIsImplausible) {
  ScopedTempDir dir("calib_check_mm");
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.T *= 1000; }), dir,
                "extrinsics.yml", "T", "baseline 120 m is implausible");
}

TEST(CalibrationCheck, ZeroProjection) {
  ScopedTempDir dir("calib_check_zero_p");
  expectRefused(
      saveChangedAndLoad(dir, [](StereoCalibration& c) { c.P1 = cv::Mat::zeros(3, 4, CV_64F); }),
      dir, "extrinsics.yml", "P1", "rectified focal length (0, 0) is not positive");
}

TEST(CalibrationCheck, SingularOrForeignQ) {
  ScopedTempDir dir("calib_check_q");
  expectRefused(
      saveChangedAndLoad(dir, [](StereoCalibration& c) { c.Q = cv::Mat::zeros(4, 4, CV_64F); }),
      dir, "extrinsics.yml", "Q", "singular");
  // Q from a calibration with another baseline: depths would be off by the ratio.
  expectRefused(saveChangedAndLoad(dir, [](StereoCalibration& c) { c.Q.at<double>(3, 2) *= 2; }),
                dir, "extrinsics.yml", "Q", "Q and T come from different calibrations");
}

TEST(CalibrationCheck, NonFiniteProjection) {
  ScopedTempDir dir("calib_check_inf_p");
  expectRefused(saveChangedAndLoad(dir,
                                   [](StereoCalibration& c) {
                                     c.P2.at<double>(0, 3) =
                                         std::numeric_limits<double>::infinity();
                                   }),
                dir, "extrinsics.yml", "P2", "NaN or infinite");
}

TEST(CalibrationCheck, BadImageSize) {
  ScopedTempDir dir("calib_check_size");
  ASSERT_TRUE(saveStereoCalibration(goodCalibration(), dir.path()));
  const auto intrinsics = dir / "intrinsics.yml";
  std::string text;
  {
    std::ifstream in(intrinsics);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const auto withSize = [&](const std::string& from, const std::string& to) {
    std::string changed = text;
    const std::size_t at = changed.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    changed.replace(at, from.size(), to);
    std::ofstream(intrinsics, std::ios::trunc) << changed;
    return loadStereoCalibration(dir.path());
  };
  expectRefused(withSize("image_width: 1624", "image_width: 0"), dir, "intrinsics.yml",
                "image_width", "0 is outside 1..32767");
  expectRefused(withSize("image_height: 1224", "image_height: 100000"), dir, "intrinsics.yml",
                "image_height", "100000 is outside 1..32767");
  expectRefused(withSize("image_width: 1624", "image_width: wide"), dir, "intrinsics.yml",
                "image_width", "is not a whole number");
  auto one_missing = withSize("image_width: 1624", "");
  ASSERT_FALSE(one_missing);
  EXPECT_EQ(one_missing.error().message,
            intrinsics.string() + ": field 'image_width' is missing (the other one is given)");
}

// ---- Matcher options ----------------------------------------------------------------------------

void expectOptionRefused(const std::function<void(MatcherOptions&)>& change,
                         const std::string& message) {
  MatcherOptions options;
  change(options);
  const core::Result<void> valid = validate(options);
  ASSERT_FALSE(valid) << "accepted; expected " << message;
  EXPECT_EQ(valid.error().message, message);
}

TEST(MatcherOptionsCheck, DefaultsAndTheShippedValuesPass) {
  EXPECT_TRUE(validate(MatcherOptions{}));
  MatcherOptions widest;
  widest.num_disparities = kMaxNumDisparities;
  widest.min_disparity = kMaxMinDisparity;
  widest.block_size = kMaxBlockSize;
  widest.match_colour = true;
  widest.p2_per_pixel = kMaxPenaltyPerPixel;
  EXPECT_TRUE(validate(widest));
}

TEST(MatcherOptionsCheck, EachOutOfRangeOptionIsNamedWithItsRange) {
  expectOptionRefused([](auto& o) { o.num_disparities = 100000; },
                      "num_disparities 100000 is outside the allowed range [16, 1024] (a multiple "
                      "of 16)");
  expectOptionRefused([](auto& o) { o.num_disparities = 100; },
                      "num_disparities 100 is outside the allowed range [16, 1024] (a multiple "
                      "of 16)");
  expectOptionRefused([](auto& o) { o.min_disparity = -5000; },
                      "min_disparity -5000 is outside the allowed range [-1024, 1023]");
  expectOptionRefused([](auto& o) { o.block_size = 9999; },
                      "block_size 9999 is outside the allowed range [1, 31] (odd)");
  expectOptionRefused([](auto& o) { o.block_size = 4; },
                      "block_size 4 is outside the allowed range [1, 31] (odd)");
  expectOptionRefused([](auto& o) { o.p2_per_pixel = 2000000000; },
                      "p2_per_pixel 2000000000 is outside the allowed range [0, 1000]");
  expectOptionRefused([](auto& o) { o.pre_filter_cap = 200; },
                      "pre_filter_cap 200 is outside the allowed range [0, 63]");
  expectOptionRefused([](auto& o) { o.uniqueness_ratio = -1; },
                      "uniqueness_ratio -1 is outside the allowed range [0, 100]");
  expectOptionRefused([](auto& o) { o.speckle_range = 1 << 30; },
                      "speckle_range 1073741824 is outside the allowed range [0, 1024]");
  expectOptionRefused([](auto& o) { o.lr_max_diff = std::numeric_limits<float>::quiet_NaN(); },
                      "lr_max_diff nan is outside the allowed range [0, ...) pixels, finite");
  expectOptionRefused([](auto& o) { o.wls_sigma = 0; },
                      "wls_sigma 0 is outside the allowed range (0, ...), finite");
  expectOptionRefused([](auto& o) { o.grow_uniqueness_ratio = -2; },
                      "grow_uniqueness_ratio -2 is outside the allowed range [-1, 100] (-1 "
                      "disables it)");
  expectOptionRefused([](auto& o) { o.grow_confirmed_fraction = 1.0; },
                      "grow_confirmed_fraction 1 is outside the allowed range [0, 1)");
  expectOptionRefused(
      [](auto& o) {
        o.grow_uniqueness_ratio = 0;
        o.wls = true;
      },
      "grow_uniqueness_ratio needs wls off (WLS fills every pixel, so there is nothing to grow "
      "into)");
  expectOptionRefused([](auto& o) { o.mode = 7; },
                      "mode 7 is outside the allowed range (sgbm, hh, sgbm_3way or hh4)");
}

TEST(MatcherOptionsCheck, CommandLineNamesAreFlags) {
  MatcherOptions options;
  options.block_size = 9999;
  const core::Result<void> valid = validate(options, OptionNames::kCommandLineFlags);
  ASSERT_FALSE(valid);
  EXPECT_EQ(valid.error().message, "--block-size 9999 is outside the allowed range [1, 31] (odd)");
}

// SGBM aborted (cv::Exception in its buffer) when the range left no column to match.
TEST(MatcherOptionsCheck, TheRangeMustLeaveColumnsToMatch) {
  MatcherOptions options;
  options.num_disparities = 448;
  EXPECT_TRUE(validate(options, cv::Size(450, 375)));
  options.num_disparities = 464;
  auto too_wide = validate(options, cv::Size(450, 375));
  ASSERT_FALSE(too_wide);
  EXPECT_EQ(too_wide.error().message,
            "num_disparities 464 leaves no column of the 450-pixel-wide images to match: at most "
            "448");
  options.num_disparities = 16;
  options.min_disparity = 440;
  auto shifted = validate(options, cv::Size(450, 375), OptionNames::kCommandLineFlags);
  ASSERT_FALSE(shifted);
  EXPECT_EQ(shifted.error().message,
            "--num-disparities 16 (from --min-disparity 440) leaves no column of the "
            "450-pixel-wide images to match");
  options.min_disparity = 0;
  const cv::Mat narrow(8, 16, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(computePairDisparity(narrow, narrow, nullptr, options));
}

TEST(MatcherOptionsCheck, LibraryEntryPointsRefuseBeforeOpenCvSeesThem) {
  MatcherOptions options;
  options.num_disparities = 100000;  // cv::Exception inside StereoSGBM before the check
  const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(128));
  auto pair = computePairDisparity(image, image, nullptr, options);
  ASSERT_FALSE(pair);
  EXPECT_NE(pair.error().message.find("num_disparities 100000"), std::string::npos);
  HeadOptions head_options;
  head_options.matcher = options;
  auto head = HeadPipeline::create(goodCalibration(), head_options);
  ASSERT_FALSE(head);
  EXPECT_NE(head.error().message.find("num_disparities 100000"), std::string::npos);
}

}  // namespace
}  // namespace fieldrig::stereo
