// One stereo head from raw frames to a rectified left image and its disparity: debayer,
// downsample, rectify (maps built once), match. The calibration is given at the cameras' full
// resolution and scaled to the matching resolution here.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/result.h"
#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/matcher.h"
#include "fieldrig/stereo/rectifier.h"
#include "fieldrig/stereo/truth_depth.h"

namespace fieldrig::stereo {

struct HeadOptions {
  double scale = 0.5;  // matching resolution / camera resolution
  MatcherOptions matcher;
  // A frame whose brightest pixel is below this is treated as blank (lens cap, dead camera).
  int blank_max_level = 8;
};

struct HeadTimings {
  double debayer_ms = 0;  // debayer + downsample, both images
  double rectify_ms = 0;
  MatchTimings match;
};

struct HeadOutput {
  cv::Mat left_bgr;   // rectified left image at matching resolution (CV_8UC3)
  cv::Mat disparity;  // CV_32F pixels of the matching resolution, kInvalidDisparity = none
};

// Thread contract: thread-compatible; one instance per thread.
class HeadPipeline {
 public:
  // `calibration` at camera resolution, with its image size. The error says what is missing.
  static core::Result<HeadPipeline> create(const StereoCalibration& calibration,
                                           const HeadOptions& options);

  // Raw frames (CV_8UC1 of `format`, or CV_8UC3 BGR images) → output. Bad input (size differs
  // from the calibration or between left and right, a blank frame) is an error saying which
  // image and why; `name` prefixes it.
  core::Result<HeadOutput> process(const cv::Mat& raw_left, const cv::Mat& raw_right,
                                   core::PixelFormat format, const std::string& name,
                                   HeadTimings* timings = nullptr);

  // The same output with the disparity made from the left camera's rendered truth depth
  // (`raw_left_depth`, CV_32F at camera size; truth_depth.h) instead of matching: the left image
  // is checked, debayered, scaled and rectified as by process(); no right image is needed.
  core::Result<HeadOutput> processTruthDepth(const cv::Mat& raw_left, const cv::Mat& raw_left_depth,
                                             core::PixelFormat format, const std::string& name,
                                             HeadTimings* timings = nullptr);

  // Turns truth maps onto this head's rectified grid and scores disparities against them.
  const TruthDepthRectifier& truthDepth() const { return truth_depth_; }

  // The calibration at matching resolution (Q reprojects this head's disparities).
  const StereoCalibration& matchingCalibration() const { return scaled_; }

 private:
  HeadPipeline(const StereoCalibration& scaled, Rectifier rectifier,
               TruthDepthRectifier truth_depth, const HeadOptions& options)
      : scaled_(scaled),
        rectifier_(std::move(rectifier)),
        truth_depth_(std::move(truth_depth)),
        options_(options),
        matcher_(options.matcher) {}

  core::Result<void> checkImage(const cv::Mat& raw, const char* side,
                                const std::string& name) const;

  StereoCalibration scaled_;
  cv::Size camera_size_;
  Rectifier rectifier_;
  TruthDepthRectifier truth_depth_;
  HeadOptions options_;
  DisparityMatcher matcher_;
};

}  // namespace fieldrig::stereo
