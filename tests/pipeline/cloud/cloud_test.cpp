// The fused cloud from a synthetic calibrated rig (tests/support/plane_rig_scene.h): each head's
// points back in its own frame lie on its plane, everything beyond the crop depth is gone, a
// head with bad frames is flagged and the others still give their points; rig.yml round trip
// and its errors.
#include <gtest/gtest.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <vector>

#include "fieldrig/cloud/fusion.h"
#include "fieldrig/cloud/rig_calibration.h"
#include "support/file_size_limit.h"
#include "support/plane_rig_scene.h"
#include "support/temp_dir.h"

namespace fieldrig::cloud {
namespace {

using namespace fieldrig::testing_support;

std::vector<HeadFrames> renderAll() {
  std::vector<HeadFrames> frames;
  for (int i = 0; i < 3; ++i) {
    RenderedHead head = renderHead(i);
    frames.push_back({head.left_raw, head.right_raw, core::PixelFormat::kBayerRG8, {}, {}});
  }
  return frames;
}

cv::Matx44d toPlot(const RigCalibration& rig, int head) {
  cv::Matx44d plot = cv::Matx44d::eye();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      plot(r, c) = rig.plot_rotation(r, c);
  }
  return plot * rig.heads[static_cast<std::size_t>(head)].to_bottom;
}

// |z - depth| of each of the head's points taken back into the head's own frame.
std::vector<double> depthErrors(const Cloud& cloud, std::size_t first, std::size_t count,
                                const cv::Matx44d& to_plot, double depth) {
  const cv::Matx44d back = to_plot.inv();
  std::vector<double> errors;
  for (std::size_t i = first; i < first + count; ++i) {
    const pcl::PointXYZRGB& p = cloud[i];
    const cv::Vec4d head = back * cv::Vec4d(p.x, p.y, p.z, 1);
    errors.push_back(std::fabs(head[2] - depth));
  }
  std::sort(errors.begin(), errors.end());
  return errors;
}

double quantile(const std::vector<double>& sorted, double q) {
  return sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
}

TEST(CloudBuilder, SyntheticRigPointsLieOnTheirPlanesInThePlotFrame) {
  const RigCalibration rig = syntheticRig();
  auto builder = CloudBuilder::create(rig);
  ASSERT_TRUE(builder) << builder.error().message;
  const FusionResult result = builder->build(renderAll());
  ASSERT_EQ(result.heads.size(), 3u);
  EXPECT_FALSE(result.partial());
  std::size_t first = 0;
  const double matching_pixels = (kCameraSize.width / 2.0) * (kNearRows / 2.0);
  for (int i = 0; i < 3; ++i) {
    const HeadStatus& head = result.heads[static_cast<std::size_t>(i)];
    ASSERT_TRUE(head.ok) << head.problem;
    // Most of the near plane is matched (the left 128 columns cannot be).
    EXPECT_GT(static_cast<double>(head.points), 0.7 * matching_pixels) << head.name;
    // None of the background: the near plane's rows are all that can be kept.
    EXPECT_LT(static_cast<double>(head.points), 1.02 * matching_pixels) << head.name;
    const std::vector<double> errors =
        depthErrors(result.cloud, first, head.points, toPlot(rig, i), kPlantDepthM[i]);
    // Within 1 cm at 1.0–1.4 m for 95 % of the points. The median is SGBM's sub-pixel bias
    // (measured 3.3, 0.0, 3.5 mm: 0.19, 0, 0.14 px of disparity; exact half-pixel disparities
    // are its worst case), bounded at 5 mm.
    EXPECT_LT(quantile(errors, 0.5), 0.005) << head.name;
    EXPECT_LT(quantile(errors, 0.95), 0.01) << head.name;
    first += head.points;
  }
  EXPECT_EQ(first, result.cloud.size());
  for (const auto& p : result.cloud) {
    ASSERT_LE(p.z, builder->options().max_depth_m);
    ASSERT_GT(p.z, builder->options().min_depth_m);
  }
  // The plot frame: x up. The middle head sits 0.5 m above the bottom one and sees the same
  // field of view, so its points are 0.5 m higher on average.
  auto meanX = [&](std::size_t from, std::size_t count) {
    double sum = 0;
    for (std::size_t i = from; i < from + count; ++i)
      sum += result.cloud[i].x;
    return sum / static_cast<double>(count);
  };
  const double bottom_x = meanX(0, result.heads[0].points);
  const double middle_x = meanX(result.heads[0].points, result.heads[1].points);
  // Each head's plane spans the same rows of its image, at 1.2 and 1.0 m: the mean height of
  // the seen part scales with depth, so compare against the projection of the row band.
  const double band_centre_rows = (kNearRows / 2.0) - (kCameraSize.height - 1) / 2.0;
  const double expected_bottom = -band_centre_rows * kPlantDepthM[0] / kFocalPx;
  const double expected_middle = 0.5 - band_centre_rows * kPlantDepthM[1] / kFocalPx;
  EXPECT_NEAR(bottom_x, expected_bottom, 0.01);
  EXPECT_NEAR(middle_x, expected_middle, 0.01);
}

TEST(CloudBuilder, BlankOrMissingFramesFlagTheHeadAndKeepTheOthers) {
  const RigCalibration rig = syntheticRig();
  auto builder = CloudBuilder::create(rig);
  ASSERT_TRUE(builder);
  std::vector<HeadFrames> frames = renderAll();
  frames[2].left = cv::Mat::zeros(kCameraSize, CV_8UC1);  // top: lens cap
  frames[1].right = cv::Mat();                            // middle: camera missing
  const FusionResult result = builder->build(frames);
  EXPECT_TRUE(result.partial());
  EXPECT_TRUE(result.heads[0].ok);
  EXPECT_GT(result.heads[0].points, 100000u);
  EXPECT_FALSE(result.heads[1].ok);
  EXPECT_EQ(result.heads[1].problem, "middle: right image is missing");
  EXPECT_FALSE(result.heads[2].ok);
  EXPECT_EQ(result.heads[2].problem, "top: left image is blank (brightest pixel 0)");
  EXPECT_EQ(result.cloud.size(), result.heads[0].points);
}

TEST(CloudBuilder, WrongSizesFlagTheHead) {
  const RigCalibration rig = syntheticRig();
  auto builder = CloudBuilder::create(rig);
  ASSERT_TRUE(builder);
  std::vector<HeadFrames> frames = renderAll();
  cv::resize(frames[0].right, frames[0].right, cv::Size(812, 612), 0, 0, cv::INTER_NEAREST);
  const FusionResult result = builder->build(frames);
  EXPECT_FALSE(result.heads[0].ok);
  EXPECT_EQ(result.heads[0].problem,
            "bottom: right image is 812x612 but the calibration is for 1624x1224");
  EXPECT_TRUE(result.heads[1].ok);
  EXPECT_TRUE(result.heads[2].ok);
}

// Truth maps that do not fit the calibration cannot score the head; it says so and still
// gives its points, while a head with fitting maps is scored.
TEST(CloudBuilder, TruthMapsOfAnotherSizeLeaveTheHeadUnscoredAndSayWhy) {
  const RigCalibration rig = syntheticRig();
  auto builder = CloudBuilder::create(rig);
  ASSERT_TRUE(builder);
  std::vector<HeadFrames> frames = renderAll();
  frames[0].left_truth_depth = cv::Mat(4, 4, CV_32F, cv::Scalar(2.0));
  frames[0].left_truth_vegetation = cv::Mat(4, 4, CV_8UC1, cv::Scalar(1));
  frames[1].left_truth_depth = cv::Mat(kCameraSize, CV_32F, cv::Scalar(2.0));
  frames[1].left_truth_vegetation = cv::Mat(kCameraSize, CV_8UC1, cv::Scalar(1));
  frames[2].left_truth_depth = cv::Mat(kCameraSize, CV_32F, cv::Scalar(2.0));
  frames[2].left_truth_vegetation = cv::Mat(8, 8, CV_8UC1, cv::Scalar(1));
  const FusionResult result = builder->build(frames);
  EXPECT_TRUE(result.heads[0].ok);
  EXPECT_GT(result.heads[0].points, 100000u);
  EXPECT_FALSE(result.heads[0].stereo_score);
  EXPECT_FALSE(result.heads[0].cloud_score);
  EXPECT_NE(result.heads[0].truth_problem.find("truth depth map is 4x4"), std::string::npos)
      << result.heads[0].truth_problem;
  EXPECT_TRUE(result.heads[1].stereo_score);
  EXPECT_EQ(result.heads[1].truth_problem, "");
  EXPECT_FALSE(result.heads[2].stereo_score);
  EXPECT_TRUE(result.heads[2].cloud_score) << "the depth fits: only the mask does not";
  EXPECT_NE(result.heads[2].truth_problem.find("truth mask is 8x8"), std::string::npos)
      << result.heads[2].truth_problem;
}

TEST(DepthEdges, BlendedPixelsAtAStepGoAndSlopesStay) {
  // Left half a leaf at 60 px, right half the background at 10 px, with SGBM's blend of the two
  // in the columns between; the rows below are a slanted surface (0.5 px per column).
  cv::Mat disparity(20, 40, CV_32F, cv::Scalar(stereo::kInvalidDisparity));
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 10; ++y)
      disparity.at<float>(y, x) = x < 18 ? 60.0F : (x < 22 ? 60.0F - 12.5F * (x - 17) : 10.0F);
    for (int y = 10; y < 20; ++y)
      disparity.at<float>(y, x) = 30.0F + 0.5F * static_cast<float>(x);
  }
  disparity.at<float>(15, 5) = stereo::kInvalidDisparity;  // a hole must not make edges around it
  const std::size_t dropped = dropDepthEdges(disparity, 2.0);
  for (int y = 0; y < 9; ++y) {  // row 9 borders the slope: its pixels see the rows below
    for (int x = 17; x <= 21; ++x)
      EXPECT_EQ(disparity.at<float>(y, x), stereo::kInvalidDisparity) << x << "," << y;
    EXPECT_EQ(disparity.at<float>(y, 10), 60.0F);
    EXPECT_EQ(disparity.at<float>(y, 30), 10.0F);
  }
  for (int x = 0; x < 40; ++x) {
    if (x != 5) {
      EXPECT_GT(disparity.at<float>(15, x), 0.0F) << "the slope is no edge, column " << x;
    }
  }
  EXPECT_GE(dropped, 5U * 9U);
}

