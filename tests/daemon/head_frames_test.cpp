// The image-files adapter in front of the plot processor (`fieldrig cloud --pairs`): two files per
// head in the rig's order, each read as it is, and an error naming a file that cannot be read.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "fieldrig/daemon/head_frames.h"
#include "support/temp_dir.h"

namespace fieldrig::daemon {
namespace {

cloud::RigCalibration twoHeadRig() {
  cloud::RigCalibration rig;
  rig.heads.resize(2);
  rig.heads[0].name = "bottom";
  rig.heads[1].name = "top";
  rig.pixel_format = core::PixelFormat::kBayerGR8;
  return rig;
}

TEST(HeadFramesFromImageFiles, TwoFilesPerHeadInTheRigsOrder) {
  testing_support::ScopedTempDir tmp("head_frames_files");
  std::vector<std::string> files;
  for (int i = 0; i < 4; ++i) {
    files.push_back((tmp / ("frame" + std::to_string(i) + ".pgm")).string());
    ASSERT_TRUE(cv::imwrite(files.back(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(10 * (i + 1)))));
  }
  const auto frames = headFramesFromImageFiles(files, twoHeadRig());
  ASSERT_TRUE(frames) << frames.error().message;
  ASSERT_EQ(frames->size(), 2U);
  for (std::size_t head = 0; head < 2; ++head) {
    const cloud::HeadFrames& f = (*frames)[head];
    EXPECT_EQ(f.pixel_format, core::PixelFormat::kBayerGR8);
    ASSERT_EQ(f.left.type(), CV_8UC1);
    EXPECT_EQ(f.left.size(), cv::Size(8, 6));
    EXPECT_EQ(f.left.at<std::uint8_t>(0, 0), 10 * (2 * head + 1));
    EXPECT_EQ(f.right.at<std::uint8_t>(0, 0), 10 * (2 * head + 2));
  }
}

TEST(HeadFramesFromImageFiles, UnreadableFileOrWrongCountIsAnError) {
  testing_support::ScopedTempDir tmp("head_frames_bad");
  std::vector<std::string> files;
  for (int i = 0; i < 4; ++i) {
    files.push_back((tmp / ("frame" + std::to_string(i) + ".pgm")).string());
    ASSERT_TRUE(cv::imwrite(files.back(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(0))));
  }
  files[3] = (tmp / "absent.pgm").string();
  const auto missing = headFramesFromImageFiles(files, twoHeadRig());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("absent.pgm"), std::string::npos)
      << missing.error().message;

  files.pop_back();
  const auto three = headFramesFromImageFiles(files, twoHeadRig());
  ASSERT_FALSE(three);
  EXPECT_NE(three.error().message.find("needs 4"), std::string::npos) << three.error().message;
}

}  // namespace
}  // namespace fieldrig::daemon
