// A synthetic calibrated three-head rig for the cloud tests and benchmark: ideal Grasshopper-like
// heads (1624×1224, f 1350 px, baseline 0.12 m), the middle and top heads above the bottom one
// (the top one tilted down), each looking at a textured fronto-parallel plane at a known depth
// over its upper two thirds and at a background plane beyond the crop depth below. Right images
// are the left texture shifted by the exact disparity; frames are mosaicked to raw Bayer.
#pragma once

#include <array>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "fieldrig/cloud/rig.h"
#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::testing_support {

inline constexpr double kFocalPx = 1350;
inline constexpr double kBaselineM = 0.12;
inline const cv::Size kCameraSize(1624, 1224);
inline constexpr double kPlantDepthM[3] = {1.2, 1.0, 1.4};  // each head's near plane
inline constexpr double kBackgroundDepthM = 2.4;
inline constexpr int kNearRows = 1224 * 2 / 3;  // of kCameraSize.height

inline stereo::StereoCalibration idealHead() {
  return stereo::idealStereoCalibration(kFocalPx, kCameraSize, kBaselineM);
}

// bottom: reference; middle: 0.5 m above; top: 1.0 m above and tilted 20° down about x.
inline cloud::RigConfig syntheticRig() {
  cloud::RigConfig rig;
  const std::array<std::string, 3> names{"bottom", "middle", "top"};
  for (int i = 0; i < 3; ++i) {
    cloud::HeadConfig head;
    head.name = names[static_cast<std::size_t>(i)];
    head.calibration = idealHead();
    head.to_bottom = cv::Matx44d::eye();
    head.to_bottom(1, 3) = -0.5 * i;  // bottom frame y points down
    rig.heads.push_back(head);
  }
  const double tilt = 20.0 * CV_PI / 180.0;
  // Top head frame → bottom frame: its z axis turned towards +y (down) by the tilt.
  cv::Matx44d& top = rig.heads[2].to_bottom;
  top(1, 1) = std::cos(tilt);
  top(1, 2) = std::sin(tilt);
  top(2, 1) = -std::sin(tilt);
  top(2, 2) = std::cos(tilt);
  rig.max_depth_m = 1.7;
  rig.pixel_format = core::PixelFormat::kBayerRG8;
  return rig;
}

// A smooth random colour texture (features of ~3 px) of the given size.
inline cv::Mat randomTexture(cv::Size size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat small(size.height / 3 + 2, size.width / 3 + 2, CV_8UC3);
  rng.fill(small, cv::RNG::UNIFORM, 0, 256);
  cv::Mat texture;
  cv::resize(small, texture, cv::Size(small.cols * 3, small.rows * 3), 0, 0, cv::INTER_CUBIC);
  return texture(cv::Rect(0, 0, size.width, size.height)).clone();
}

// The texture shifted left by `shift` pixels (sub-pixel, bilinear): out(x, y) = in(x + shift, y).
inline cv::Mat shifted(const cv::Mat& in, double shift) {
  const cv::Matx23d m(1, 0, -shift, 0, 1, 0);
  cv::Mat out;
  cv::warpAffine(in, out, m, in.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

struct RenderedHead {
  cv::Mat left_raw, right_raw;  // Bayer RG8
};

// Renders head `index` of syntheticRig(): the near plane over rows [0, kNearRows), the
// background below.
inline RenderedHead renderHead(int index) {
  const int margin = 300;  // texture beyond the right border, revealed by the disparity shift
  const cv::Size wide(kCameraSize.width + margin, kCameraSize.height);
  const cv::Mat near_texture = randomTexture(wide, 11 + static_cast<std::uint64_t>(index));
  const cv::Mat far_texture = randomTexture(wide, 101 + static_cast<std::uint64_t>(index));
  const double near_d = kFocalPx * kBaselineM / kPlantDepthM[index];
  const double far_d = kFocalPx * kBaselineM / kBackgroundDepthM;
  const cv::Rect view(0, 0, kCameraSize.width, kCameraSize.height);
  cv::Mat left(kCameraSize, CV_8UC3), right(kCameraSize, CV_8UC3);
  const cv::Rect near_rows(0, 0, kCameraSize.width, kNearRows);
  const cv::Rect far_rows(0, kNearRows, kCameraSize.width, kCameraSize.height - kNearRows);
  near_texture(view)(near_rows).copyTo(left(near_rows));
  far_texture(view)(far_rows).copyTo(left(far_rows));
  shifted(near_texture, near_d)(view)(near_rows).copyTo(right(near_rows));
  shifted(far_texture, far_d)(view)(far_rows).copyTo(right(far_rows));
  return {stereo::mosaicBayer(left, core::PixelFormat::kBayerRG8),
          stereo::mosaicBayer(right, core::PixelFormat::kBayerRG8)};
}

}  // namespace fieldrig::testing_support