TEST(DepthEdges, KeepingTheNearSideKeepsTheLeafsEdgeAndDropsTheBlend) {
  // A leaf at 60 px (columns < 18), SGBM's blend in columns 18-21, the background at 10 px beyond.
  cv::Mat disparity(10, 40, CV_32F);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 40; ++x)
      disparity.at<float>(y, x) = x < 18 ? 60.0F : (x < 22 ? 60.0F - 12.5F * (x - 17) : 10.0F);
  }
  cv::Mat both_sides = disparity.clone();
  const std::size_t dropped = dropDepthEdges(disparity, 2.0, /*keep_near_side=*/true);
  dropDepthEdges(both_sides, 2.0);
  for (int y = 0; y < 10; ++y) {
    EXPECT_EQ(disparity.at<float>(y, 17), 60.0F) << "the leaf's own edge pixel stays, row " << y;
    EXPECT_EQ(both_sides.at<float>(y, 17), stereo::kInvalidDisparity) << "row " << y;
    for (int x = 18; x <= 21; ++x)
      EXPECT_EQ(disparity.at<float>(y, x), stereo::kInvalidDisparity) << x << "," << y;
    EXPECT_EQ(disparity.at<float>(y, 22), 10.0F) << "the background beyond the blend, row " << y;
  }
  EXPECT_EQ(dropped, 4U * 10U);
}

