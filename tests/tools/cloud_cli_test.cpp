// `fieldrig cloud`, run as the built binary on a recorded session and on image files from the
// synthetic calibrated rig (tests/support/plane_rig_scene.h): the PLY it writes, the flagged
// partial cloud for a blank or missing camera, and clear errors for unusable calibration.
#include <gtest/gtest.h>
#include <pcl/io/ply_io.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fieldrig/cloud/fusion.h"
#include "fieldrig/recording/session_writer.h"
#include "support/cli_run.h"
#include "support/plane_rig_scene.h"
#include "support/temp_dir.h"

namespace fieldrig::cloud {
namespace {

using namespace fieldrig::testing_support;
using Json = nlohmann::json;

const std::array<std::string, 6> kCameras{"bottom_left",  "bottom_right", "middle_left",
                                          "middle_right", "top_left",     "top_right"};

struct Fixture {
  std::vector<cv::Mat> raw;  // six frames in kCameras order
  Fixture() {
    for (int i = 0; i < 3; ++i) {
      RenderedHead head = renderHead(i);
      raw.push_back(head.left_raw);
      raw.push_back(head.right_raw);
    }
  }
};

const Fixture& fixture() {
  static const Fixture rendered;
  return rendered;
}

// Writes one set of the six frames; `missing` names a camera recorded as missing.
void writeSession(const std::filesystem::path& dir, const std::vector<cv::Mat>& frames,
                  const std::string& missing = "", const std::string& calib_dir = "") {
  recording::SessionInfo info;
  if (!calib_dir.empty())
    info.calibration.push_back({"calib_dir", calib_dir});
  recording::SessionWriter writer;
  ASSERT_TRUE(writer.open(dir, info));
  recording::FrameSetRecord set;
  set.trigger_id = 1;
  for (int camera = 0; camera < 6; ++camera) {
    recording::FrameView frame;
    frame.camera_index = camera;
    frame.camera_name = kCameras[static_cast<std::size_t>(camera)];
    const cv::Mat& image = frames[static_cast<std::size_t>(camera)];
    frame.width = image.cols;
    frame.height = image.rows;
    frame.pixel_format = core::PixelFormat::kBayerRG8;
    if (frame.camera_name == missing) {
      frame.status = recording::FrameStatus::kMissing;
      frame.reason = "timeout";
      set.complete = false;
    } else {
      frame.pixels = std::span<const std::uint8_t>(image.data, image.total());
    }
    set.frames.push_back(frame);
  }
  ASSERT_TRUE(writer.write(set).ok());
  writer.close();
}

Json lastJson(const CliRun& run) {
  return run.out_lines.empty() ? Json() : Json::parse(run.out_lines.back());
}

TEST(CloudCli, SessionSetToPlotFramePly) {
  ScopedTempDir dir("cloud_cli_session");
  ASSERT_TRUE(saveRigCalibration(syntheticRig(), dir / "calib"));
  writeSession(dir / "session", fixture().raw);
  const CliRun run = runFieldrig({"cloud", (dir / "session").string(), "--set", "0", "--calib",
                                  (dir / "calib").string(), "--out", (dir / "plot.ply").string()},
                                 dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json out = lastJson(run);
  EXPECT_FALSE(out["partial"].get<bool>());
  Cloud cloud;
  ASSERT_EQ(pcl::io::loadPLYFile((dir / "plot.ply").string(), cloud), 0);
  EXPECT_EQ(cloud.size(), out["points"].get<std::size_t>());
  const std::size_t bottom_points = out["heads"][0]["points"].get<std::size_t>();
  ASSERT_GT(bottom_points, 100000u);
  // The bottom head's plane at 1.2 m is plot z = 1.2 (the plot rotation keeps z).
  std::vector<float> z;
  for (std::size_t i = 0; i < bottom_points; ++i)
    z.push_back(cloud[i].z);
  std::nth_element(z.begin(), z.begin() + static_cast<long>(z.size() / 2), z.end());
  EXPECT_NEAR(z[z.size() / 2], kPlantDepthM[0], 0.005);
  for (const auto& p : cloud)
    ASSERT_LE(p.z, 1.7f);
}

TEST(CloudCli, CalibrationFromTheSessionsReference) {
  ScopedTempDir dir("cloud_cli_reference");
  ASSERT_TRUE(saveRigCalibration(syntheticRig(), dir / "session_calib"));
  // Relative to the session folder.
  writeSession(dir / "session", fixture().raw, "", "../session_calib");
  const CliRun run = runFieldrig(
      {"cloud", (dir / "session").string(), "--set", "0", "--out", (dir / "p.ply").string()},
      dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_GT(lastJson(run)["points"].get<std::size_t>(), 300000u);
}

TEST(CloudCli, PairsOfFiles) {
  ScopedTempDir dir("cloud_cli_pairs");
  ASSERT_TRUE(saveRigCalibration(syntheticRig(), dir / "calib"));
  std::string pairs;
  for (int i = 0; i < 6; ++i) {
    const auto file = dir / (kCameras[static_cast<std::size_t>(i)] + ".pgm");
    ASSERT_TRUE(cv::imwrite(file.string(), fixture().raw[static_cast<std::size_t>(i)]));
    // append, not "," + std::string: GCC 12 -O3 gives a false-positive -Wrestrict.
    pairs.append(i ? "," : "").append(file.string());
  }
  const CliRun run = runFieldrig({"cloud", "--pairs", pairs, "--calib", (dir / "calib").string(),
                                  "--out", (dir / "plot.ply").string()},
                                 dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json out = lastJson(run);
  EXPECT_FALSE(out["partial"].get<bool>());
  for (int i = 0; i < 3; ++i)
    EXPECT_GT(out["heads"][i]["points"].get<int>(), 100000);

  const CliRun too_few = runFieldrig(
      {"cloud", "--pairs", "a.pgm,b.pgm", "--calib", (dir / "calib").string(), "--out", "x.ply"},
      dir.path());
  EXPECT_EQ(too_few.exit_code, 2);
  EXPECT_NE(too_few.err.find("--pairs names 2 files"), std::string::npos) << too_few.err;
}

TEST(CloudCli, MissingCameraAndBlankFrameGiveFlaggedPartialCloud) {
  ScopedTempDir dir("cloud_cli_partial");
  ASSERT_TRUE(saveRigCalibration(syntheticRig(), dir / "calib"));
  std::vector<cv::Mat> frames = fixture().raw;
  frames[2] = cv::Mat::zeros(kCameraSize, CV_8UC1);  // middle_left: all black
  writeSession(dir / "session", frames, "top_right");
  const CliRun run = runFieldrig({"cloud", (dir / "session").string(), "--set", "0", "--calib",
                                  (dir / "calib").string(), "--out", (dir / "plot.ply").string()},
                                 dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json out = lastJson(run);
  EXPECT_TRUE(out["partial"].get<bool>());
  EXPECT_TRUE(out["heads"][0]["ok"].get<bool>());
  EXPECT_FALSE(out["heads"][1]["ok"].get<bool>());
  EXPECT_EQ(out["heads"][1]["problem"], "middle: left image is blank (brightest pixel 0)");
  EXPECT_FALSE(out["heads"][2]["ok"].get<bool>());
  EXPECT_EQ(out["heads"][2]["problem"], "top: right image is missing");
  EXPECT_EQ(out["problems"][0], "top_right: recorded as missing (timeout)");
  EXPECT_EQ(out["points"], out["heads"][0]["points"]);
  EXPECT_TRUE(std::filesystem::exists(dir / "plot.ply"));
}

TEST(CloudCli, UnusableCalibrationIsAClearError) {
  ScopedTempDir dir("cloud_cli_bad_calib");
  writeSession(dir / "session", fixture().raw);
  const CliRun no_calib = runFieldrig({"cloud", (dir / "session").string(), "--set", "0", "--calib",
                                       (dir / "absent").string(), "--out", "x.ply"},
                                      dir.path());
  EXPECT_EQ(no_calib.exit_code, 2);
  EXPECT_NE(no_calib.err.find((dir / "absent" / "rig.yml").string() + ": cannot open"),
            std::string::npos)
      << no_calib.err;

  // Calibrated for another camera size: every head is refused, nothing is written.
  RigCalibration other = syntheticRig();
  for (HeadCalibration& head : other.heads)
    head.stereo.image_size = cv::Size(1280, 960);
  ASSERT_TRUE(saveRigCalibration(other, dir / "calib"));
  const CliRun mismatched =
      runFieldrig({"cloud", (dir / "session").string(), "--set", "0", "--calib",
                   (dir / "calib").string(), "--out", (dir / "x.ply").string()},
                  dir.path());
  EXPECT_EQ(mismatched.exit_code, 2);
  EXPECT_NE(
      mismatched.err.find("bottom: left image is 1624x1224 but the calibration is for 1280x960"),
      std::string::npos)
      << mismatched.err;
  EXPECT_NE(mismatched.err.find("no head gave any point"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.ply"));

  const CliRun no_set = runFieldrig({"cloud", (dir / "session").string(), "--set", "7", "--calib",
                                     (dir / "calib").string(), "--out", "x.ply"},
                                    dir.path());
  EXPECT_EQ(no_set.exit_code, 2);
  EXPECT_NE(no_set.err.find("no set with index 7"), std::string::npos) << no_set.err;
}

// Implausible calibration values used to load and give an empty or distorted cloud with exit 0;
// now `cloud` refuses them, naming the file and the field.
TEST(CloudCli, ImplausibleCalibrationNamesFileAndField) {
  ScopedTempDir dir("cloud_cli_implausible_calib");
  writeSession(dir / "session", fixture().raw);
  const auto cloudWith = [&](const RigCalibration& rig) {
    EXPECT_TRUE(saveRigCalibration(rig, dir / "calib"));
    return runFieldrig({"cloud", (dir / "session").string(), "--set", "0", "--calib",
                        (dir / "calib").string(), "--out", (dir / "x.ply").string()},
                       dir.path());
  };
  RigCalibration zero_camera = syntheticRig();
  zero_camera.heads[1].stereo.M1 = cv::Mat::zeros(3, 3, CV_64F);
  const CliRun singular = cloudWith(zero_camera);
  EXPECT_EQ(singular.exit_code, 2);
  EXPECT_NE(singular.err.find((dir / "calib" / "middle" / "intrinsics.yml").string() +
                              ": field 'M1': singular camera matrix (fx = 0)"),
            std::string::npos)
      << singular.err;

  RigCalibration reflected = syntheticRig();
  reflected.heads[2].to_bottom(0, 0) = -1;
  const CliRun reflection = cloudWith(reflected);
  EXPECT_EQ(reflection.exit_code, 2);
  EXPECT_NE(reflection.err.find((dir / "calib" / "rig.yml").string() +
                                ": field 'top_to_bottom': not a rotation: a reflection"),
            std::string::npos)
      << reflection.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.ply"));
}

}  // namespace
}  // namespace fieldrig::cloud
