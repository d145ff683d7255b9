#include "fieldrig/stereo/head.h"
#include "fieldrig/core/time.h"

#include <chrono>

#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::stereo {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

core::Result<HeadPipeline> HeadPipeline::create(const StereoCalibration& calibration,
                                                const HeadOptions& options) {
  if (calibration.image_size.empty()) {
    return core::Error{"calibration has no image size (image_width/image_height in intrinsics)"};
  }
  const StereoCalibration scaled = calibration.scaled(options.scale);
  if (auto valid = validate(options.matcher, scaled.image_size); !valid)
    return core::Error{"matcher options: " + valid.error().message};
  core::Result<Rectifier> rectifier = Rectifier::create(scaled);
  if (!rectifier)
    return rectifier.error();
  core::Result<TruthDepthRectifier> truth_depth =
      TruthDepthRectifier::create(scaled, calibration.image_size, options.scale);
  if (!truth_depth)
    return truth_depth.error();
  HeadPipeline head(scaled, std::move(*rectifier), std::move(*truth_depth), options);
  head.camera_size_ = calibration.image_size;
  return head;
}

core::Result<void> HeadPipeline::checkImage(const cv::Mat& raw, const char* side,
                                            const std::string& name) const {
  if (raw.empty()) {
    return core::Error{name + ": " + side + " image is missing"};
  }
  if (raw.size() != camera_size_) {
    return core::Error{name + ": " + side + " image is " + sizeText(raw.size()) +
                       " but the calibration is for " + sizeText(camera_size_)};
  }
  double max_level = 0;
  cv::minMaxLoc(raw.reshape(1), nullptr, &max_level);
  if (max_level < options_.blank_max_level) {
    return core::Error{name + ": " + side + " image is blank (brightest pixel " +
                       std::to_string(static_cast<int>(max_level)) + ")"};
  }
  return {};
}

core::Result<HeadOutput> HeadPipeline::process(const cv::Mat& raw_left, const cv::Mat& raw_right,
                                               core::PixelFormat format, const std::string& name,
                                               HeadTimings* timings) {
  for (const auto& [side, raw] : {std::pair{"left", &raw_left}, {"right", &raw_right}}) {
    if (auto checked = checkImage(*raw, side, name); !checked)
      return checked.error();
  }
  auto start = Clock::now();
  core::Result<cv::Mat> left = debayerAndScale(raw_left, format, options_.scale);
  if (!left)
    return core::Error{name + ": left image: " + left.error().message};
  core::Result<cv::Mat> right = debayerAndScale(raw_right, format, options_.scale);
  if (!right)
    return core::Error{name + ": right image: " + right.error().message};
  if (timings)
    timings->debayer_ms = core::millisecondsSince(start);
  start = Clock::now();
  HeadOutput out;
  cv::Mat right_rectified;
  rectifier_.rectify(*left, *right, out.left_bgr, right_rectified);
  if (timings)
    timings->rectify_ms = core::millisecondsSince(start);
  out.disparity =
      matcher_.compute(out.left_bgr, right_rectified, timings ? &timings->match : nullptr);
  return out;
}

core::Result<HeadOutput> HeadPipeline::processTruthDepth(const cv::Mat& raw_left,
                                                         const cv::Mat& raw_left_depth,
                                                         core::PixelFormat format,
                                                         const std::string& name,
                                                         HeadTimings* timings) {
  if (auto checked = checkImage(raw_left, "left", name); !checked)
    return checked.error();
  auto start = Clock::now();
  core::Result<cv::Mat> left = debayerAndScale(raw_left, format, options_.scale);
  if (!left)
    return core::Error{name + ": left image: " + left.error().message};
  if (timings)
    timings->debayer_ms = core::millisecondsSince(start);
  start = Clock::now();
  HeadOutput out;
  rectifier_.rectifyLeft(*left, out.left_bgr);
  core::Result<cv::Mat> disparity = truth_depth_.disparity(raw_left_depth);
  if (!disparity)
    return core::Error{name + ": " + disparity.error().message};
  out.disparity = std::move(*disparity);
  if (timings)
    timings->rectify_ms = core::millisecondsSince(start);
  return out;
}

}  // namespace fieldrig::stereo