TEST(Rig, SaveLoadRoundTrip) {
  ScopedTempDir dir("cloud_rig_round_trip");
  RigCalibration rig = syntheticRig();
  rig.pixel_format = core::PixelFormat::kBayerGB8;
  ASSERT_TRUE(saveRigCalibration(rig, dir.path()));
  auto loaded = loadRigCalibration(dir.path());
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_EQ(loaded->heads.size(), 3u);
  EXPECT_EQ(loaded->heads[2].name, "top");
  EXPECT_LT(cv::norm(loaded->heads[2].to_bottom - rig.heads[2].to_bottom), 1e-12);
  EXPECT_EQ(loaded->heads[1].stereo.image_size, kCameraSize);
  EXPECT_EQ(loaded->pixel_format, core::PixelFormat::kBayerGB8);
  EXPECT_LT(cv::norm(cv::Mat(loaded->plot_rotation), cv::Mat(rig.plot_rotation)), 1e-12);
}

TEST(Rig, ErrorsNameFileAndField) {
  ScopedTempDir dir("cloud_rig_errors");
  auto missing = loadRigCalibration(dir.path());
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, (dir.path() / "rig.yml").string() + ": cannot open");

  ASSERT_TRUE(saveRigCalibration(syntheticRig(), dir.path()));
  std::filesystem::remove(dir.path() / "middle" / "extrinsics.yml");
  auto no_head = loadRigCalibration(dir.path());
  ASSERT_FALSE(no_head);
  EXPECT_EQ(no_head.error().message,
            (dir.path() / "middle" / "extrinsics.yml").string() + ": cannot open");

  {
    std::ofstream out(dir.path() / "rig.yml");
    out << "%YAML:1.0\nheads: [bottom]\nplot_rotation: !!opencv-matrix\n  rows: 3\n  cols: 3\n"
           "  dt: d\n  data: [ 2, 0, 0, 0, 1, 0, 0, 0, 1 ]\n";
  }
  auto not_rotation = loadRigCalibration(dir.path());
  ASSERT_FALSE(not_rotation);
  EXPECT_EQ(not_rotation.error().message,
            (dir.path() / "rig.yml").string() +
                ": field 'plot_rotation': not a rotation: not orthonormal (|R*R^T - I| = 3 > "
                "0.001)");
}

