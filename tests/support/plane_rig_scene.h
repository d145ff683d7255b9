// A scene of planes for the cloud tests and benchmark, seen by sim's ideal three-head rig
// (sim::idealRig: 1624×1224, f 1350 px, baseline 0.12 m) with the middle and top heads above the
// bottom one (the top one tilted down): each head looks at a textured fronto-parallel plane at a
// known depth over its upper two thirds and at a background plane beyond the crop depth below.
// Right images are the left texture shifted by the exact disparity; frames are mosaicked to raw
// Bayer.
#pragma once

#include <array>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/sim/synthetic_field.h"
#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::testing_support {

inline constexpr double kFocalPx = sim::kIdealFocalPx;
inline constexpr double kBaselineM = sim::kIdealBaselineM;
inline const cv::Size kCameraSize(sim::kIdealImageWidth, sim::kIdealImageHeight);
inline constexpr double kPlantDepthM[3] = {1.2, 1.0, 1.4};  // each head's near plane
inline constexpr double kBackgroundDepthM = 2.4;
inline constexpr int kNearRows = 1224 * 2 / 3;  // of kCameraSize.height

// sim's ideal rig with the heads 0.5 m apart and the top one tilted 20° down, so that the fusion
// is tested with a rotation as well as offsets.
inline cloud::RigCalibration syntheticRig() {
  sim::IdealRigGeometry geometry;
  geometry.head_heights_m = {0.5, 1.0, 1.5};
  geometry.head_tilts_down_deg = {0, 0, 20};
  return sim::idealRig(geometry);
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