// A head's name is the folder of its calibration (and of its frames in a session): a name with a
// path in it reached files outside the calibration folder. Damaged files are errors, not crashes.
TEST(Rig, HeadNamesAreFolderNamesAndDamagedFilesAreRefused) {
  ScopedTempDir dir("cloud_rig_names");
  ASSERT_TRUE(saveRigCalibration(syntheticRig(), dir.path()));
  const std::string file = (dir.path() / "rig.yml").string();
  const auto withRig = [&](const std::string& text) {
    std::ofstream(dir.path() / "rig.yml", std::ios::binary | std::ios::trunc) << text;
    return loadRigCalibration(dir.path());
  };
  for (const char* name : {"../bottom", "/etc", "..", "a b", ""}) {
    const auto loaded = withRig(std::string("%YAML:1.0\nheads: [ \"") + name + "\" ]\n");
    ASSERT_FALSE(loaded) << name;
    EXPECT_EQ(loaded.error().message.rfind(file + ": field 'heads': '" + name + "'", 0), 0u)
        << loaded.error().message;
  }
  const auto twice = withRig("%YAML:1.0\nheads: [ bottom, bottom ]\n");
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.error().message.find("names 'bottom' twice"), std::string::npos)
      << twice.error().message;
  const auto not_map = withRig("%YAML:1.0\n- bottom\n- top\n");
  ASSERT_FALSE(not_map);
  EXPECT_EQ(not_map.error().message, file + ": not a map of fields (OpenCV YAML)");
  const auto huge = withRig(
      "%YAML:1.0\nheads: [ bottom ]\nplot_rotation: !!opencv-matrix\n  rows: 3\n"
      "  cols: 2147483647\n  dt: d\n  data: [ 1 ]\n");
  ASSERT_FALSE(huge);
  EXPECT_EQ(huge.error().message, file + ": field 'plot_rotation' is not a finite 3x3 matrix");

  RigCalibration bad_name = syntheticRig();
  bad_name.heads[1].name = "../elsewhere";
  const auto saved = saveRigCalibration(bad_name, dir.path() / "out");
  ASSERT_FALSE(saved);
  EXPECT_NE(saved.error().message.find("'../elsewhere' is not a head name"), std::string::npos)
      << saved.error().message;
}

// Each kind of unusable head transform is refused naming rig.yml and the field; a head's own
// unusable calibration names its file (before, all of these loaded).
TEST(Rig, HeadTransformsAndHeadCalibrationsAreChecked) {
  ScopedTempDir dir("cloud_rig_checks");
  const std::string rig_file = (dir.path() / "rig.yml").string();
  const auto loadChanged = [&](const std::function<void(RigCalibration&)>& change) {
    RigCalibration rig = syntheticRig();
    change(rig);
    EXPECT_TRUE(saveRigCalibration(rig, dir.path()));
    return loadRigCalibration(dir.path());
  };
  const auto expectRefused = [](const core::Result<RigCalibration>& loaded,
                                const std::string& message) {
    ASSERT_FALSE(loaded) << "accepted; expected " << message;
    EXPECT_EQ(loaded.error().message.rfind(message, 0), 0u) << loaded.error().message;
  };
  expectRefused(loadChanged([](RigCalibration& rig) {
                  for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c)
                      rig.heads[1].to_bottom(r, c) = 0;
                }),
                rig_file + ": field 'middle_to_bottom': not a rotation: not orthonormal");
  expectRefused(loadChanged([](RigCalibration& rig) { rig.heads[2].to_bottom(0, 0) = -1; }),
                rig_file + ": field 'top_to_bottom': not a rotation: a reflection (det = -1)");
  expectRefused(loadChanged([](RigCalibration& rig) { rig.heads[1].to_bottom(3, 1) = 0.5; }),
                rig_file + ": field 'middle_to_bottom': not a rigid transform");
  // A rig measured in millimetres.
  expectRefused(loadChanged([](RigCalibration& rig) { rig.heads[2].to_bottom(1, 3) = -1500; }),
                rig_file + ": field 'top_to_bottom': the head is 1500 m from the bottom one");
  expectRefused(loadChanged([](RigCalibration& rig) { rig.plot_rotation(2, 2) = -1; }),
                rig_file + ": field 'plot_rotation': not a rotation: a reflection");
  expectRefused(loadChanged([](RigCalibration& rig) {
                  rig.heads[1].stereo.M1 = cv::Mat::zeros(3, 3, CV_64F);
                }),
                (dir.path() / "middle" / "intrinsics.yml").string() +
                    ": field 'M1': singular camera matrix (fx = 0)");
  expectRefused(loadChanged([](RigCalibration& rig) {
                  rig.heads[0].stereo.R = cv::Mat::zeros(3, 3, CV_64F);
                }),
                (dir.path() / "bottom" / "extrinsics.yml").string() +
                    ": field 'R': not a rotation: not orthonormal");
  // The synthetic rig itself, as sim and `fieldrig sim plots` write it, loads.
  auto good = loadChanged([](RigCalibration&) {});
  EXPECT_TRUE(good) << good.error().message;
}

// Calibrations written before the processing options left rig.yml carry them at their defaults:
// they still load; a changed value is refused with where it belongs now, never dropped silently.
TEST(Rig, ProcessingOptionsOfEarlierRigFilesLoadAtDefaultsAndAreRefusedOtherwise) {
  ScopedTempDir dir("cloud_rig_legacy");
  ASSERT_TRUE(saveRigCalibration(syntheticRig(), dir.path()));
  const std::filesystem::path file = dir.path() / "rig.yml";
  std::string text;
  {
    std::ifstream in(file);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  auto writeWith = [&](const std::string& extra) {
    std::ofstream out(file, std::ios::trunc);
    out << text << extra;
  };
  writeWith(
      "max_depth_m: 1.7\nmin_depth_m: 0.2\nscale: 0.5\nmin_disparity: 0\n"
      "num_disparities: 128\nedge_max_jump_px: 2.\n");
  auto at_defaults = loadRigCalibration(dir.path());
  ASSERT_TRUE(at_defaults) << at_defaults.error().message;
  EXPECT_EQ(at_defaults->heads.size(), 3u);

  writeWith("scale: 0.25\n");
  auto changed = loadRigCalibration(dir.path());
  ASSERT_FALSE(changed);
  EXPECT_EQ(changed.error().message,
            file.string() +
                ": field 'scale' is a processing option, no longer part of the calibration: set "
                "it as pipeline.cloud.scale in the configuration and remove it here");
  writeWith("num_disparities: 64\n");
  auto disparities = loadRigCalibration(dir.path());
  ASSERT_FALSE(disparities);
  EXPECT_NE(disparities.error().message.find("pipeline.matcher.num_disparities"), std::string::npos)
      << disparities.error().message;
}

TEST(CloudBuilder, RefusesOptionsOutOfRange) {
  CloudOptions options;
  options.scale = std::numeric_limits<double>::quiet_NaN();
  auto nan_scale = CloudBuilder::create(syntheticRig(), options);
  ASSERT_FALSE(nan_scale);
  EXPECT_EQ(nan_scale.error().message.rfind("cloud options: scale", 0), 0u)
      << nan_scale.error().message;
  options = {};
  options.min_depth_m = 2.0;
  auto crop = CloudBuilder::create(syntheticRig(), options);
  ASSERT_FALSE(crop);
  EXPECT_NE(crop.error().message.find("min_depth_m"), std::string::npos) << crop.error().message;
  options = {};
  options.matcher.num_disparities = 100;
  EXPECT_FALSE(CloudBuilder::create(syntheticRig(), options));
}

TEST(Ply, WritesBinaryWithColourAndRefusesEmpty) {
  ScopedTempDir dir("cloud_ply");
  Cloud cloud;
  pcl::PointXYZRGB p;
  p.x = 1;
  p.y = 2;
  p.z = 1.25f;
  p.r = 200;
  p.g = 10;
  p.b = 30;
  cloud.push_back(p);
  ASSERT_TRUE(writePly(cloud, dir / "one.ply"));
  std::ifstream in(dir / "one.ply", std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("element vertex 1"), std::string::npos);
  EXPECT_NE(header.find("property uchar red"), std::string::npos);
  EXPECT_EQ(header.find("element camera"), std::string::npos);
  pcl::PointCloud<pcl::PointXYZRGB> back;
  ASSERT_EQ(pcl::io::loadPLYFile((dir / "one.ply").string(), back), 0);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_FLOAT_EQ(back[0].z, 1.25f);
  EXPECT_EQ(back[0].r, 200);
  EXPECT_EQ(back[0].b, 30);
  EXPECT_FALSE(writePly(Cloud(), dir / "empty.ply"));

  // A write that fails (a full disk; here a file size limit) is an error and leaves the old
  // cloud whole: PCL's writer reported success and left a cut file in its place.
  const auto bytesOf = [](const std::filesystem::path& file) {
    std::ifstream whole(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
  };
  const std::string before = bytesOf(dir / "one.ply");
  Cloud large;
  large.resize(10000, p);
  core::Result<std::filesystem::path> failed = dir / "one.ply";
  {
    const FileSizeLimit limit(4096);
    failed = writePly(large, dir / "one.ply");
  }
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().message.find("one.ply: cannot write: File too large"), std::string::npos)
      << failed.error().message;
  EXPECT_EQ(bytesOf(dir / "one.ply"), before);
  ASSERT_TRUE(writePly(large, dir / "one.ply"));
  ASSERT_EQ(pcl::io::loadPLYFile((dir / "one.ply").string(), back), 0);
  EXPECT_EQ(back.size(), 10000u);
}

}  // namespace
}  // namespace fieldrig::cloud
